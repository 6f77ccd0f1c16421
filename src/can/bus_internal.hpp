#pragma once
// Pieces shared by the bus implementations (not installed).
#include <atomic>
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

std::unique_ptr<Bus> open_mem_bus(const std::string& name);
/// `spec` is the text after "udp:" (may be empty).
std::unique_ptr<Bus> open_udp_bus(const std::string& spec);
std::unique_ptr<Bus> open_socketcan_bus(const std::string& interface);

}  // namespace lash::can::detail
