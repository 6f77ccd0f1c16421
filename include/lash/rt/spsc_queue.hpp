#pragma once
/// @file spsc_queue.hpp
/// A fixed-capacity single-producer single-consumer queue of trivially copyable values: the
/// hand-over between a real-time step and a non-real-time thread. push() and pop() never block,
/// never allocate and are O(1); a full queue refuses the push (the caller counts it).
/// One thread pushes, one thread pops; the slot is written before the release store of the
/// head and read after the acquire load of it, so no value is seen half-written.
#include <array>
#include <atomic>
#include <cstddef>
#include <type_traits>

namespace lash::rt {

template <class T, std::size_t N>
class SpscQueue {
  static_assert(std::is_trivially_copyable_v<T>);
  static_assert(N >= 2 && (N & (N - 1)) == 0, "capacity must be a power of two");

 public:
  /// Producer: false when full. noexcept, real-time safe.
  bool push(const T& v) noexcept {
    const std::size_t h = head_.load(std::memory_order_relaxed);
    if (h - tail_.load(std::memory_order_acquire) >= N) return false;
    slots_[h & (N - 1)] = v;
    head_.store(h + 1, std::memory_order_release);
    return true;
  }
  /// Consumer: false when empty. noexcept, real-time safe.
  bool pop(T& out) noexcept {
    const std::size_t t = tail_.load(std::memory_order_relaxed);
    if (t == head_.load(std::memory_order_acquire)) return false;
    out = slots_[t & (N - 1)];
    tail_.store(t + 1, std::memory_order_release);
    return true;
  }
  static constexpr std::size_t capacity() noexcept { return N; }

 private:
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::array<T, N> slots_{};
};

}  // namespace lash::rt
