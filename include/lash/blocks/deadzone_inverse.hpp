#pragma once
/// @file deadzone_inverse.hpp
/// Deadzone inverse: the characteristic inverse DI(·) of Tao & Kokotović, *Adaptive Control of
/// Systems with Actuator and Sensor Nonlinearities*, Wiley 1996 (chapter on adaptive deadzone
/// inverses; also "Adaptive control of plants with unknown dead-zones", IEEE Trans. Automatic
/// Control 39(1), 1994); the thesis's controller (paper 2, §2.7.2, Fig 2.12) is its symmetric case.
///
/// The deadzone it undoes (lash's `Deadzone` block of eq. (1) with a slope per side):
///   DZ(v) = m_r·(v − c_r)  for v > c_r,   0 for c_l ≤ v ≤ c_r,   m_l·(v − c_l)  for v < c_l
/// with c_l ≤ 0 ≤ c_r. The inverse maps a desired deadzone output u to a command v:
///   v = c_r + u/m_r   if u > 0
///   v = c_l + u/m_l   if u < 0
///   v = 0             if u = 0
/// so that DZ(DI(u)) = u for every u (an identity; the test checks it on random signals).
///
/// Chattering. The exact inverse jumps by c_r − c_l where u crosses 0; a noisy u near zero
/// (a PID holding a set point at the edge of the deadzone) then flips the command between
/// the two edges every sample. The optional smoothing band δ ≥ 0 replaces the jump by a
/// straight line through the origin on each side:
///   v = u·(c_r + δ/m_r)/δ   for 0 ≤ u < δ,     v = u·(δ/m_l − c_l)/δ   for −δ < u < 0
/// which meets the exact branches at u = ±δ. Inside the band DZ(DI(u)) lies between 0 and u
/// (|DZ(DI(u)) − u| ≤ |u| < δ), outside it is exact. lash's choice: δ = 0 by default (the
/// thesis's controller), and a δ of a few times the noise of u (Kp × sensor noise) when the
/// loop holds a set point near the edge — a continuous command at the price of an error
/// bounded by δ there.
///
/// The thesis's own choice, `from_deadzone(288, 0.97)`, puts the edges 3 % inside the
/// identified deadzone "to prevent unintended actuation should there be a small error in
/// the deadzone estimate".
///
/// Real time: step() and set_params() are noexcept, O(1) and allocation-free; the
/// parameters may change between any two steps (the adaptive compensator does so).
namespace lash {

struct DeadzoneInverseParams {
  double offset_right = 0.0;  ///< c_r ≥ 0: right edge of the deadzone [input unit]
  double offset_left = 0.0;   ///< −c_l ≥ 0: magnitude of the left edge [input unit]
  double slope_right = 1.0;   ///< m_r > 0: deadzone slope right of c_r [output unit / input unit]
  double slope_left = 1.0;    ///< m_l > 0: deadzone slope left of c_l [output unit / input unit]
  double smoothing = 0.0;     ///< δ ≥ 0: smoothing band around u = 0 [output unit]; 0 = exact inverse

  /// The thesis's choice: fraction·deadzone on both sides (fraction 0.97, deadzone 288 mA).
  static DeadzoneInverseParams from_deadzone(double deadzone, double fraction = 0.97);
  /// Throws std::invalid_argument naming the field unless offsets are finite and ≥ 0, slopes
  /// finite and > 0 and the smoothing finite and ≥ 0.
  void validate() const;
};

class DeadzoneInverse {
 public:
  /// Throws std::invalid_argument (see DeadzoneInverseParams::validate).
  explicit DeadzoneInverse(DeadzoneInverseParams p);

  /// Desired deadzone output u → command v.
  double step(double u) const noexcept {
    const double d = p_.smoothing;
    if (u > 0.0) {
      if (u >= d) return p_.offset_right + u / p_.slope_right;
      return u * (p_.offset_right + d / p_.slope_right) / d;
    }
    if (u < 0.0) {
      if (-u >= d) return -p_.offset_left + u / p_.slope_left;
      return u * (p_.offset_left + d / p_.slope_left) / d;
    }
    return 0.0;
  }
  /// Replaces the edges between samples (e.g. from an online deadzone estimate); negative or
  /// non-finite values become 0 so the step stays well defined.
  void set_offsets(double right, double left) noexcept {
    p_.offset_right = (right > 0.0 && right < kHuge) ? right : 0.0;
    p_.offset_left = (left > 0.0 && left < kHuge) ? left : 0.0;
  }
  /// Replaces all parameters between samples; a value outside its domain keeps the old one.
  void set_params(const DeadzoneInverseParams& p) noexcept {
    set_offsets(p.offset_right, p.offset_left);
    if (p.slope_right > 0.0 && p.slope_right < kHuge) p_.slope_right = p.slope_right;
    if (p.slope_left > 0.0 && p.slope_left < kHuge) p_.slope_left = p.slope_left;
    if (p.smoothing >= 0.0 && p.smoothing < kHuge) p_.smoothing = p.smoothing;
  }
  void reset() noexcept {}
  const DeadzoneInverseParams& params() const noexcept { return p_; }

 private:
  static constexpr double kHuge = 1e300;
  DeadzoneInverseParams p_;
};

}  // namespace lash
