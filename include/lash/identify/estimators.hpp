#pragma once
/// @file estimators.hpp
/// The switching RLS estimators of SPEC A4 (thesis §1.4, §1.6). Each takes one sample
/// (v(k), y(k)) per step(), which is noexcept, O(1) and allocation-free; construction
/// validates the EstimatorConfig (std::invalid_argument) and allocates the filters.
///
/// Every estimator exposes per side a1, b1 (and c, d where the model has them), update
/// counts per key, `identified`, the one-step prediction ŷ and a free-run simulated output
/// y_sim of the identified model driven by v alone. A parameter that is not identified yet
/// is NaN — never a huge number.
///
/// Regression (SPEC A4): φ(k) = [−y(k−1), v(k−1), 1], η = [a1, b1, e].
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "lash/blocks/side.hpp"
#include "lash/identify/config.hpp"
#include "lash/identify/preprocess.hpp"
#include "lash/identify/rls.hpp"

namespace lash {

/// Identified parameters of one side; NaN = not identified / not part of the model.
struct SideParams {
  double a1 = std::numeric_limits<double>::quiet_NaN();
  double b1 = std::numeric_limits<double>::quiet_NaN();
  double c = std::numeric_limits<double>::quiet_NaN();
  double d = std::numeric_limits<double>::quiet_NaN();
  bool identified = false;
};

namespace detail {
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double deadzone(double x, double cl, double cr) noexcept {
  return x > cr ? x - cr : (x < cl ? x - cl : 0.0);
}
constexpr int side_index(Side s) noexcept { return s == Side::right ? 0 : 1; }
/// The range of the values one regressor took (excitation check: a constant input makes b1 and
/// the offset e inseparable — only b1·v + e is determined).
struct ValueRange {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double x) noexcept {
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  /// More than one value (beyond rounding) was seen.
  bool several() const noexcept { return hi - lo > 1e-9 * std::max(1.0, std::max(std::fabs(hi), std::fabs(lo))); }
};
/// Fixed ring of the last 64 values (instrument history).
struct History {
  std::array<double, 64> buf{};
  unsigned pos = 0;
  void push(double x) noexcept { buf[pos++ & 63u] = x; }
  /// j = 1 → last pushed value.
  double ago(std::size_t j) const noexcept { return buf[(pos - static_cast<unsigned>(j)) & 63u]; }
};
}  // namespace detail

/// Linear first-order model (eq. 9–12): φ = [−y(k−1), v(k−1)], η = [a1, b1]; every sample updates.
class LinearEstimator {
 public:
  explicit LinearEstimator(const EstimatorConfig& cfg);
  /// Advances one sample; returns ŷ(k) = φᵀη̂(k−1) (eq. 14).
  double step(double v, double y) noexcept;
  double prediction() const noexcept { return yhat_; }
  double simulated() const noexcept { return ysim_; }
  SideParams params() const noexcept;
  std::uint64_t updates() const noexcept { return rls_.updates(); }
  std::uint64_t skipped() const noexcept { return skipped_ + rls_.skipped(); }
  bool identified() const noexcept { return rls_.updates() >= cfg_.min_updates; }
  const Rls<2>& rls() const noexcept { return rls_; }

 private:
  EstimatorConfig cfg_;
  Preprocessor pre_;
  Rls<2> rls_;
  detail::History hist_;
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
  SideParams params(Side s) const noexcept { return p_[side_index(s)]; }
  std::uint64_t updates(Side s) const noexcept { return rls_[side_index(s)].updates(); }
  std::uint64_t skipped() const noexcept { return skipped_ + rls_[0].skipped() + rls_[1].skipped(); }
  bool identified() const noexcept { return p_[0].identified && p_[1].identified; }
  const Rls<3>& rls(Side s) const noexcept { return rls_[side_index(s)]; }

 protected:
  explicit TwoSideEstimator(const EstimatorConfig& cfg);
  /// Side i after an update, with its deadzone edge c (NaN when the model cannot give one) and
  /// the model's own plausibility test of c. The free run holds the side's last stable set
  /// (finite, |a1| < 1); the side is identified only if also c_r ≥ 0 ≥ c_l and plausible.
  void refresh(int i, double c, bool plausible) noexcept;
  /// Updates side i's RLS with φ = [−y(k−1), v(k−1), 1] (or its instrument); returns ŷ.
  double update(int i, double y) noexcept;

  EstimatorConfig cfg_;
  Preprocessor pre_;
  std::array<Rls<3>, 2> rls_;
  std::array<SideParams, 2> p_{};
  std::array<double, 2> sa1_{}, sb1_{}, sc_{};  // parameters used by the free-run simulation
  History hist_;
  double y1_ = 0.0, v1_ = 0.0, vraw1_ = 0.0;
  int sim_last_ = 0;
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

 private:
  void refresh(int i) noexcept;
  double w_ = 0.0;
  int last_ = 0;
};

/// Output deadzone (§1.6.1, eq. 36, motor cart): side r when y(k) > 0 and y(k−1) > 0,
/// side l when both < 0 (|y| ≤ zero_threshold counts as 0); e = −c(1 + a1).
class OutputDeadzoneEstimator : public detail::TwoSideEstimator {
 public:
  explicit OutputDeadzoneEstimator(const EstimatorConfig& cfg);
  double step(double v, double y) noexcept;

 private:
  void refresh(int i) noexcept;
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

  explicit DeadzoneDeadbandEstimator(const EstimatorConfig& cfg);

  double step(double v, double y) noexcept {
    if (!(std::isfinite(v) && std::isfinite(y))) {
      ++skipped_;
      return yhat_ = detail::kNaN;
    }
    const Conditioned s = pre_.step(v, y);
    const int dir = direction(s.ydot, cfg_.noise.derivative_threshold);
    const double y1 = y1_, v1 = v1_;
    const int side = v1 > cfg_.guess_right ? 0 : (v1 < cfg_.guess_left ? 1 : -1);
    run_ = (dir != 0 && dir == dir1_ && side == side1_) ? run_ + 1 : 1;
    side1_ = side;
    if (side >= 0 && dir != 0 && run_ >= cfg_.direction_run) {
      const int key = side * 2 + (dir > 0 ? 0 : 1);
      if (cfg_.pooled) {
        const double sg = dir > 0 ? -1.0 : 1.0;
        const std::array<double, 4> phi{-y1, v1, 1.0, sg};
        if (cfg_.method == EstimationMethod::iv)
          yhat_ = pooled_[side].update_iv(phi, {-hist_.ago(1 + cfg_.iv_delay), v1, 1.0, sg}, s.y);
        else
          yhat_ = pooled_[side].update(phi, s.y);
        ++count_[key];
      } else {
        const std::array<double, 3> phi{-y1, v1, 1.0};
        if (cfg_.method == EstimationMethod::iv)
          yhat_ = rls_[key].update_iv(phi, {-hist_.ago(1 + cfg_.iv_delay), v1, 1.0}, s.y);
        else
          yhat_ = rls_[key].update(phi, s.y);
        count_[key] = rls_[key].updates();
      }
      // Derived (a1, b1, c, d) are refreshed on every update until the side is identified, then
      // every 4th update (the free run lags at most 3 samples; params() is always current).
      if (!p_[side].identified || (++since_[side] & 3u) == 0) refresh(side);
      last_ = side;
    } else {
      yhat_ = predict_free(side >= 0 ? side : last_, y1, v1);
    }
    hist_.push(s.y);
    y1_ = s.y;
    v1_ = s.v;
    dir1_ = dir;
    simulate(v);
    return yhat_;
  }

  double prediction() const noexcept { return yhat_; }
  double simulated() const noexcept { return ysim_; }
  /// Current parameters (computed from the four/two RLS on each call).
  SideParams params(Side s) const noexcept;
  /// Updates of key (side, +) or (side, −).
  std::uint64_t updates(Side s, bool plus) const noexcept {
    return count_[detail::side_index(s) * 2 + (plus ? 0 : 1)];
  }
  std::uint64_t skipped() const noexcept;
  bool identified() const noexcept { return p_[0].identified && p_[1].identified; }
  /// Raw [a1, b1, e] of one key (separate-RLS mode).
  const Rls<3>& rls(Key k) const noexcept { return rls_[k]; }
  /// The 4-parameter regression of one side (pooled mode).
  const Rls<4>& pooled_rls(Side s) const noexcept { return pooled_[detail::side_index(s)]; }

 private:
  SideParams derive(int side) const noexcept;
  void refresh(int side) noexcept;
  double predict_free(int side, double y1, double v1) const noexcept;
  void simulate(double v) noexcept {
    int s;
    if (cfg_.sim_side_by_sign) s = vraw1_ >= 0.0 ? 0 : 1;
    else s = vraw1_ > sc_[0] ? 0 : (vraw1_ < sc_[1] ? 1 : sim_last_);
    sim_last_ = s;
    const double u = detail::deadzone(vraw1_, sc_[1], sc_[0]);
    w_ = -sa1_[s] * w_ + sb1_[s] * u;
    const double d = sd_[s];
    if (w_ < ysim_ - d) ysim_ = w_ + d;
    else if (w_ > ysim_ + d) ysim_ = w_ - d;
    vraw1_ = v;
  }

  EstimatorConfig cfg_;
  Preprocessor pre_;
  std::array<Rls<3>, 4> rls_;
  std::array<Rls<4>, 2> pooled_;
  std::array<std::uint64_t, 4> count_{};
  std::array<SideParams, 2> p_{};
  std::array<double, 2> sa1_{}, sb1_{}, sc_{}, sd_{};
  std::array<double, 2> prev_c_{}, prev_d_{};
  std::array<std::uint32_t, 2> settled_{};
  std::array<std::uint32_t, 2> since_{};
  detail::History hist_;
  double y1_ = 0.0, v1_ = 0.0, vraw1_ = 0.0, w_ = 0.0;
  int dir1_ = 0, last_ = 0, sim_last_ = 0, side1_ = -1;
  std::uint32_t run_ = 0;
  double yhat_ = 0.0, ysim_ = 0.0;
  std::uint64_t skipped_ = 0;
};

/// Free cart loosely coupled to a motor cart (§1.6.3, eq. 38–41). y is the free cart's
/// position; its velocity ẏ (backward difference, eq. 26) equals the motor cart's velocity ẇ
/// while the pin is engaged and 0 inside the position deadband.
/// Stage 1: output-deadzone velocity model (eq. 38) updated on samples where the free cart
/// has moved in one direction for three samples (so ẏ(k), ẏ(k−1) are both ẇ) and
/// |ÿ| ≤ accel_limit. A side is identified when it has min_updates updates, −1 < a1 < 0, c on
/// its own side of zero (c_r ≥ 0 ≥ c_l) and the input took more than one value on its updates.
/// Stage 2 (t ≥ stage2_start_s, both sides identified): the free-run velocity model is
/// integrated to ŵ; engaged, y − ŵ = o ∓ d (moving ±). o drifts (ŵ is an open-loop integral),
/// so d is taken per slot crossing: when the free cart starts moving the other way, y − ŵ has
/// changed by ±2d since its last moving sample. d = mean over crossings (available after the
/// first); o = least-squares offset given d. The free run uses only identified parameter sets
/// (the last one per side); a side never identified predicts no motion.
class CoupledCartsEstimator {
 public:
  explicit CoupledCartsEstimator(const EstimatorConfig& cfg);
  double step(double v, double y) noexcept;
  double prediction() const noexcept { return yhat_; }
  double simulated() const noexcept { return ysim_; }
  /// Velocity model per side (a1, b1, c) and the shared deadband half-width d.
  SideParams params(Side s) const noexcept;
  double deadband() const noexcept;
  std::uint64_t updates(Side s) const noexcept { return rls_[detail::side_index(s)].updates(); }
  /// Stage-2 slot crossings that ended moving + (plus = true) or −.
  std::uint64_t deadband_updates(bool plus) const noexcept { return dcount_[plus ? 0 : 1]; }
  std::uint64_t skipped() const noexcept;
  bool identified() const noexcept;
  /// Simulated motor-cart velocity ŵ̇ and position ŵ (+ offset).
  double simulated_velocity() const noexcept { return wdot_; }

 private:
  void refresh(int i) noexcept;
  EstimatorConfig cfg_;
  Preprocessor pre_;
  std::array<Rls<3>, 2> rls_;
  std::array<std::uint64_t, 2> dcount_{};  // stage-2 crossings ending in motion + / −
  double dsum_ = 0.0, r_last_ = 0.0, osum_ = 0.0, odir_ = 0.0;
  std::uint64_t on_ = 0;
  int dir_last_ = 0;
  bool r_ok_ = false;
  std::array<SideParams, 2> p_{};
  std::array<double, 2> sa1_{}, sb1_{}, sc_{};  // last identified set per side (free run)
  std::array<bool, 2> valid_{};                   // side identified at least once
  std::array<detail::ValueRange, 2> vrange_{};  // v(k−1) over each side's updates
  double vel1_ = 0.0, v1_ = 0.0, vraw1_ = 0.0, y1_ = 0.0;
  int dir1_ = 0, dir2_ = 0, sim_last_ = 0;
  double x_ = 0.0, wdot_ = 0.0, w_ = 0.0, ydb_ = 0.0;
  std::uint64_t k_ = 0, stage2_k_ = 0;
  double yhat_ = 0.0, ysim_ = 0.0;
  std::uint64_t skipped_ = 0;
};

}  // namespace lash
