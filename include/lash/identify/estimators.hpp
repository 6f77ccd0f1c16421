#pragma once
/// @file estimators.hpp
/// The switching RLS estimators of docs/method.md §A4 (thesis §1.4, §1.6). Each takes one sample
/// (v(k), y(k)) per step(), which is noexcept, O(1) and allocation-free; construction
/// validates the EstimatorConfig (std::invalid_argument) and allocates the filters.
///
/// Every estimator exposes per side a1, b1 (and c, d where the model has them), update
/// counts per key, `identified`, the one-step prediction ŷ and a free-run simulated output
/// y_sim of the identified model driven by v alone. A parameter that is not identified yet
/// is NaN — never a huge number.
///
/// Regression (docs/method.md §A4): φ(k) = [−y(k−1), v(k−1), 1], η = [a1, b1, e].
///
/// restart() (after a gap in the record's timestamps, docs/identification.md "Gaps") clears the
/// signal history — filters, delays, derivative, the direction-hold counters, the previous samples
/// and the instruments — but keeps the parameter estimates, covariances, update counts and the
/// verdict's evidence. The next warmup() samples refill that history and update nothing, so no
/// regression ever mixes samples from both sides of a gap. The free-run simulation y_sim is a
/// model driven by v alone, not a regression: it runs on. restart() is noexcept and allocation-free.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "lash/blocks/side.hpp"
#include "lash/identify/config.hpp"
#include "lash/identify/preprocess.hpp"
#include "lash/identify/rls.hpp"
#include "lash/identify/verdict.hpp"
#include "lash/metrics/fit.hpp"

namespace lash {

namespace detail {
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double deadzone(double x, double cl, double cr) noexcept {
  return x > cr ? x - cr : (x < cl ? x - cl : 0.0);
}
using ValueRange = verdict_rules::ValueRange;
/// Samples after a restart() before a regression may use a sample again: the preprocessor's
/// memory, the previous samples y(k−1), y(k−2) and, for IV, the instrument's delay.
inline std::uint32_t warmup_samples(const EstimatorConfig& c, const Preprocessor& p) noexcept {
  const std::size_t iv = c.method == EstimationMethod::iv ? c.iv_delay + 1 : 0;
  return static_cast<std::uint32_t>(p.memory_samples() + 2 + iv);
}
/// Fixed ring of the last 64 values (instrument history).
struct History {
  std::array<double, 64> buf{};
  unsigned pos = 0;
  void push(double x) noexcept { buf[pos++ & 63u] = x; }
  /// j = 1 → last pushed value.
  double ago(std::size_t j) const noexcept { return buf[(pos - static_cast<unsigned>(j)) & 63u]; }
};
/// The one free-run side choice of the two-sided models: right above the right edge, left below
/// the left edge, otherwise (inside the deadzone) the side last used (thesis §1.4.2, docs/method.md §A4.2);
/// by_sign: the side of the sign of x (eq. 34).
constexpr Side free_run_side(double x, const PerSide<double>& edge, Side last, bool by_sign = false) noexcept {
  if (by_sign) return side_of(x);
  return x > edge.right ? Side::right : (x < edge.left ? Side::left : last);
}
/// Input-side switching (eq. 18): right when v(k−1) > c_r*, left when v(k−1) < c_l*, none inside.
constexpr std::optional<Side> guess_side(double v1, const EstimatorConfig& c) noexcept {
  if (v1 > c.guess_right) return Side::right;
  if (v1 < c.guess_left) return Side::left;
  return std::nullopt;
}
/// Free-run fit of a model (verdict check 6): NRMSE of y_sim against y over t ≥ fit_start_s, or
/// over every sample when the record ends before that.
struct FitWindow {
  std::uint64_t k0 = 0, k = 0;
  NrmseAccumulator window, before;  // t ≥ fit_start_s, and the samples before it
  void add(double y, double ysim) noexcept {
    if (k++ >= k0) [[likely]]
      window.add(y, ysim);
    else
      before.add(y, ysim);
  }
  /// The window's NRMSE; the whole record's when it ended before the window began.
  double nrmse() const noexcept { return window.n > 0 ? window.value() : before.value(); }
};
}  // namespace detail

/// Linear first-order model (eq. 9–12): φ = [−y(k−1), v(k−1)], η = [a1, b1]; every sample updates.
/// The verdict is that of the whole model (reported on Side::right and Side::left alike).
class LinearEstimator {
 public:
  explicit LinearEstimator(const EstimatorConfig& cfg);
  /// Advances one sample; returns ŷ(k) = φᵀη̂(k−1) (eq. 14). A non-finite sample changes nothing
  /// but the skip count (ŷ = NaN).
  double step(double v, double y) noexcept;
  double prediction() const noexcept { return yhat_; }
  double simulated() const noexcept { return ysim_; }
  /// a1, b1 with the update-time verdict (checks 1–5 of verdict.hpp); NaN while not identified.
  SideParams params() const noexcept;
  SideParams params(Side) const noexcept { return params(); }
  /// The full verdict (checks 1–6): what reports show.
  Reason verdict(Side = Side::right) const noexcept;
  std::uint64_t updates() const noexcept { return rls_.updates(); }
  std::uint64_t updates(Side) const noexcept { return rls_.updates(); }
  std::uint64_t skipped() const noexcept { return skipped_ + rls_.skipped(); }
  bool identified() const noexcept { return verdict() == Reason::none; }
  /// NRMSE of the free run y_sim against y (verdict check 6, a fraction).
  double fit_nrmse() const noexcept { return fit_.nrmse(); }
  const Rls<2>& rls() const noexcept { return rls_; }
  const EstimatorConfig& config() const noexcept { return cfg_; }
  /// Back to the state right after construction. Not real-time safe (reallocates the filters).
  void reset() { *this = LinearEstimator(cfg_); }
  /// After a gap: clears the signal history, keeps the estimates (see the file comment).
  void restart() noexcept;
  /// Samples after restart() that update nothing.
  std::uint32_t warmup() const noexcept { return warmup_; }
  /// True while samples of that warm-up are still to go (after the last step()).
  bool warming_up() const noexcept { return warm_ > 0; }

 private:
  EstimatorConfig cfg_;
  Preprocessor pre_;
  Rls<2> rls_;
  std::uint32_t warmup_ = 0, warm_ = 0;  // warm-up length; samples of it still to go
  detail::History hist_;
  detail::ValueRange vrange_, yrange_;
  detail::FitWindow fit_;
  double y1_ = 0.0, v1_ = 0.0, vraw1_ = 0.0, x_ = 0.0;
  double yhat_ = 0.0, ysim_ = 0.0;
  std::uint64_t skipped_ = 0;
};

namespace detail {
/// What the two deadzone estimators share: one Rls<3> per side (η = [a1, b1, e]), the side
/// parameters, the parameter set the free run uses per side, the preprocessor and the
/// accessors. The models differ in their switching rule and in how c follows from e.
class TwoSideEstimator {
 public:
  double prediction() const noexcept { return yhat_; }
  double simulated() const noexcept { return ysim_; }
  SideParams params(Side s) const noexcept { return p_[s]; }
  Reason verdict(Side s) const noexcept;
  std::uint64_t updates(Side s) const noexcept { return rls_[s].updates(); }
  std::uint64_t skipped() const noexcept { return skipped_ + rls_.right.skipped() + rls_.left.skipped(); }
  bool identified() const noexcept { return verdict(Side::right) == Reason::none && verdict(Side::left) == Reason::none; }
  double fit_nrmse() const noexcept { return fit_.nrmse(); }
  const Rls<3>& rls(Side s) const noexcept { return rls_[s]; }
  const EstimatorConfig& config() const noexcept { return cfg_; }
  /// After a gap: clears the signal history, keeps the estimates (see the file comment).
  void restart() noexcept;
  std::uint32_t warmup() const noexcept { return warmup_; }
  /// True while samples of that warm-up are still to go (after the last step()).
  bool warming_up() const noexcept { return warm_ > 0; }

 protected:
  explicit TwoSideEstimator(const EstimatorConfig& cfg);
  /// Side s after an update, with its deadzone edge c (NaN when the model cannot give one) and
  /// whether c lies inside the switching guesses. The free run holds the side's last stable set
  /// (finite, |a1| < 1); the verdict (verdict.hpp) decides whether the side is identified.
  void refresh(Side s, double c, bool guess_ok) noexcept;
  /// Updates side s's RLS with φ = [−y(k−1), v(k−1), 1] (or its instrument); returns ŷ.
  double update(Side s, double y) noexcept;

  EstimatorConfig cfg_;
  Preprocessor pre_;
  PerSide<Rls<3>> rls_;
  std::uint32_t warmup_ = 0, warm_ = 0;
  PerSide<SideParams> p_{};
  PerSide<double> sa1_{}, sb1_{}, sc_{};  // parameters used by the free-run simulation
  PerSide<ValueRange> vrange_{}, yrange_{};  // v(k−1), y(k−1) over each side's updates
  History hist_;
  FitWindow fit_;
  double y1_ = 0.0, v1_ = 0.0, vraw1_ = 0.0;
  Side sim_last_ = Side::right;
  double yhat_ = 0.0, ysim_ = 0.0;
  std::uint64_t skipped_ = 0;
};
}  // namespace detail

/// Input deadzone (§1.4.2, eq. 17–22): side r when v(k−1) > c_r*, l when v(k−1) < c_l*;
/// e = −b1·c so c = −e/b1. Inside the guesses nothing is updated.
class InputDeadzoneEstimator : public detail::TwoSideEstimator {
 public:
  explicit InputDeadzoneEstimator(const EstimatorConfig& cfg);
  double step(double v, double y) noexcept;
  /// Online re-guessing (identify/reguess.hpp): sets side s's switching guess (guess_right or
  /// guess_left of the config) and restarts only that side's recursion — its RLS (estimate,
  /// covariance, update count) and its verdict evidence; the other side, the signal history and
  /// the free-run model are untouched. noexcept, O(1), allocation-free.
  void set_guess(Side s, double guess) noexcept;
  void reset() { *this = InputDeadzoneEstimator(cfg_); }

 private:
  void refresh(Side s) noexcept;
  double w_ = 0.0;
  Side last_ = Side::right;
};

/// Output deadzone (§1.6.1, eq. 36, motor cart): side r when y(k) > 0 and y(k−1) > 0,
/// side l when both < 0 (|y| ≤ zero_threshold counts as 0); e = −c(1 + a1).
class OutputDeadzoneEstimator : public detail::TwoSideEstimator {
 public:
  explicit OutputDeadzoneEstimator(const EstimatorConfig& cfg);
  double step(double v, double y) noexcept;
  void reset() { *this = OutputDeadzoneEstimator(cfg_); }

 private:
  void refresh(Side s) noexcept;
  double x_ = 0.0;
};

/// Input deadzone + output deadband (§1.4.3, eq. 23–32): four RLS keyed l+, l−, r+, r−.
/// Side from v(k−1) against the guesses; direction + when y(k) > y(k−1) > y(k−2) (with the
/// ẏ dead band: ẏ(k), ẏ(k−1) > threshold), − likewise; otherwise no update.
/// e+ = −d(1 + a1+) − b1+·c, e− = d(1 + a1−) − b1−·c; (d, c) from the 2×2 system of eq. 31/32.
/// A side's a1 and b1 are the update-count-weighted means of its + and − estimators.
class DeadzoneDeadbandEstimator {
 public:
  enum Key : int { right_plus = 0, right_minus = 1, left_plus = 2, left_minus = 3 };
  static constexpr Key key(Side s, bool plus) noexcept {
    return static_cast<Key>((s == Side::right ? 0 : 2) + (plus ? 0 : 1));
  }

  explicit DeadzoneDeadbandEstimator(const EstimatorConfig& cfg);
  double step(double v, double y) noexcept;
  /// Online re-guessing (identify/reguess.hpp): sets side s's switching guess (guess_right or
  /// guess_left of the config) and restarts only that side's recursion — its RLS (estimate,
  /// covariance, update count) and its verdict evidence; the other side, the signal history and
  /// the free-run model are untouched. noexcept, O(1), allocation-free.
  void set_guess(Side s, double guess) noexcept;
  void reset() { *this = DeadzoneDeadbandEstimator(cfg_); }
  /// After a gap: clears the signal history, keeps the estimates (see the file comment).
  void restart() noexcept;
  std::uint32_t warmup() const noexcept { return warmup_; }
  /// True while samples of that warm-up are still to go (after the last step()).
  bool warming_up() const noexcept { return warm_ > 0; }

  double prediction() const noexcept { return yhat_; }
  double simulated() const noexcept { return ysim_; }
  /// Current parameters (computed from the four/two RLS on each call).
  SideParams params(Side s) const noexcept;
  Reason verdict(Side s) const noexcept;
  /// Updates of key (side, +) or (side, −).
  std::uint64_t updates(Side s, bool plus) const noexcept { return count_[key(s, plus)]; }
  /// Updates of the side (both directions).
  std::uint64_t updates(Side s) const noexcept { return count_[key(s, true)] + count_[key(s, false)]; }
  std::uint64_t skipped() const noexcept;
  bool identified() const noexcept { return verdict(Side::right) == Reason::none && verdict(Side::left) == Reason::none; }
  double fit_nrmse() const noexcept { return fit_.nrmse(); }
  const EstimatorConfig& config() const noexcept { return cfg_; }
  /// Raw [a1, b1, e] of one key (separate-RLS mode).
  const Rls<3>& rls(Key k) const noexcept { return rls_[k]; }
  /// The 4-parameter regression of one side (pooled mode).
  const Rls<4>& pooled_rls(Side s) const noexcept { return pooled_[s]; }

 private:
  /// A side's raw parameters with their update-time verdict, and whether they may drive the
  /// free run (the method's own premise; see derive()).
  struct Derived {
    SideParams p;
    bool usable = false;
  };
  /// with_verdict = false: the values and `usable` only (p.reason left at its default).
  Derived derive(Side s, bool with_verdict = true) const noexcept;
  void refresh(Side s) noexcept;
  double predict_free(Side s, double y1, double v1) const noexcept;
  void simulate(double v) noexcept;

  EstimatorConfig cfg_;
  Preprocessor pre_;
  std::array<Rls<3>, 4> rls_;
  PerSide<Rls<4>> pooled_;
  std::array<std::uint64_t, 4> count_{};
  PerSide<bool> usable_{};
  struct FreeRunSide {  // the free-run model of a side, read together on every sample
    double a1 = 0.0, b1 = 0.0, d = 0.0;
  };
  PerSide<FreeRunSide> sim_{};
  PerSide<double> sc_{};
  PerSide<double> prev_c_{}, prev_d_{};
  PerSide<std::uint32_t> settled_{};
  PerSide<std::uint32_t> since_{};
  PerSide<detail::ValueRange> vrange_{}, yrange_{};
  detail::History hist_;
  detail::FitWindow fit_;
  double y1_ = 0.0, v1_ = 0.0, vraw1_ = 0.0, w_ = 0.0;
  Side last_ = Side::right, sim_last_ = Side::right;
  int regime1_ = 0;  // the last sample's regime (step()): direction of motion × guess side, 0 = not moving
  std::uint32_t run_ = 0;
  std::uint32_t warmup_ = 0, warm_ = 0;
  double yhat_ = 0.0, ysim_ = 0.0;
  std::uint64_t skipped_ = 0;
};

/// Free cart loosely coupled to a motor cart (§1.6.3, eq. 38–41). y is the free cart's
/// position; its velocity ẏ (backward difference, eq. 26) equals the motor cart's velocity ẇ
/// while the pin is engaged and 0 inside the position deadband.
/// Stage 1: output-deadzone velocity model (eq. 38) updated on samples where the free cart
/// has moved in one direction for three samples (so ẏ(k), ẏ(k−1) are both ẇ) and
/// |ÿ| ≤ accel_limit. A side is identified when the verdict (verdict.hpp) says so, with
/// −1 < a1 < 0 required (a positive time constant).
/// Stage 2 (t ≥ stage2_start_s, both sides usable): the free-run velocity model is
/// integrated to ŵ; engaged, y − ŵ = o ∓ d (moving ±). o drifts (ŵ is an open-loop integral),
/// so d is taken per slot crossing: when the free cart starts moving the other way, y − ŵ has
/// changed by ±2d since its last moving sample. d = mean over crossings (available after the
/// first); o = least-squares offset given d. The free run uses only usable parameter sets
/// (the last one per side: enough updates, −1 < a1 < 0, c on its side of zero, input
/// exciting); a side never usable predicts no motion.
class CoupledCartsEstimator {
 public:
  explicit CoupledCartsEstimator(const EstimatorConfig& cfg);
  double step(double v, double y) noexcept;
  void reset() { *this = CoupledCartsEstimator(cfg_); }
  /// After a gap: clears the signal history (and the open slot crossing), keeps the estimates.
  void restart() noexcept;
  std::uint32_t warmup() const noexcept { return warmup_; }
  /// True while samples of that warm-up are still to go (after the last step()).
  bool warming_up() const noexcept { return warm_ > 0; }
  double prediction() const noexcept { return yhat_; }
  double simulated() const noexcept { return ysim_; }
  /// Velocity model per side (a1, b1, c) and the shared deadband half-width d.
  SideParams params(Side s) const noexcept;
  Reason verdict(Side s) const noexcept;
  double deadband() const noexcept;
  /// Verdict of the shared deadband: not_updated before the first slot crossing, unphysical if d < 0.
  Reason deadband_reason() const noexcept;
  std::uint64_t updates(Side s) const noexcept { return rls_[s].updates(); }
  /// Stage-2 slot crossings that ended moving + (plus = true) or −.
  std::uint64_t deadband_updates(bool plus) const noexcept { return dcount_[plus ? 0 : 1]; }
  std::uint64_t skipped() const noexcept;
  bool identified() const noexcept;
  double fit_nrmse() const noexcept { return fit_.nrmse(); }
  const EstimatorConfig& config() const noexcept { return cfg_; }
  /// Simulated motor-cart velocity ŵ̇ and position ŵ (+ offset).
  double simulated_velocity() const noexcept { return wdot_; }

 private:
  void refresh(Side s) noexcept;
  EstimatorConfig cfg_;
  Preprocessor pre_;
  PerSide<Rls<3>> rls_;
  std::array<std::uint64_t, 2> dcount_{};  // stage-2 crossings ending in motion + / −
  double dsum_ = 0.0, r_last_ = 0.0, osum_ = 0.0, odir_ = 0.0;
  std::uint64_t on_ = 0;
  int dir_last_ = 0;
  bool r_ok_ = false;
  PerSide<SideParams> p_{};
  PerSide<double> sa1_{}, sb1_{}, sc_{};  // last usable set per side (free run)
  PerSide<bool> valid_{};                   // side usable at least once
  PerSide<detail::ValueRange> vrange_{}, yrange_{};  // v(k−1), velocity(k−1) over each side's updates
  detail::FitWindow fit_;
  double vel1_ = 0.0, v1_ = 0.0, vraw1_ = 0.0, y1_ = 0.0;
  int dir1_ = 0, dir2_ = 0;
  std::uint32_t warmup_ = 0, warm_ = 0;
  Side sim_last_ = Side::right;
  double x_ = 0.0, wdot_ = 0.0, w_ = 0.0, ydb_ = 0.0;
  std::uint64_t k_ = 0, stage2_k_ = 0;
  double yhat_ = 0.0, ysim_ = 0.0;
  std::uint64_t skipped_ = 0;
};

}  // namespace lash
