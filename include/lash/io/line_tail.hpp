#pragma once
/// @file line_tail.hpp
/// Follows a text file another process is appending to (`tail -f` for a log written while a run
/// goes on): each poll() reads what was added since the last one and hands over the complete
/// lines only; a last line without its '\n' waits for the next poll. A missing file is not an
/// error (poll() returns 0 until it appears); a file that became shorter (replaced or truncated)
/// is read again from its start. Memory is bounded: at most `max_line` bytes of an unfinished
/// line are kept, a longer line is skipped up to its '\n' and counted (overlong()).
/// Not thread-safe; no real-time code.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace lash {

class LineTail {
 public:
  explicit LineTail(std::filesystem::path path, std::size_t max_line = 64 * 1024);
  ~LineTail();
  LineTail(const LineTail&) = delete;
  LineTail& operator=(const LineTail&) = delete;

  /// Reads up to `max_bytes` new bytes and calls on_line for every line they complete (without
  /// its '\n' and a trailing '\r'). Returns the number of lines handed over.
  std::size_t poll(const std::function<void(std::string_view)>& on_line, std::size_t max_bytes = 1 << 20);
  bool opened() const noexcept { return fd_ >= 0; }
  /// Bytes read so far from the current file (the position of the next read).
  std::uint64_t offset() const noexcept { return offset_; }
  std::uint64_t overlong() const noexcept { return overlong_; }
  /// Times the file was found shorter than what was read and read again from the start.
  std::uint64_t restarts() const noexcept { return restarts_; }
  /// Bytes of an unfinished line held (<= max_line).
  std::size_t pending_bytes() const noexcept { return partial_.size(); }

 private:
  void reopen();
  std::filesystem::path path_;
  std::size_t max_line_;
  int fd_ = -1;
  std::uint64_t offset_ = 0, overlong_ = 0, restarts_ = 0;
  std::string partial_;
  bool skipping_ = false;  // inside an overlong line: drop bytes up to its '\n'
};

}  // namespace lash
