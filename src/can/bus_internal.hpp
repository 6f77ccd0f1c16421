#pragma once
// Pieces shared by the bus implementations (not installed).
#include <sys/socket.h>

#include <atomic>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "lash/can/bus.hpp"

namespace lash::can::detail {

inline bool passes(const std::vector<Filter>& filters, const Frame& f) noexcept {
  if (filters.empty()) return true;
  for (const auto& flt : filters)
    if (flt.extended == f.extended && (f.id & flt.mask) == (flt.id & flt.mask)) return true;
  return false;
}

struct AtomicStats {
  std::atomic<std::uint64_t> sent{0}, received{0}, filtered{0}, dropped{0};
  BusStats load() const noexcept {
    return {sent.load(std::memory_order_relaxed), received.load(std::memory_order_relaxed),
            filtered.load(std::memory_order_relaxed), dropped.load(std::memory_order_relaxed)};
  }
};

/// Counts `f` as received when it passes `filters`, as filtered otherwise; true = deliver it.
inline bool accept(const std::vector<Filter>& filters, const Frame& f, AtomicStats& stats) noexcept {
  if (!passes(filters, f)) {
    stats.filtered.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  stats.received.fetch_add(1, std::memory_order_relaxed);
  return true;
}

/// The kernel receive time (SO_TIMESTAMPNS control message) of `msg` [s, CLOCK_REALTIME], if present.
inline void kernel_timestamp(msghdr& msg, double& timestamp_s) noexcept {
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPNS) {
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      timestamp_s = static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
    }
  }
}

std::unique_ptr<Bus> open_mem_bus(const std::string& name);
/// `spec` is the text after "udp:" (may be empty).
std::unique_ptr<Bus> open_udp_bus(const std::string& spec);
std::unique_ptr<Bus> open_socketcan_bus(const std::string& interface);

}  // namespace lash::can::detail
