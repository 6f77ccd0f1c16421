#include "lash/rt/dma_latency.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

namespace lash::rt {

DmaLatencyHold::DmaLatencyHold(bool enable) {
  if (!enable) {
    why_ = "disabled";
    return;
  }
  const int fd = ::open("/dev/cpu_dma_latency", O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    why_ = std::string("cannot open /dev/cpu_dma_latency (") + std::strerror(errno) + ")";
    return;
  }
  const std::int32_t zero_us = 0;  // the interface takes a binary s32 [µs]
  if (::write(fd, &zero_us, sizeof zero_us) != static_cast<ssize_t>(sizeof zero_us)) {
    why_ = std::string("cannot write /dev/cpu_dma_latency (") + std::strerror(errno) + ")";
    ::close(fd);
    return;
  }
  fd_ = fd;
  why_ = "held at 0 us";
}

DmaLatencyHold::~DmaLatencyHold() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace lash::rt
