#include "lash/io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <ctime>
#include <ext/stdio_filebuf.h>
#include <cstring>
#include <iostream>
#include <system_error>

#include <fmt/core.h>

#include "lash/io/error.hpp"

namespace lash {

bool is_stream_output(const std::filesystem::path& path) {
  if (path == "-") return true;
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);  // follows symlinks
  return !ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st);
}

void check_output_path(const std::filesystem::path& target, const std::string& option) {
  if (target.empty()) throw InputError("", 0, option, "the output path is empty");
  std::error_code ec;
  if (target != "-" && std::filesystem::is_directory(target, ec))
    throw InputError(target.string(), 0, option, "is a directory, not a file");
  if (is_stream_output(target)) return;
  const auto dir = target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(dir, ec))
    throw InputError(target.string(), 0, option, "cannot write: directory " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw InputError(target.string(), 0, option,
                     "cannot write in directory " + dir.string() + ": " + std::strerror(errno));
}

namespace {

std::string open_failure_reason(const std::filesystem::path& target, const std::filesystem::path& opened) {
  const int err = errno;
  std::string why = err ? std::strerror(err) : "unknown error";
  const auto dir = target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return "cannot open for writing: directory " + dir.string() + " does not exist";
  if (opened != target) return "cannot open for writing (" + opened.string() + "): " + why;
  return "cannot open for writing: " + why;
}

std::uint64_t random_u64() {
  std::uint64_t r = 0;
  if (::getrandom(&r, sizeof r, 0) == static_cast<ssize_t>(sizeof r)) return r;
  // No entropy source: still unique per call (O_EXCL refuses a taken name anyway).
  static std::atomic<std::uint64_t> n{0};
  return (static_cast<std::uint64_t>(::getpid()) << 32) ^ static_cast<std::uint64_t>(::time(nullptr)) ^
         (n.fetch_add(1) * 0x9E3779B97F4A7C15ull);
}

/// Creates the temporary next to `target` at an unpredictable name; -1 with errno set if it cannot.
int create_temp(const std::filesystem::path& target, std::filesystem::path& tmp) {
  struct stat st {};
  const bool keep_mode = ::stat(target.c_str(), &st) == 0 && S_ISREG(st.st_mode);
  for (int attempt = 0; attempt < 64; ++attempt) {
    tmp = target;
    tmp += fmt::format(".tmp.{:016x}", random_u64());
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) {
      if (keep_mode) (void)::fchmod(fd, st.st_mode & 07777);
      return fd;
    }
    if (errno != EEXIST) return -1;
  }
  return -1;
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  if (target_ == "-") {
    direct_ = true;
    tmp_ = target_;
    os_ = &std::cout;
    return;
  }
  errno = 0;
  int fd = -1;
  if (is_stream_output(target_)) {  // an existing device, FIFO or socket: written in place
    direct_ = true;
    tmp_ = target_;
    fd = ::open(tmp_.c_str(), O_WRONLY | O_CLOEXEC);
  } else {
    fd = create_temp(target_, tmp_);
  }
  if (fd < 0) throw InputError(target_.string(), 0, "", open_failure_reason(target_, tmp_));
  buf_ = std::make_unique<__gnu_cxx::stdio_filebuf<char>>(fd, std::ios::out | std::ios::binary, std::size_t{1} << 16);
  out_.rdbuf(buf_.get());
}

bool AtomicFile::close_file() noexcept {
  auto* fb = static_cast<__gnu_cxx::stdio_filebuf<char>*>(buf_.get());
  return fb == nullptr || !fb->is_open() || fb->close() != nullptr;
}

AtomicFile::~AtomicFile() {
  if (!committed_ && !direct_) {
    (void)close_file();
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  os_->flush();
  bool ok = static_cast<bool>(*os_);
  if (os_ == &out_) ok = close_file() && ok;
  if (!ok) throw InputError(target_.string(), 0, "", "write failed");
  if (!direct_) {
    std::error_code ec;
    std::filesystem::rename(tmp_, target_, ec);
    if (ec) throw InputError(target_.string(), 0, "", "cannot rename temporary file: " + ec.message());
  }
  committed_ = true;
}

}  // namespace lash
