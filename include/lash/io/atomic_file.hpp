#pragma once
/// @file atomic_file.hpp
/// Output files that appear whole or not at all: data go to a temporary file
/// next to the target, which is renamed over it only by `commit()`. If the
/// object is destroyed without commit (an error was thrown), the temporary is
/// removed and nothing half-written is left behind. Not real-time safe.
#include <filesystem>
#include <fstream>

namespace lash {

class AtomicFile {
 public:
  /// Opens `<target>.tmp.<pid>` for writing; throws InputError if it cannot.
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();

  std::ofstream& stream() noexcept { return out_; }
  const std::filesystem::path& temp_path() const noexcept { return tmp_; }
  const std::filesystem::path& target() const noexcept { return target_; }
  /// Flushes, closes and renames over the target; throws InputError on I/O failure.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace lash
