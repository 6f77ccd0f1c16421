#include "lash/can/replay.hpp"

#include <cmath>
#include <stdexcept>

#include "lash/rt/periodic.hpp"
#include "lash/io/numeric.hpp"

namespace lash::can {

ReplayResult replay(Bus& bus, const std::function<bool(LogEntry&)>& next, const ReplayOptions& o,
                    const std::atomic<bool>& stop) {
  if (!(o.speed > 0) || !std::isfinite(o.speed)) throw std::invalid_argument("replay: speed must be > 0");
  if (o.spin_ns < 0 || o.spin_ns > 1'000'000'000) throw std::invalid_argument("replay: spin must be 0..1 s");
  if (o.fifo_priority < 0 || o.fifo_priority > 99) throw std::invalid_argument("replay: SCHED_FIFO priority must be 0..99");
  ReplayResult res;
  LogEntry e;
  if (!next(e)) return res;
  if (o.fifo_priority > 0) res.warning = rt::use_fifo(o.fifo_priority);
  // Every frame, the first included, goes out at an absolute deadline; the 10 ms lead
  // lets the first one take the same (warm) path as the rest.
  const std::int64_t t0 = rt::monotonic_ns() + 10'000'000;
  const double log0 = e.frame.timestamp_s;
  for (bool more = true; more; more = next(e)) {
    if (stop.load(std::memory_order_relaxed)) {
      res.interrupted = true;
      break;
    }
    const double dt = (e.frame.timestamp_s - log0) / o.speed;
    // Frames of a log span at most ~1e12 s (can::writable_times); a later one waits ~146 years.
    const std::int64_t deadline = t0 + round_clamped<std::int64_t>(dt * 1e9, 0, std::int64_t{1} << 62);
    rt::sleep_until_ns(deadline - o.spin_ns, &stop);
    while (rt::monotonic_ns() < deadline && !stop.load(std::memory_order_relaxed)) {
    }
    if (stop.load(std::memory_order_relaxed)) {
      res.interrupted = true;
      break;
    }
    if (bus.send(e.frame)) {
      ++res.sent;
    } else {
      ++res.failed;
    }
  }
  return res;
}

ReplayResult replay(Bus& bus, std::span<const LogEntry> entries, const ReplayOptions& o, const std::atomic<bool>& stop) {
  std::size_t i = 0;
  return replay(
      bus,
      [&](LogEntry& e) {
        if (i >= entries.size()) return false;
        e = entries[i++];
        return true;
      },
      o, stop);
}

}  // namespace lash::can
