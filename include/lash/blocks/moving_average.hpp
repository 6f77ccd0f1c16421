#pragma once
/// @file moving_average.hpp
/// M-point non-weighted moving average that includes the current sample
/// (thesis §1.4.5): delay (M−1)/2 samples, variance of white noise / M.
/// Storage is allocated once at construction; step() is O(1).
#include <cstddef>
#include <vector>

namespace lash {

class MovingAverage {
 public:
  /// Throws std::invalid_argument unless length ≥ 1. Not real-time safe (allocates).
  explicit MovingAverage(std::size_t length);

  /// Mean of the last M inputs (missing history counts as 0, like every state at k = 0).
  /// The window sum is never a running sum (no value is ever subtracted), so it cannot drift:
  /// the window is the head of the current block of M samples (summed as they come) plus the
  /// tail of the previous block, whose suffix sums are recomputed from the stored values once
  /// per block (M additions every M samples). The output is a function of the window's values
  /// alone, with a rounding error below M·ε·Σ|x| however long the run.
  double step(double x) noexcept {
    buf_[pos_] = x;
    head_ += x;
    const double out = (head_ + buf_[n_ + pos_]) * inv_len_;  // buf_[n_ + p]: Σ old[p+1 .. M−1]
    if (++pos_ == n_) [[unlikely]] next_block();
    return out;
  }
  void reset() noexcept;
  std::size_t length() const noexcept { return n_; }
  /// Group delay (M−1)/2 [samples].
  double delay_samples() const noexcept { return 0.5 * static_cast<double>(n_ - 1); }

 private:
  /// A block of M samples is complete: its suffix sums become the tail of the next window.
  void next_block() noexcept {
    double t = 0.0;
    buf_[2 * n_ - 1] = 0.0;
    for (std::size_t i = n_ - 1; i > 0; --i) {
      t += buf_[i];
      buf_[n_ + i - 1] = t;
    }
    head_ = 0.0;
    pos_ = 0;
  }
  std::vector<double> buf_;  // [0, M): the current block's values; [M, 2M): the previous block's suffix sums
  double inv_len_ = 1.0;     // 1/M
  std::size_t n_ = 1;        // M
  std::size_t pos_ = 0;
  double head_ = 0.0;        // Σ of the current block's values so far
};

/// Two MovingAverage of the same length M stepped together (the preprocessor's v and y): the
/// same block scheme and the same operations per channel, so each output is bit for bit that
/// of a MovingAverage of its channel, with one position, one block test and one buffer of
/// (a, b) pairs (GCC/Clang vector extension: one SSE2/NEON operation per pair).
class MovingAveragePair {
 public:
  /// Throws std::invalid_argument unless length ≥ 1. Not real-time safe (allocates).
  explicit MovingAveragePair(std::size_t length);

  /// Means of the last M values of each channel (as MovingAverage::step per channel).
  void step(double a, double b, double& mean_a, double& mean_b) noexcept {
    const v2 x = {a, b};
    v2* const buf = buf_.data();
    buf[pos_] = x;
    head_ += x;
    const v2 out = (head_ + buf[n_ + pos_]) * inv_len_;
    if (++pos_ == n_) [[unlikely]] next_block();
    mean_a = out[0];
    mean_b = out[1];
  }
  void reset() noexcept;
  std::size_t length() const noexcept { return n_; }

 private:
  using v2 = double __attribute__((vector_size(16)));
  void next_block() noexcept {
    v2 t = {0.0, 0.0};
    buf_[2 * n_ - 1] = t;
    for (std::size_t i = n_ - 1; i > 0; --i) {
      t += buf_[i];
      buf_[n_ + i - 1] = t;
    }
    head_ = v2{0.0, 0.0};
    pos_ = 0;
  }
  std::vector<v2> buf_;  // as MovingAverage's, a pair per slot
  double inv_len_ = 1.0;
  std::size_t n_ = 1;
  std::size_t pos_ = 0;
  v2 head_ = {0.0, 0.0};
};

}  // namespace lash
