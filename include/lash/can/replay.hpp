#pragma once
/// @file replay.hpp
/// Sends logged frames with their original timing (lash can replay).
///
/// Frame k goes out at the absolute CLOCK_MONOTONIC deadline t0 + (t_k − t_0)/speed:
/// the replay sleeps (rt::sleep_until_ns, interruptible) until `spin` before it and
/// then polls the clock for at most `spin`, so a stop request is seen within one
/// spin interval plus the signal delivery — never after a long gap in the log.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "lash/can/bus.hpp"
#include "lash/can/log.hpp"

namespace lash::can {

struct ReplayOptions {
  double speed = 1.0;                  ///< time scale (> 0; 2 = twice as fast)
  std::int64_t spin_ns = 2'000'000;    ///< busy-wait before each deadline [ns] (0..1e9)
  int fifo_priority = 0;               ///< SCHED_FIFO 1–99; 0 keeps the default scheduler
};

struct ReplayResult {
  std::size_t sent = 0;
  std::size_t failed = 0;
  bool interrupted = false;  ///< `stop` was set before the last frame
  std::string warning;       ///< e.g. SCHED_FIFO refused ("" if none)
};

/// Replays `entries` on `bus`. Throws std::invalid_argument for bad options.
ReplayResult replay(Bus& bus, std::span<const LogEntry> entries, const ReplayOptions& options,
                    const std::atomic<bool>& stop);
/// Replays the frames `next` hands out (false: the end), read as they are needed (a LogReader:
/// memory bounded whatever the log's length); each is read before the wait for its deadline.
/// `interrupted` when `stop` was seen before the end.
ReplayResult replay(Bus& bus, const std::function<bool(LogEntry&)>& next, const ReplayOptions& options,
                    const std::atomic<bool>& stop);

}  // namespace lash::can
