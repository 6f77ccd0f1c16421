#pragma once
/// @file first_order.hpp
/// Physical figures of a discrete first-order lag y(k) = −a1·y(k−1) + b1·u(k−1) (docs/method.md §A1.3,
/// thesis eq. 9): its static gain and its time constant. One implementation for the whole
/// project (blocks, identify, control, sweep). Real-time safe (noexcept, no allocation).
#include <cmath>
#include <limits>

namespace lash {

/// Static gain K = b1/(1 + a1) [output unit / input unit] — the steady state of a unit step.
/// NaN when a1 = −1 (an integrator has no static gain) or an argument is not finite.
inline double static_gain(double a1, double b1) noexcept {
  const double den = 1.0 + a1;
  if (!(std::isfinite(a1) && std::isfinite(b1)) || den == 0.0) return std::numeric_limits<double>::quiet_NaN();
  return b1 / den;
}

/// Time constant τ = −T/ln(−a1) [s] of the sampled lag a1 = −e^{−T/τ}: defined only when
/// 0 < −a1 < 1 (a stable lag that does not oscillate); NaN otherwise.
inline double time_constant_s(double a1, double dt_s) noexcept {
  if (!(a1 < 0.0 && a1 > -1.0) || !(dt_s > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return -dt_s / std::log(-a1);
}

}  // namespace lash
