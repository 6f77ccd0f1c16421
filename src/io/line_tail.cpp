#include "lash/io/line_tail.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>

namespace lash {

LineTail::LineTail(std::filesystem::path path, std::size_t max_line) : path_(std::move(path)), max_line_(max_line) {
  if (max_line_ == 0) max_line_ = 1;
}

LineTail::~LineTail() {
  if (fd_ >= 0) ::close(fd_);
}

void LineTail::reopen() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  offset_ = 0;
  partial_.clear();
  skipping_ = false;
}

std::size_t LineTail::poll(const std::function<void(std::string_view)>& on_line, std::size_t max_bytes) {
  if (fd_ < 0) {
    reopen();
    if (fd_ < 0) return 0;
  }
  // Replaced (another inode at the path) or truncated: read the new file from its start.
  struct stat open_st {}, path_st {};
  const bool have_open = ::fstat(fd_, &open_st) == 0;
  if (::stat(path_.c_str(), &path_st) == 0 && have_open &&
      (open_st.st_ino != path_st.st_ino || open_st.st_dev != path_st.st_dev ||
       static_cast<std::uint64_t>(path_st.st_size) < offset_)) {
    ++restarts_;
    reopen();
    if (fd_ < 0) return 0;
  }
  std::size_t lines = 0, read_total = 0;
  std::array<char, 64 * 1024> buf;
  while (read_total < max_bytes) {
    const ssize_t n = ::pread(fd_, buf.data(), std::min(buf.size(), max_bytes - read_total),
                              static_cast<off_t>(offset_));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    offset_ += static_cast<std::uint64_t>(n);
    read_total += static_cast<std::size_t>(n);
    std::string_view chunk(buf.data(), static_cast<std::size_t>(n));
    while (!chunk.empty()) {
      const std::size_t nl = chunk.find('\n');
      const std::string_view part = chunk.substr(0, nl);
      if (!skipping_ && partial_.size() + part.size() > max_line_) {  // too long: skip to its end
        partial_.clear();
        skipping_ = true;
        ++overlong_;
      }
      if (!skipping_) partial_.append(part);
      if (nl == std::string_view::npos) break;
      chunk.remove_prefix(nl + 1);
      if (skipping_) {
        skipping_ = false;
        continue;
      }
      std::string_view line(partial_);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      on_line(line);
      ++lines;
      partial_.clear();
    }
  }
  return lines;
}

}  // namespace lash
