#pragma once
/// @file difference.hpp
/// Backward difference (thesis eq. 26): ẋ(k) = (x(k) − x(k−1)) / T.
/// For white noise var(ẋ) = 2·var(x)/T² (eq. 33).

namespace lash {

class BackwardDifference {
 public:
  /// Throws std::invalid_argument unless dt_s > 0 and finite.
  explicit BackwardDifference(double dt_s);
  double step(double x) noexcept {
    const double d = (x - prev_) / dt_;
    prev_ = x;
    return d;
  }
  void reset() noexcept { prev_ = 0.0; }
  double dt_s() const noexcept { return dt_; }

 private:
  double dt_;
  double prev_ = 0.0;
};

}  // namespace lash
