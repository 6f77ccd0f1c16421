// Unit tests of the periodic loop: statistics against hand-computed values and
// the loop's bookkeeping (no timing assertions: speed and jitter go to bench/).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <vector>

#include "lash/rt/periodic.hpp"

using namespace lash::rt;

TEST(RtSummary, HandComputed) {
  // 1..100: mean 50.5, sample std sqrt(sum (k-50.5)^2 / 99) = sqrt(841.666…) , p99 = 99th smallest = 99.
  std::vector<double> v;
  for (int k = 100; k >= 1; --k) v.push_back(k);
  const Summary s = summarize(v);
  EXPECT_EQ(s.n, 100u);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 100.0);
  EXPECT_NEAR(s.std, std::sqrt(100.0 * 101.0 / 12.0), 1e-12);  // n(n+1)/12 for 1..n
  EXPECT_DOUBLE_EQ(s.p99, 99.0);
}

TEST(RtSummary, SmallSamplesAndEmpty) {
  EXPECT_EQ(summarize({}).n, 0u);
  const std::vector<double> one{3.5};
  const Summary s = summarize(one);
  EXPECT_DOUBLE_EQ(s.mean, 3.5);
  EXPECT_DOUBLE_EQ(s.std, 0.0);
  EXPECT_DOUBLE_EQ(s.p99, 3.5);  // ceil(0.99) = 1st smallest
  const std::vector<double> ten{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  EXPECT_DOUBLE_EQ(summarize(ten).p99, 10.0);  // ceil(9.9) = 10th
}

// The streamed statistics against summarize() over the same values: min, max and the nearest-rank
// p99 exact (any n up to max_n), the mean bit for bit (same additions), the std to rounding.
TEST(RtSummary, StreamEqualsSummarize) {
  std::uint64_t x = 88172645463325252ULL;  // xorshift64: a fixed sequence with ties and outliers
  auto next = [&] {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return x;
  };
  for (std::size_t n : {1u, 2u, 99u, 100u, 101u, 199u, 200u, 201u, 1000u, 12345u}) {
    StreamSummary s(20000);
    std::vector<double> v;
    for (std::size_t i = 0; i < n; ++i) {
      const double a = static_cast<double>(next() % 1000) * 0.25 + (next() % 97 == 0 ? 1e4 : 0.0);
      v.push_back(a);
      s.add(a);
    }
    const Summary want = summarize(v), got = s.result();
    EXPECT_EQ(got.n, n);
    EXPECT_EQ(got.min, want.min) << n;
    EXPECT_EQ(got.max, want.max) << n;
    EXPECT_EQ(got.p99, want.p99) << n;
    EXPECT_EQ(got.mean, want.mean) << n;
    EXPECT_NEAR(got.std, want.std, 1e-9 * (1.0 + want.std)) << n;
  }
  EXPECT_EQ(StreamSummary(10).result().n, 0u);
}

// Without kept records the loop hands every record to on_record and keeps none: constant memory.
TEST(RtLoop, StreamedRecordsAreHandedOverNotKept) {
  LoopConfig c;
  c.period_ns = 200'000;
  c.max_steps = 20;
  c.keep_records = false;
  PeriodicLoop loop(c);
  std::vector<StepRecord> got;
  got.reserve(20);
  std::atomic<bool> stop{false};
  const RunResult r = loop.run_with_io([]() noexcept {}, [](std::size_t, std::int64_t) noexcept { return true; },
                                       []() noexcept {},
                                       [&](std::size_t k, const StepRecord& rec) noexcept {
                                         if (k == got.size()) got.push_back(rec);
                                       },
                                       stop);
  EXPECT_EQ(r.steps, 20u);
  EXPECT_TRUE(loop.records().empty());
  ASSERT_EQ(got.size(), 20u);
  for (std::size_t k = 0; k < got.size(); ++k) EXPECT_EQ(got[k].release_ns, static_cast<std::int64_t>(k) * 200'000);
}

TEST(RtLoop, RejectsBadConfig) {
  LoopConfig c;
  c.max_steps = 0;
  EXPECT_THROW(PeriodicLoop{c}, std::invalid_argument);
  c.max_steps = 1;
  c.period_ns = 0;
  EXPECT_THROW(PeriodicLoop{c}, std::invalid_argument);
  c.period_ns = 1000;
  c.fifo_priority = 100;
  EXPECT_THROW(PeriodicLoop{c}, std::invalid_argument);
  c.fifo_priority = 0;
  c.spin_ns = 1000;  // spin as long as the period: never sleeps
  EXPECT_THROW(PeriodicLoop{c}, std::invalid_argument);
  c.spin_ns = -1;
  EXPECT_THROW(PeriodicLoop{c}, std::invalid_argument);
}

TEST(RtLoop, SpinKeepsTheGridAndSetStartFixesThePhase) {
  // With a spin margin the releases are still exactly k·T after the start chosen by
  // set_start_ns(), and no step starts before its release.
  LoopConfig c;
  c.period_ns = 500'000;
  c.max_steps = 20;
  c.spin_ns = 100'000;
  PeriodicLoop loop(c);
  const std::int64_t start = monotonic_ns() + 2'000'000;
  loop.set_start_ns(start);
  std::atomic<bool> stop{false};
  std::vector<std::int64_t> begun;
  begun.reserve(20);
  loop.run([&](std::size_t, std::int64_t) noexcept { begun.push_back(monotonic_ns()); return true; }, stop);
  EXPECT_EQ(loop.start_ns(), start);
  ASSERT_EQ(begun.size(), 20u);
  for (std::size_t k = 0; k < 20; ++k) {
    EXPECT_EQ(loop.records()[k].release_ns, static_cast<std::int64_t>(k) * 500'000);
    EXPECT_GE(begun[k], start + static_cast<std::int64_t>(k) * 500'000);
    EXPECT_GE(loop.records()[k].wake_latency_ns, 0);
  }
}

TEST(RtLoop, RunsAllStepsOnAbsoluteGrid) {
  LoopConfig c;
  c.period_ns = 200'000;  // 0.2 ms
  c.max_steps = 50;
  PeriodicLoop loop(c);
  std::atomic<bool> stop{false};
  std::vector<std::size_t> seen;
  seen.reserve(50);
  const RunResult r = loop.run([&](std::size_t k, std::int64_t) noexcept { seen.push_back(k); return true; }, stop);
  EXPECT_EQ(r.steps, 50u);
  EXPECT_EQ(r.reason, StopReason::completed);
  ASSERT_EQ(loop.records().size(), 50u);
  for (std::size_t k = 0; k < 50; ++k) {
    EXPECT_EQ(seen[k], k);
    // Releases are exactly k·T from the start: absolute deadlines, no drift.
    EXPECT_EQ(loop.records()[k].release_ns, static_cast<std::int64_t>(k) * 200'000);
    EXPECT_GE(loop.records()[k].wake_latency_ns, 0);
    EXPECT_GE(loop.records()[k].tet_ns, 0);
  }
  EXPECT_EQ(loop.tet_us().n, 50u);
}

TEST(RtLoop, StepCanStopTheLoop) {
  LoopConfig c;
  c.period_ns = 100'000;
  c.max_steps = 100;
  PeriodicLoop loop(c);
  std::atomic<bool> stop{false};
  const RunResult r = loop.run([](std::size_t k, std::int64_t) noexcept { return k < 4; }, stop);
  EXPECT_EQ(r.steps, 5u);
  EXPECT_EQ(r.reason, StopReason::step_returned_false);
}

TEST(RtLoop, StopFlagEndsAtStepBoundary) {
  LoopConfig c;
  c.period_ns = 100'000;
  c.max_steps = 100;
  PeriodicLoop loop(c);
  std::atomic<bool> stop{false};
  const RunResult r = loop.run(
      [&](std::size_t k, std::int64_t) noexcept {
        if (k == 6) stop = true;
        return true;
      },
      stop);
  EXPECT_EQ(r.steps, 7u);
  EXPECT_EQ(r.reason, StopReason::requested);
}

TEST(RtLoop, OverrunsCountedAndPolicyStops) {
  // Every step busy-waits 3 periods: each one misses its deadline.
  LoopConfig c;
  c.period_ns = 50'000;
  c.max_steps = 20;
  c.policy = OverrunPolicy::stop;
  c.max_consecutive_overruns = 4;
  PeriodicLoop loop(c);
  std::atomic<bool> stop{false};
  auto busy = [](std::size_t, std::int64_t) noexcept {
    const auto t0 = monotonic_ns();
    while (monotonic_ns() - t0 < 150'000) {
    }
    return true;
  };
  const RunResult r = loop.run(busy, stop);
  EXPECT_EQ(r.reason, StopReason::overruns);
  EXPECT_EQ(r.steps, 4u);
  EXPECT_EQ(r.overruns, 4u);
  ASSERT_EQ(loop.overruns().size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(loop.overruns()[i].step, i);
    EXPECT_GT(loop.overruns()[i].late_ns, 0);
  }
  // Tolerate: runs to the end, counting every overrun.
  c.policy = OverrunPolicy::tolerate;
  c.max_steps = 6;
  PeriodicLoop tolerant(c);
  const RunResult r2 = tolerant.run(busy, stop);
  EXPECT_EQ(r2.reason, StopReason::completed);
  EXPECT_EQ(r2.steps, 6u);
  EXPECT_EQ(r2.overruns, 6u);
}

TEST(RtLoop, RealtimeSettingsWarnInsteadOfFailing) {
  LoopConfig c;
  c.max_steps = 1;
  c.cpu = 100000;  // no such CPU
  PeriodicLoop loop(c);
  const auto warnings = loop.apply_realtime_settings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("does not exist"), std::string::npos);
}

TEST(RtLoop, IoPhasesAreTimedApartFromTheTask) {
  // Input and output phases that each spin for >= 100 us around an empty task: the I/O time
  // holds both (>= 200 us), the TET does not, and the cycle is their sum.
  LoopConfig c;
  c.period_ns = 2'000'000;
  c.max_steps = 5;
  PeriodicLoop loop(c);
  std::atomic<bool> stop{false};
  auto spin = []() noexcept {
    const std::int64_t t0 = monotonic_ns();
    while (monotonic_ns() - t0 < 100'000) {
    }
  };
  std::vector<int> order;
  order.reserve(15);
  const RunResult r = loop.run_with_io([&]() noexcept { order.push_back(0); spin(); },
                                       [&](std::size_t, std::int64_t) noexcept { order.push_back(1); return true; },
                                       [&]() noexcept { order.push_back(2); spin(); }, stop);
  ASSERT_EQ(r.steps, 5u);
  for (std::size_t i = 0; i < order.size(); ++i) EXPECT_EQ(order[i], static_cast<int>(i % 3));
  for (const auto& rec : loop.records()) {
    EXPECT_GE(rec.io_ns, 200'000);
    EXPECT_LT(rec.tet_ns, rec.io_ns);
  }
  const Summary io = loop.io_us(), tet = loop.tet_us(), cyc = loop.cycle_us();
  EXPECT_GE(io.min, 200.0);
  EXPECT_NEAR(cyc.mean, io.mean + tet.mean, 1e-9);
}
