#include "lash/rt/periodic.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <functional>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <unistd.h>

namespace lash::rt {

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleep_until_ns(std::int64_t t_ns, const std::atomic<bool>* stop) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(t_ns % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) return;
  }
}

std::string use_fifo(int priority) {
  if (priority < 1 || priority > 99) return "SCHED_FIFO priority must be 1..99";
  sched_param sp{};
  sp.sched_priority = priority;
  if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
    return std::string("SCHED_FIFO priority ") + std::to_string(priority) + " refused (" + std::strerror(errno) +
           "; needs CAP_SYS_NICE or RLIMIT_RTPRIO)";
  return "";
}

Summary summarize(std::span<const double> values) {
  Summary s;
  s.n = values.size();
  if (values.empty()) return s;
  double sum = 0.0;
  s.min = values[0];
  s.max = values[0];
  for (double v : values) {
    sum += v;
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  s.mean = sum / static_cast<double>(s.n);
  if (s.n > 1) {
    double ss = 0.0;
    for (double v : values) ss += (v - s.mean) * (v - s.mean);
    s.std = std::sqrt(ss / static_cast<double>(s.n - 1));
  }
  std::vector<double> sorted(values.begin(), values.end());
  // Nearest rank: the ceil(0.99 n)-th smallest value.
  const auto rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(s.n)));
  const std::size_t idx = std::clamp<std::size_t>(rank, 1, s.n) - 1;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(idx), sorted.end());
  s.p99 = sorted[idx];
  return s;
}

StreamSummary::StreamSummary(std::size_t max_n) : tail_cap_(max_n / 100 + 2) { tail_.reserve(tail_cap_); }

void StreamSummary::add(double v) noexcept {
  if (n_ == 0) {
    min_ = max_ = v;
  } else {
    min_ = std::min(min_, v);
    max_ = std::max(max_, v);
  }
  ++n_;
  sum_ += v;
  const double d = v - mean_;
  mean_ += d / static_cast<double>(n_);
  m2_ += d * (v - mean_);
  const auto greater = std::greater<double>();
  if (tail_.size() < tail_cap_) {
    tail_.push_back(v);
    std::push_heap(tail_.begin(), tail_.end(), greater);
  } else if (v > tail_.front()) {
    std::pop_heap(tail_.begin(), tail_.end(), greater);
    tail_.back() = v;
    std::push_heap(tail_.begin(), tail_.end(), greater);
  }
}

Summary StreamSummary::result() const {
  Summary s;
  s.n = n_;
  if (n_ == 0) return s;
  s.min = min_;
  s.max = max_;
  s.mean = sum_ / static_cast<double>(n_);
  if (n_ > 1) s.std = std::sqrt(m2_ / static_cast<double>(n_ - 1));
  const auto rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(n_)));
  const std::size_t from_top = n_ - std::clamp<std::size_t>(rank, 1, n_);  // 0 = the largest
  std::vector<double> t = tail_;
  std::sort(t.begin(), t.end(), std::greater<double>());
  s.p99 = t[std::min(from_top, t.size() - 1)];
  return s;
}

const char* to_string(StopReason r) noexcept {
  switch (r) {
    case StopReason::completed: return "completed";
    case StopReason::requested: return "requested";
    case StopReason::step_returned_false: return "step_returned_false";
    case StopReason::overruns: return "overruns";
  }
  return "?";
}

PeriodicLoop::PeriodicLoop(LoopConfig cfg) : cfg_(cfg) {
  if (cfg_.period_ns <= 0) throw std::invalid_argument("rt: period must be > 0 ns");
  if (cfg_.max_steps == 0) throw std::invalid_argument("rt: max_steps must be > 0");
  if (cfg_.fifo_priority < 0 || cfg_.fifo_priority > 99)
    throw std::invalid_argument("rt: SCHED_FIFO priority must be in 0..99");
  if (cfg_.max_consecutive_overruns == 0) throw std::invalid_argument("rt: max_consecutive_overruns must be >= 1");
  if (cfg_.spin_ns < 0 || cfg_.spin_ns >= cfg_.period_ns)
    throw std::invalid_argument("rt: spin must be >= 0 and shorter than the period");
  records_.resize(cfg_.keep_records ? cfg_.max_steps : 0);
  overruns_.resize(cfg_.keep_records ? cfg_.max_steps : std::min(cfg_.max_steps, kMaxOverrunEvents));
}

namespace {
// Touch this much stack once so that page faults do not happen on the sample path.
void prefault_stack() noexcept {
  volatile unsigned char buf[256 * 1024];
  for (std::size_t i = 0; i < sizeof buf; i += 4096) buf[i] = 0;
}
}  // namespace

std::vector<std::string> PeriodicLoop::apply_realtime_settings() {
  std::vector<std::string> warnings;
  // A thread of the default scheduler has a timer slack of 50 us: the kernel may end each
  // clock_nanosleep up to that much after the release to batch wake-ups. A periodic loop
  // wants its release, not a batch: 1 ns (the least; SCHED_FIFO threads have none anyway).
  if (prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL) != 0)
    warnings.push_back(std::string("PR_SET_TIMERSLACK refused (") + std::strerror(errno) +
                       "): sleeps may end up to 50 us late");
  if (cfg_.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
      warnings.push_back(std::string("mlockall failed (") + std::strerror(errno) +
                         "): memory is not locked, page faults may add latency "
                         "(needs CAP_IPC_LOCK or a larger RLIMIT_MEMLOCK)");
    } else {
      prefault_stack();
      // Touch the preallocated buffers too.
      std::fill(records_.begin(), records_.end(), StepRecord{});
      std::fill(overruns_.begin(), overruns_.end(), OverrunEvent{});
    }
  }
  if (cfg_.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    const long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    if (cfg_.cpu >= CPU_SETSIZE || cfg_.cpu >= ncpu) {
      warnings.push_back("CPU " + std::to_string(cfg_.cpu) + " does not exist (" + std::to_string(ncpu) +
                         " online): affinity unchanged");
    } else {
      CPU_SET(static_cast<std::size_t>(cfg_.cpu), &set);
      if (sched_setaffinity(0, sizeof set, &set) != 0)
        warnings.push_back(std::string("sched_setaffinity failed (") + std::strerror(errno) +
                           "): affinity unchanged");
    }
  }
  if (cfg_.fifo_priority > 0) {
    sched_param sp{};
    sp.sched_priority = cfg_.fifo_priority;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
      warnings.push_back(std::string("SCHED_FIFO priority ") + std::to_string(cfg_.fifo_priority) + " refused (" +
                         std::strerror(errno) + "): running with the default scheduler "
                         "(needs CAP_SYS_NICE or RLIMIT_RTPRIO)");
  }
  return warnings;
}

namespace {
template <class Get>
Summary summarize_us(std::span<const StepRecord> records, Get get) {
  std::vector<double> v;
  v.reserve(records.size());
  for (const auto& r : records) v.push_back(static_cast<double>(get(r)) * 1e-3);
  return summarize(v);
}
}  // namespace

Summary tet_us(std::span<const StepRecord> records) {
  return summarize_us(records, [](const StepRecord& r) { return r.tet_ns; });
}
Summary wake_latency_us(std::span<const StepRecord> records) {
  return summarize_us(records, [](const StepRecord& r) { return r.wake_latency_ns; });
}
Summary io_us(std::span<const StepRecord> records) {
  return summarize_us(records, [](const StepRecord& r) { return r.io_ns; });
}
Summary cycle_us(std::span<const StepRecord> records) {
  return summarize_us(records, [](const StepRecord& r) { return r.io_ns + r.tet_ns; });
}

}  // namespace lash::rt
