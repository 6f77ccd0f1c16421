#pragma once
/// @file verdict.hpp
/// The one decision "is this side identified, and if not, why" (issue 12 item 4), used by every
/// estimator of docs/method.md §A4 (the rules: §A4.7); `lash estimate`, `lash sweep` and library
/// users read it from the estimator (`params(s).reason`, `verdict(s)`), never re-decide it.
///
/// A side (for the linear model: the model) is identified only when, in this order,
///  1. it was updated enough (`min_updates` per key; deadzone-deadband: (c, d) also settled)
///     — else `not_updated`;
///  2. it was excited: the input v(k−1) and the output regressor y(k−1) each took more than one
///     value over the side's updates (a constant v makes b1 and the offset inseparable, a
///     constant y leaves a1 undetermined), v did not sit at one level (its largest or its
///     smallest value) on more than 90 % of them (a held input separates b1 and the offset
///     only in the transients after its switches: ValueRange::varied), and the information
///     matrix P⁻¹ of its RLS is well
///     conditioned (checked by `verdict()`, see `well_conditioned`) — else `not_excited`;
///  3. it is stable: finite and |a1| < 1 — else `unstable`;
///  4. it is physical: b1 > 0, the deadzone edge on its own side of zero (c_r ≥ 0 ≥ c_l:
///     friction, spring pretension or spool overlap contain zero, thesis §1.6.1), the deadband
///     half-width d ≥ 0 (coupled carts also −1 < a1 < 0: a positive time constant) — else
///     `unphysical`;
///  5. the switching guesses were right: an input-side model's edge lies inside its guesses,
///     c_l* < c < c_r* (eq. 18) — else `wrong_guess` (the side's guess is inside the deadzone);
///  6. the model fits: the free-run NRMSE of the whole model over its fit window is at most
///     `fit_threshold` (checked by `verdict()`) — else `poor_fit`;
///  7. where 95 % intervals were computed (`lash estimate`, the monitor; intervals.hpp), none of
///     them reaches a physically impossible value (a1 < 0 and τ > 0; K > 0; the
///     edge on its own side of zero; d ≥ 0) — else `uncertain` (interval_verdict);
///  8. only with `ci_tolerance` > 0 (config.hpp; off by default), where intervals are computed:
///     the side has intervals, and those of K, τ, c and d each lie within ±ci_tolerance of their
///     centre — else `uncertain` (precision_verdict).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

#include "lash/blocks/side.hpp"

namespace lash {

enum class Reason : std::uint8_t { none, not_updated, not_excited, unstable, unphysical, poor_fit, wrong_guess, uncertain };

/// "none", "not_updated", "not_excited", "unstable", "unphysical", "poor_fit", "wrong_guess", "uncertain".
const char* to_string(Reason r) noexcept;

/// The one text of both sides' verdicts, "right: <right>; left: <left>", written into `out`
/// (truncated to fit, always NUL-terminated; nothing written if out is empty). noexcept and
/// allocation-free: the master's real-time step reports it this way.
void both_sides_reason(std::span<char> out, const char* right, const char* left) noexcept;

/// Identified parameters of one side; NaN = not identified / not part of the model.
struct SideParams {
  double a1 = std::numeric_limits<double>::quiet_NaN();
  double b1 = std::numeric_limits<double>::quiet_NaN();
  double c = std::numeric_limits<double>::quiet_NaN();
  double d = std::numeric_limits<double>::quiet_NaN();
  bool identified = false;
  Reason reason = Reason::not_updated;  ///< none when identified
};

namespace verdict_rules {

/// The deadzone edge c of `s` lies on its own side of zero: c_r ≥ 0, c_l ≤ 0.
constexpr bool physical_edge(double c, Side s) noexcept { return s == Side::right ? c >= 0.0 : c <= 0.0; }

/// The range of the values one regressor took (the excitation check's value test).
struct Extent {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double x) noexcept {
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  /// More than one value (beyond rounding) was seen.
  bool several() const noexcept { return hi - lo > 1e-9 * std::max(1.0, std::max(std::fabs(hi), std::fabs(lo))); }
};

/// The range of the values one regressor took (excitation check), and how many of them sat at
/// its extremes (the held-level check).
struct ValueRange : Extent {
  std::uint64_t n = 0;     ///< values seen
  std::uint64_t n_lo = 0;  ///< of them at lo (within rounding), since lo last fell beyond it
  std::uint64_t n_hi = 0;  ///< of them at hi (within rounding), since hi last rose beyond it
  void add(double x) noexcept {
    const double tol = 1e-9 * std::max(1.0, std::fabs(x));
    ++n;
    if (x > hi + tol) {
      hi = x;
      n_hi = 1;
    } else if (x >= hi - tol) {
      ++n_hi;
    }
    if (x < lo - tol) {
      lo = x;
      n_lo = 1;
    } else if (x <= lo + tol) {
      ++n_lo;
    }
  }
  /// The share of the values that sat at one extreme, the larger of the two (0 when none was
  /// seen). A side whose input held one level (a square wave's ±A, a binary PRBS, a step) has
  /// most of its updates there; a sine, a triangle, a multisine or random levels have a few %.
  double held_share() const noexcept {
    return n == 0 ? 0.0 : static_cast<double>(std::max(n_lo, n_hi)) / static_cast<double>(n);
  }
  /// Several values, and no extreme held by more than `kMaxHeldShare` of them (check 2).
  bool varied() const noexcept { return several() && held_share() <= kMaxHeldShare; }
  /// Above this share of a side's updates at one input level the side is not excited: b1 and
  /// the edge's offset are then told apart by less than a tenth of its samples, the transients
  /// after the input's switches, where the fast dynamics the first-order model lacks sit
  /// (docs/method.md §A4.7). Measured: square waves 0.92–1, sines, triangles and random inputs
  /// at most 0.003; a few random levels per side (the monitor's 3 s sections) stay below it.
  static constexpr double kMaxHeldShare = 0.9;
};

/// What the update-time checks (1–5) see of one side.
struct Evidence {
  Side side = Side::right;
  bool updated = false;        ///< enough updates (and, where the model asks, settled)
  bool excited = false;        ///< v(k−1) and y(k−1) took more than one value; no singular solve
  double a1 = std::numeric_limits<double>::quiet_NaN();
  double b1 = std::numeric_limits<double>::quiet_NaN();
  bool has_c = false;          ///< the model has a deadzone edge (then c must be finite)
  double c = std::numeric_limits<double>::quiet_NaN();
  bool has_d = false;          ///< the model has a deadband half-width on this side
  double d = std::numeric_limits<double>::quiet_NaN();
  bool negative_a1 = false;    ///< coupled carts: also −1 < a1 < 0 (a positive time constant)
  bool guess_ok = true;        ///< input-side models: c_l* < c < c_r*
};

/// Checks 1–5 in order; Reason::none when all pass. noexcept, O(1).
Reason judge(const Evidence& e) noexcept;

/// Condition test of the information matrix P⁻¹ of an RLS (check 2, not on the sample path:
/// O(N³), no allocation). cond(P⁻¹) = cond(P): P (symmetrised) scaled to unit diagonal must have
/// its smallest eigenvalue above `kMinScaledEigenvalue` (1e-10) — exactly or nearly collinear
/// regressors (a correlation beyond 1 − 1e-10) fail.
template <std::size_t N>
bool well_conditioned(const std::array<std::array<double, N>, N>& P) noexcept;

inline constexpr double kMinScaledEigenvalue = 1e-10;

/// Checks 1–6 from the update-time reason, the information condition and the model's fit.
/// A NaN fit (no sample in the window, or y ≡ 0 there) is no evidence against the side.
constexpr Reason finish(Reason update_time, bool conditioned, double fit_nrmse, double fit_threshold) noexcept {
  if (update_time != Reason::none) return update_time;
  if (!conditioned) return Reason::not_excited;
  if (fit_nrmse > fit_threshold) return Reason::poor_fit;
  return Reason::none;
}

}  // namespace verdict_rules
}  // namespace lash
