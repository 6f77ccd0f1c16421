#pragma once
/// @file atomic_file.hpp
/// Output files that appear whole or not at all. For a regular file (or a
/// name that does not exist yet) data go to a temporary file next to the
/// target, which is renamed over it only by `commit()`; if the object is
/// destroyed without commit (an error was thrown), the temporary is removed
/// and nothing half-written is left behind.
///
/// The temporary is `<target>.tmp.<16 random hex digits>` (getrandom), created
/// with O_CREAT|O_EXCL|O_NOFOLLOW: a link, file or FIFO planted at any name is
/// never followed, opened or truncated (a taken name is skipped). It gets the
/// target's mode when the target exists (else 0666 less the umask).
///
/// A target that exists and is not a regular file (`/dev/null`, a FIFO, a
/// terminal) is opened and written directly — never renamed over — and the
/// name `-` means standard output. Those outputs are streams, so "whole or
/// nothing" cannot hold for them. Not real-time safe.
#include <filesystem>
#include <string>
#include <memory>
#include <ostream>
#include <streambuf>

namespace lash {

class AtomicFile {
 public:
  /// Opens the temporary `<target>.tmp.<random>` (regular file), the target
  /// itself (existing non-regular file) or stdout (`-`); throws InputError
  /// naming the target and the system's reason if it cannot.
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();

  std::ostream& stream() noexcept { return *os_; }
  /// True when the target is written in place (stdout, device, FIFO).
  bool direct() const noexcept { return direct_; }
  /// The file being written: the temporary, or the target itself when direct().
  const std::filesystem::path& temp_path() const noexcept { return tmp_; }
  const std::filesystem::path& target() const noexcept { return target_; }
  /// Flushes, closes and (regular file) renames over the target; throws
  /// InputError on I/O failure.
  void commit();

 private:
  bool close_file() noexcept;

  std::filesystem::path target_;
  std::filesystem::path tmp_;
  std::unique_ptr<std::streambuf> buf_;  ///< over the file's descriptor (it closes it)
  std::ostream out_{nullptr};
  std::ostream* os_ = &out_;
  bool direct_ = false;
  bool committed_ = false;
};

/// True if `path` names standard output (`-`) or an existing file that is not
/// a regular file (device, FIFO, socket): outputs that must be written in place.
bool is_stream_output(const std::filesystem::path& path);

/// Checks, before any work, that an AtomicFile on `target` can be created: `-` and existing
/// stream outputs pass; otherwise the target must not be a directory and its directory must
/// exist and be writable. Throws InputError(target, 0, option, reason).
void check_output_path(const std::filesystem::path& target, const std::string& option);

}  // namespace lash
