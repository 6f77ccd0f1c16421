#pragma once
/// @file source.hpp
/// Where the monitor's frames come from: a bus (`udp:GROUP:PORT`, `socketcan:IFACE`, `mem:NAME`,
/// opened by lash::can::open_bus as `lash can dump` does) or a log file (candump, ASC, BLF, TRC
/// by extension, lash::can), read one frame at a time by can::LogReader (bounded memory, a FIFO
/// works too). Lines or objects a reader cannot parse are counted (garbage()) and skipped. Not
/// real-time code.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "lash/can/frame.hpp"

namespace lash::monitor {

class FrameSource {
 public:
  enum class Next : std::uint8_t { frame, idle, end };
  virtual ~FrameSource() = default;
  /// The next frame (its timestamp_s: log time, or the bus's receive time [s]); a bus returns
  /// `idle` when nothing arrived within `wait`; `end` at the end of a log.
  virtual Next next(can::Frame& out, std::chrono::nanoseconds wait) = 0;
  /// Lines / objects of a log that could not be read (skipped).
  virtual std::uint64_t garbage() const noexcept = 0;
  /// Frames the bus itself dropped (malformed datagrams, queue overflow).
  virtual std::uint64_t bus_dropped() const noexcept { return 0; }
  /// True for a bus: time passes without frames (now_s()).
  virtual bool live() const noexcept = 0;
  /// Wall-clock time in the epoch of a bus's timestamps (CLOCK_REALTIME) [s].
  double now_s() const noexcept;
};

/// Opens `spec`: a bus address (scheme `udp:`, `socketcan:`, `mem:`) or a log file path.
/// `realtime`: a log is delivered at its recorded pace (sleeping between frames, in slices of at
/// most 100 ms that look at `stop`). InputError (exit 2) for a missing file or a bad address.
std::unique_ptr<FrameSource> open_source(const std::string& spec, bool realtime = false,
                                         const std::atomic<bool>* stop = nullptr);

}  // namespace lash::monitor
