#pragma once
/// @file saturation.hpp
/// Saturation: clamps to [lower, upper] (e.g. a current driver's 0–2000 mA).

namespace lash {

class Saturation {
 public:
  /// Throws std::invalid_argument unless lower ≤ upper (infinities allowed, NaN not).
  Saturation(double lower, double upper);
  double step(double x) const noexcept { return x < lo_ ? lo_ : (x > hi_ ? hi_ : x); }
  void reset() noexcept {}
  double lower() const noexcept { return lo_; }
  double upper() const noexcept { return hi_; }

 private:
  double lo_;
  double hi_;
};

}  // namespace lash
