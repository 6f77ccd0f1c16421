#pragma once
/// @file dma_latency.hpp
/// PM QoS: while an object of this class lives, the process holds /dev/cpu_dma_latency
/// open with the value 0 µs written to it, so the kernel keeps the CPUs out of deep idle
/// states whose exit latency would delay a real-time wake-up (what cyclictest does by
/// default; Documentation/power/pm_qos_interface.rst). The request ends when the file is
/// closed. Not real-time safe (open/write); hold it around a loop, not inside one.
#include <string>

namespace lash::rt {

class DmaLatencyHold {
 public:
  /// enable = false holds nothing. Failure (no such file, EACCES without root) is not an
  /// error: held() is false and why() says why.
  explicit DmaLatencyHold(bool enable = true);
  DmaLatencyHold(const DmaLatencyHold&) = delete;
  DmaLatencyHold& operator=(const DmaLatencyHold&) = delete;
  ~DmaLatencyHold();
  bool held() const noexcept { return fd_ >= 0; }
  const std::string& why() const noexcept { return why_; }

 private:
  int fd_ = -1;
  std::string why_;
};

}  // namespace lash::rt
