#pragma once
/// @file delay.hpp
/// Pure delay of n samples: out(k) = in(k − n), 0 before the first n samples.
/// Used to keep v aligned with a filtered y (thesis §1.4.5).
#include <cstddef>
#include <vector>

namespace lash {

class Delay {
 public:
  /// n = 0 passes through. Not real-time safe (allocates n slots).
  explicit Delay(std::size_t samples);
  double step(double x) noexcept {
    if (buf_.empty()) return x;
    const double out = buf_[pos_];
    buf_[pos_] = x;
    if (++pos_ == buf_.size()) pos_ = 0;
    return out;
  }
  void reset() noexcept;
  std::size_t samples() const noexcept { return buf_.size(); }

 private:
  std::vector<double> buf_;
  std::size_t pos_ = 0;
};

}  // namespace lash
