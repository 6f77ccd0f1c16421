#pragma once
/// @file moving_average.hpp
/// M-point non-weighted moving average that includes the current sample
/// (thesis §1.4.5): delay (M−1)/2 samples, variance of white noise / M.
/// Storage is allocated once at construction; step() is O(1).
#include <cmath>
#include <cstddef>
#include <vector>

namespace lash {

class MovingAverage {
 public:
  /// Throws std::invalid_argument unless length ≥ 1. Not real-time safe (allocates).
  explicit MovingAverage(std::size_t length);

  /// Mean of the last M inputs (missing history counts as 0, like every state at k = 0).
  /// Kept as an exact running sum with Neumaier compensation, so no drift over long runs.
  double step(double x) noexcept {
    const double old = buf_[pos_];
    buf_[pos_] = x;
    if (++pos_ == n_) pos_ = 0;
    add(x);
    add(-old);
    return (sum_ + comp_) / len_;
  }
  void reset() noexcept;
  std::size_t length() const noexcept { return buf_.size(); }
  /// Group delay (M−1)/2 [samples].
  double delay_samples() const noexcept { return 0.5 * static_cast<double>(buf_.size() - 1); }

 private:
  void add(double v) noexcept {
    const double t = sum_ + v;
    if (std::fabs(sum_) >= std::fabs(v)) comp_ += (sum_ - t) + v;  // fabs: no branch, the same comparison
    else comp_ += (v - t) + sum_;
    sum_ = t;
  }
  std::vector<double> buf_;
  double len_ = 1.0;  // M as a double (the same quotient as dividing by the converted size)
  std::size_t n_ = 1;  // M
  std::size_t pos_ = 0;
  double sum_ = 0.0;
  double comp_ = 0.0;
};

}  // namespace lash
