#include "lash/io/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>
#include <system_error>

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

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  if (target_ == "-") {
    direct_ = true;
    tmp_ = target_;
    os_ = &std::cout;
    return;
  }
  if (is_stream_output(target_)) {
    direct_ = true;
    tmp_ = target_;
    errno = 0;
    out_.open(tmp_, std::ios::out | std::ios::binary);
  } else {
    tmp_ = target_;
    tmp_ += ".tmp." + std::to_string(::getpid());
    errno = 0;
    out_.open(tmp_, std::ios::out | std::ios::trunc | std::ios::binary);
  }
  if (!out_) throw InputError(target_.string(), 0, "", open_failure_reason(target_, tmp_));
}

AtomicFile::~AtomicFile() {
  if (!committed_ && !direct_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  os_->flush();
  const bool ok = static_cast<bool>(*os_);
  if (os_ == &out_) out_.close();
  if (!ok) throw InputError(target_.string(), 0, "", "write failed");
  if (!direct_) {
    std::error_code ec;
    std::filesystem::rename(tmp_, target_, ec);
    if (ec) throw InputError(target_.string(), 0, "", "cannot rename temporary file: " + ec.message());
  }
  committed_ = true;
}

}  // namespace lash
