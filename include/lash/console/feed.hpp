#pragma once
/// @file feed.hpp
/// The console's input: one producer (the thread that measures) pushes samples of up to
/// kMaxSignals values into a lock-free single-producer/single-consumer ring (rt/spsc_queue.hpp);
/// the console's drain thread pops them. push() never blocks, never allocates and is O(1): a
/// full ring refuses the sample and the refusal is counted (shown in the page as drops, never
/// silent).
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "lash/rt/spsc_queue.hpp"

namespace lash::console {

inline constexpr std::size_t kMaxSignals = 32;

/// One sample: time [s] and the values of the first `count` signals (the order of
/// ConsoleOptions::signals). Trivially copyable.
struct Sample {
  double t_s = 0.0;
  std::uint32_t count = 0;
  std::array<double, kMaxSignals> values{};
};

class Feed {
 public:
  static constexpr std::size_t kCapacity = 4096;
  /// Producer side. noexcept, real-time safe; false (and a drop counted) when the ring is full.
  bool push(const Sample& s) noexcept {
    if (ring_.push(s)) return true;
    drops_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  /// Consumer side (the console's drain thread).
  bool pop(Sample& out) noexcept { return ring_.pop(out); }
  std::uint64_t drops() const noexcept { return drops_.load(std::memory_order_relaxed); }

 private:
  rt::SpscQueue<Sample, kCapacity> ring_;
  std::atomic<std::uint64_t> drops_{0};
};

}  // namespace lash::console
