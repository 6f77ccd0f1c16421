#pragma once
/// @file periodic.hpp
/// Fixed-step periodic loop on absolute deadlines (docs/method.md §B4, thesis paper 2 §2.7.3:
/// the xPC target ran the model every 5 ms and logged its task execution time).
///
/// Step k is released at r_k = start + k·T and the loop sleeps with
/// clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, r_k), so releases never drift.
/// Each step records
///   - the wake-up latency  s_k − r_k   (s_k = time the step starts),
///   - the task execution time (TET)  e_k − s_k  (e_k = time the step returns),
///   - with run_with_io(), the I/O time around the task: an input phase before it and an
///     output phase after it (an emulated CAN controller's reception and transmission,
///     can/controller_bus.hpp), timed apart from the TET; the cycle is I/O + TET,
/// into a buffer preallocated for the whole run (no allocation on the sample path), or, with
/// LoopConfig::keep_records = false, only to an on_record callback (run_with_io's streaming
/// form): the loop's memory is then constant, whatever the number of steps.
/// An overrun is a step whose cycle misses its deadline r_k + T: it starts after it
/// (released late by more than a period) or is still running at it. Overruns
/// are counted and timestamped; a late step is run at once (the grid is kept,
/// releases are not skipped) and, by policy, the loop is either tolerant or
/// stops after N consecutive overruns.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace lash::rt {

/// Current CLOCK_MONOTONIC time [ns]. noexcept, vDSO, no allocation.
std::int64_t monotonic_ns() noexcept;
/// Sleeps until the absolute CLOCK_MONOTONIC time `t_ns` (restarts after EINTR unless `stop` is set).
void sleep_until_ns(std::int64_t t_ns, const std::atomic<bool>* stop = nullptr) noexcept;
/// Switches the calling thread to SCHED_FIFO `priority` (1–99). Returns "" on success,
/// else why it was refused (the thread keeps its scheduler).
std::string use_fifo(int priority);

enum class OverrunPolicy : std::uint8_t { tolerate, stop };

struct LoopConfig {
  std::int64_t period_ns = 5'000'000;      ///< T [ns]
  std::size_t max_steps = 0;               ///< steps to run = size of the preallocated record buffer (> 0)
  std::int64_t start_ns = 0;               ///< absolute CLOCK_MONOTONIC time of r_0 [ns]; 0 = now + T
  int fifo_priority = 0;                   ///< SCHED_FIFO priority 1–99; 0 keeps the default scheduler
  bool lock_memory = false;                ///< mlockall(MCL_CURRENT | MCL_FUTURE) and pre-fault the stack
  int cpu = -1;                            ///< pin to this CPU; −1 = no affinity change
  std::int64_t spin_ns = 0;                ///< sleep until r_k − spin_ns, then busy-wait to r_k (0 = sleep only)
  OverrunPolicy policy = OverrunPolicy::tolerate;
  std::size_t max_consecutive_overruns = 10;  ///< policy stop: stop after this many in a row (≥ 1)
  /// true: every step's record is kept (records(), a buffer of max_steps records) and every
  /// overrun event; false: records go only to the on_record callback and at most
  /// kMaxOverrunEvents overrun events are kept (all are counted): constant memory.
  bool keep_records = true;
};

/// Overrun events a loop keeps when it does not keep its records (the rest are only counted).
inline constexpr std::size_t kMaxOverrunEvents = 4096;

/// One step as it happened.
struct StepRecord {
  std::int64_t release_ns = 0;       ///< r_k − start [ns]
  std::int64_t wake_latency_ns = 0;  ///< s_k − r_k [ns]
  std::int64_t tet_ns = 0;           ///< task execution time [ns]
  std::int64_t io_ns = 0;            ///< input + output phase time around the task [ns] (0 without I/O phases)
};

/// A step that missed its deadline.
struct OverrunEvent {
  std::size_t step = 0;
  std::int64_t t_ns = 0;     ///< start of the step relative to start [ns]
  std::int64_t late_ns = 0;  ///< e_k − (r_k + T) [ns] (> 0)
};

/// Sample statistics of one quantity.
struct Summary {
  std::size_t n = 0;
  double mean = 0, min = 0, max = 0, std = 0, p99 = 0;  ///< std: sample standard deviation (n − 1)
};
/// mean/min/max/std and the 99th percentile (nearest rank: the ⌈0.99·n⌉-th smallest).
Summary summarize(std::span<const double> values);

/// The same statistics over a stream of at most max_n values, in O(max_n/100) memory: the sum
/// (mean equal bit for bit to summarize()'s, same order of additions), Welford's running
/// variance (std equal to summarize()'s up to rounding), min, max, and the ⌈max_n/100⌉ + 2
/// largest values seen, which hold the nearest-rank 99th percentile of any n ≤ max_n values
/// exactly (n − ⌈0.99·n⌉ + 1 ≤ ⌊n/100⌋ + 1 of them lie at or above it). The tail is reserved
/// at construction: add() is noexcept-safe, allocation-free and O(log(max_n/100)).
class StreamSummary {
 public:
  explicit StreamSummary(std::size_t max_n = 0);
  void add(double v) noexcept;
  Summary result() const;
  std::size_t count() const noexcept { return n_; }

 private:
  std::size_t n_ = 0, tail_cap_ = 2;
  double sum_ = 0.0, mean_ = 0.0, m2_ = 0.0, min_ = 0.0, max_ = 0.0;
  std::vector<double> tail_;  ///< min-heap of the largest values
};

/// The same statistics over records [µs] (what PeriodicLoop's members return for its own).
Summary tet_us(std::span<const StepRecord> records);
Summary wake_latency_us(std::span<const StepRecord> records);
Summary io_us(std::span<const StepRecord> records);
Summary cycle_us(std::span<const StepRecord> records);

enum class StopReason : std::uint8_t { completed, requested, step_returned_false, overruns };
const char* to_string(StopReason r) noexcept;

struct RunResult {
  std::size_t steps = 0;
  std::size_t overruns = 0;
  StopReason reason = StopReason::completed;
};

class PeriodicLoop {
 public:
  /// Validates the configuration (throws std::invalid_argument) and preallocates the buffers.
  explicit PeriodicLoop(LoopConfig cfg);

  /// Applies SCHED_FIFO, mlockall and CPU affinity as configured. What is not permitted
  /// (EPERM, no such CPU, RLIMIT_MEMLOCK) is skipped and reported as a warning; the loop
  /// still runs with the default settings. Not real-time safe.
  std::vector<std::string> apply_realtime_settings();

  /// Runs step(k, t_ns) for k = 0, 1, … at the releases; `step` must be noexcept and return
  /// false to stop. t_ns is the step's start relative to start. Stops early when `stop` becomes
  /// true (checked at every step boundary and while sleeping).
  template <class Step>
  RunResult run(Step&& step, const std::atomic<bool>& stop) noexcept {
    return run_with_io([]() noexcept {}, std::forward<Step>(step), []() noexcept {}, stop);
  }

  /// As run(), with an input phase before and an output phase after each step (both
  /// noexcept callables). The TET times the step alone; the phases are recorded as I/O time;
  /// the deadline applies to the whole cycle.
  template <class Input, class Step, class Output>
  RunResult run_with_io(Input&& input, Step&& step, Output&& output, const std::atomic<bool>& stop) noexcept {
    return run_with_io(std::forward<Input>(input), std::forward<Step>(step), std::forward<Output>(output),
                       [](std::size_t, const StepRecord&) noexcept {}, stop);
  }

  /// As run_with_io(), and on_record(k, record) (noexcept) is called once per step after the
  /// output phase, outside the timed cycle, with the step's record: the streaming form (a
  /// node pushes its step's log and the record into its log writer's ring there).
  template <class Input, class Step, class Output, class OnRecord>
  RunResult run_with_io(Input&& input, Step&& step, Output&& output, OnRecord&& on_record,
                        const std::atomic<bool>& stop) noexcept {
    const std::int64_t T = cfg_.period_ns;
    start_ns_ = cfg_.start_ns != 0 ? cfg_.start_ns : monotonic_ns() + T;
    n_records_ = 0;
    n_overruns_ = 0;
    std::size_t steps = 0;
    RunResult res;
    std::size_t consecutive = 0;
    for (std::size_t k = 0; k < cfg_.max_steps; ++k) {
      const std::int64_t r = start_ns_ + static_cast<std::int64_t>(k) * T;
      if (cfg_.spin_ns > 0) {
        // Wake early and spin to the release: the core stays awake (no idle-state exit, no
        // hypervisor round trip) at the price of spin_ns of CPU per step.
        sleep_until_ns(r - cfg_.spin_ns, &stop);
        while (monotonic_ns() < r && !stop.load(std::memory_order_relaxed)) {
        }
      } else {
        sleep_until_ns(r, &stop);
      }
      if (stop.load(std::memory_order_relaxed)) {
        res.reason = StopReason::requested;
        break;
      }
      const std::int64_t s = monotonic_ns();
      input();
      const std::int64_t s_task = monotonic_ns();
      const bool keep_going = step(k, s - start_ns_);
      const std::int64_t e_task = monotonic_ns();
      output();
      const std::int64_t e = monotonic_ns();
      const StepRecord rec{r - start_ns_, s - r, e_task - s_task, (s_task - s) + (e - e_task)};
      if (n_records_ < records_.size()) records_[n_records_++] = rec;
      ++steps;
      on_record(k, rec);
      const std::int64_t deadline = r + T;
      if (e > deadline) {
        if (n_overruns_ < overruns_.size()) overruns_[n_overruns_] = OverrunEvent{k, s - start_ns_, e - deadline};
        ++n_overruns_;
        if (++consecutive >= cfg_.max_consecutive_overruns && cfg_.policy == OverrunPolicy::stop) {
          res.reason = StopReason::overruns;
          break;
        }
      } else {
        consecutive = 0;
      }
      if (!keep_going) {
        res.reason = StopReason::step_returned_false;
        break;
      }
    }
    res.steps = steps;
    res.overruns = n_overruns_;
    return res;
  }

  /// Sets r_0 for the next run (absolute CLOCK_MONOTONIC [ns]; 0 = now + T), e.g. once a
  /// handshake has fixed the phase: the loop is built (and its buffers touched) beforehand.
  void set_start_ns(std::int64_t t_ns) noexcept { cfg_.start_ns = t_ns; }
  const LoopConfig& config() const noexcept { return cfg_; }
  std::int64_t start_ns() const noexcept { return start_ns_; }
  std::span<const StepRecord> records() const noexcept { return {records_.data(), n_records_}; }
  /// The overrun events kept (all of them with keep_records; else the first kMaxOverrunEvents).
  std::span<const OverrunEvent> overruns() const noexcept {
    return {overruns_.data(), n_overruns_ < overruns_.size() ? n_overruns_ : overruns_.size()};
  }
  /// Every overrun so far (overruns() keeps at most the first kMaxOverrunEvents without records).
  std::size_t overrun_count() const noexcept { return n_overruns_; }
  /// Statistics over the recorded steps [µs]: TET, wake-up latency, I/O time, and the cycle
  /// (I/O + TET: what the deadline is checked against, wake-up latency excluded).
  Summary tet_us() const { return rt::tet_us(records()); }
  Summary wake_latency_us() const { return rt::wake_latency_us(records()); }
  Summary io_us() const { return rt::io_us(records()); }
  Summary cycle_us() const { return rt::cycle_us(records()); }

 private:
  LoopConfig cfg_;
  std::int64_t start_ns_ = 0;
  std::vector<StepRecord> records_;
  std::vector<OverrunEvent> overruns_;
  std::size_t n_records_ = 0;
  std::size_t n_overruns_ = 0;  ///< all overruns (the first overruns_.size() are kept)
};

}  // namespace lash::rt
