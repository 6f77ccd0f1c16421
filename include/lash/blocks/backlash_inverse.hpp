#pragma once
/// @file backlash_inverse.hpp
/// Backlash (deadband) inverse: the characteristic inverse BI(·) of Tao & Kokotović, *Adaptive
/// Control of Systems with Actuator and Sensor Nonlinearities*, Wiley 1996 (chapter on adaptive
/// backlash inverses; also "Continuous-time adaptive control of systems with unknown backlash",
/// IEEE Trans. Automatic Control 40(6), 1995).
///
/// The backlash it undoes (lash's `Deadband` of thesis eq. 5–6, slope 1, with a gap per
/// direction): the output y follows the input w at w − c_r while w pushes up, at w + c_l'
/// while w pushes down (c_l' = left half-width ≥ 0), and holds in between:
///   y(k) = w(k) − c_r    if w(k) > y(k−1) + c_r
///   y(k) = w(k) + c_l'   if w(k) < y(k−1) − c_l'
///   y(k) = y(k−1)        otherwise
/// lash's `Deadband` is the case c_r = c_l' = d (half-width d; Simulink's Backlash block and
/// Modelica's are parametrised by the full width 2d).
///
/// The inverse maps a desired output u to the input w: while u rises, w = u + c_r (the pin
/// pushes from behind); while u falls, w = u − c_l'; on a reversal of u's direction w jumps
/// across the deadband by c_r + c_l'; while u holds, w holds. Started engaged (reset(u0),
/// B's output = u0) B(BI(u)) = u exactly for every sequence u (the test checks it).
///
/// Chattering. A noisy u reverses every sample and the exact inverse then jumps across the
/// whole gap each time. With a smoothing band δ > 0 the offset o = w − u no longer jumps: it
/// moves towards +c_r (u rising) or −c_l' (u falling) in proportion to the travel of u,
///   o(k) = clamp(o(k−1) + (u(k) − u(k−1))·(c_r + c_l')/δ, −c_l', c_r),   w(k) = u(k) + o(k)
/// so the gap is crossed over δ of travel of u; the command is continuous and
/// |B(BI(u)) − u| ≤ δ (the output lags a reversal by at most δ). δ = 0 is the exact inverse.
///
/// Real time: step() and set_params() are noexcept, O(1) and allocation-free; the widths may
/// change between any two steps (the adaptive compensator does so).
namespace lash {

struct BacklashInverseParams {
  double right = 0.0;      ///< c_r ≥ 0: gap while the output is pushed up (half-width d) [unit of w]
  double left = 0.0;       ///< c_l' ≥ 0: gap while the output is pushed down [unit of w]
  double smoothing = 0.0;  ///< δ ≥ 0: travel of u over which the gap is crossed [unit of u]; 0 = jump

  /// Throws std::invalid_argument naming the field unless all are finite and ≥ 0.
  void validate() const;
};

class BacklashInverse {
 public:
  /// Throws std::invalid_argument (see BacklashInverseParams::validate). Starts engaged
  /// pushing up at u = 0 (w = c_r).
  explicit BacklashInverse(BacklashInverseParams p);

  /// Desired output u(k) → input w(k).
  double step(double u) noexcept {
    const double du = u - u_prev_;
    u_prev_ = u;
    const double hi = p_.right, lo = -p_.left;
    if (p_.smoothing > 0.0) {
      o_ += du * (hi - lo) / p_.smoothing;
    } else if (du > 0.0) {
      o_ = hi;
    } else if (du < 0.0) {
      o_ = lo;
    }
    o_ = o_ > hi ? hi : (o_ < lo ? lo : o_);
    return u + o_;
  }
  /// Starts from rest at output u0, engaged on the side given by `rising` (w = u0 + c_r when
  /// rising, u0 − c_l' otherwise); the backlash being inverted must start at y = u0.
  void reset(double u0 = 0.0, bool rising = true) noexcept {
    u_prev_ = u0;
    o_ = rising ? p_.right : -p_.left;
  }
  /// Replaces the widths between samples (e.g. from an online deadband estimate); negative or
  /// non-finite values keep the old ones. The current offset is clamped into the new gap.
  void set_params(const BacklashInverseParams& p) noexcept {
    const double old_r = p_.right, old_l = p_.left;
    if (p.right >= 0.0 && p.right < kHuge) p_.right = p.right;
    if (p.left >= 0.0 && p.left < kHuge) p_.left = p.left;
    if (p.smoothing >= 0.0 && p.smoothing < kHuge) p_.smoothing = p.smoothing;
    // Keep the engaged side and the fraction of the gap crossed: an offset at an end of the old
    // gap moves to the same end of the new one.
    if (o_ >= 0.0) o_ = old_r > 0.0 ? o_ / old_r * p_.right : p_.right;
    else o_ = old_l > 0.0 ? o_ / old_l * p_.left : -p_.left;
  }
  /// The current offset w − u [unit of w].
  double offset() const noexcept { return o_; }
  const BacklashInverseParams& params() const noexcept { return p_; }

 private:
  static constexpr double kHuge = 1e300;
  BacklashInverseParams p_;
  double u_prev_ = 0.0;
  double o_ = 0.0;
};

}  // namespace lash
