#pragma once
/// @file first_order.hpp
/// First-order discrete linear part (thesis eq. 8–10), piecewise per side:
/// w(k) = −a1·w(k−1) + b1·u(k−1), i.e. G(z) = b1 / (z + a1).
#include "lash/blocks/side.hpp"
#include "lash/metrics/first_order.hpp"

namespace lash {

struct FirstOrderParams {
  double a1 = 0.0;  ///< pole term: G(z) = b1/(z + a1); stable for |a1| < 1 [-]
  double b1 = 0.0;  ///< input gain [output unit / input unit]

  /// Zero-order-hold discretisation of K/(τs + 1) (eq. 9–10):
  /// a1 = −exp(−T/τ), b1 = K(1 − exp(−T/τ)). Throws unless τ > 0, T > 0.
  static FirstOrderParams from_continuous(double gain, double tau_s, double dt_s);
  /// Steady-state gain K = b1 / (1 + a1) (lash::static_gain).
  double gain() const noexcept { return static_gain(a1, b1); }
  /// Time constant τ = −T / ln(−a1) [s] (lash::time_constant_s); NaN unless −1 < a1 < 0.
  double tau_s(double dt_s) const noexcept { return time_constant_s(a1, dt_s); }
};

class FirstOrder {
 public:
  /// Throws std::invalid_argument unless all numbers are finite.
  explicit FirstOrder(PerSide<FirstOrderParams> p);

  /// @see Eq. (8): advances one sample with the parameters of `side` and
  /// returns w(k) computed from w(k−1), u(k−1); `u` is stored as u(k).
  double step(double u, Side side) noexcept {
    const auto& p = p_[side];
    w_ = -p.a1 * w_ + p.b1 * u_prev_;
    u_prev_ = u;
    return w_;
  }
  double step(double u) noexcept { return step(u, Side::right); }
  void reset() noexcept { w_ = 0.0; u_prev_ = 0.0; }
  double output() const noexcept { return w_; }
  const PerSide<FirstOrderParams>& params() const noexcept { return p_; }

 private:
  PerSide<FirstOrderParams> p_;
  double w_ = 0.0;
  double u_prev_ = 0.0;
};

}  // namespace lash
