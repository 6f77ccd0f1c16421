#include "lash/io/atomic_file.hpp"

#include <unistd.h>

#include <system_error>

#include "lash/io/error.hpp"

namespace lash {

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  tmp_ = target_;
  tmp_ += ".tmp." + std::to_string(::getpid());
  out_.open(tmp_, std::ios::out | std::ios::trunc | std::ios::binary);
  if (!out_) throw InputError(target_.string(), 0, "", "cannot open for writing");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok) throw InputError(target_.string(), 0, "", "write failed");
  std::error_code ec;
  std::filesystem::rename(tmp_, target_, ec);
  if (ec) throw InputError(target_.string(), 0, "", "cannot rename temporary file: " + ec.message());
  committed_ = true;
}

}  // namespace lash
