#pragma once
/// @file bus.hpp
/// One interface for every CAN bus (in-memory, UDP multicast, SocketCAN).
/// Addresses are strings: "mem:NAME", "udp:239.74.163.2:43113", "socketcan:vcan0".
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lash/can/frame.hpp"

namespace lash::can {

/// Accept a frame when (frame.id & mask) == (id & mask) and the id format matches.
struct Filter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;  ///< 0 accepts everything
  bool extended = false;
};

/// Counters every bus keeps.
struct BusStats {
  std::uint64_t sent = 0;
  std::uint64_t received = 0;   ///< frames delivered to receive()
  std::uint64_t filtered = 0;   ///< frames dropped by filters
  std::uint64_t dropped = 0;    ///< malformed/oversized/unknown datagrams or queue overflow
};

/// What one Bus::receive_batch() call did.
struct BatchResult {
  std::size_t stored = 0;  ///< frames written to `out` (they passed the filters)
  std::size_t reads = 0;   ///< frames/datagrams taken from the medium
  bool drained = false;    ///< the medium had nothing more queued when the call returned
};

class Bus {
 public:
  virtual ~Bus() = default;
  /// Sends one frame. Returns false (and counts nothing as sent) on failure.
  virtual bool send(const Frame& frame) noexcept = 0;
  /// Waits up to `timeout` for the next frame that passes the filters.
  /// timeout 0 polls. The returned frame carries a receive timestamp [s].
  virtual std::optional<Frame> receive(std::chrono::nanoseconds timeout) noexcept = 0;
  /// Polls without waiting: stores up to out.size() frames that pass the filters, reading at
  /// most `max_reads` frames/datagrams from the medium (filtered, own and malformed ones
  /// count). The bound is what keeps a flood of unrelated frames from stretching a real-time
  /// step. The default calls receive(0).
  virtual BatchResult receive_batch(std::span<Frame> out, std::size_t max_reads) noexcept;
  /// Replaces the receive filters (an empty list accepts everything). Not real-time safe.
  virtual void set_filters(std::vector<Filter> filters) = 0;
  virtual BusStats stats() const noexcept = 0;
  virtual std::string address() const = 0;
};

/// Opens a bus from its address string; throws lash::InputError with a clear
/// message for an unknown scheme or when the bus cannot be opened
/// (e.g. "socketcan: this kernel has no CAN support"). Not real-time safe.
std::unique_ptr<Bus> open_bus(const std::string& address);

}  // namespace lash::can
