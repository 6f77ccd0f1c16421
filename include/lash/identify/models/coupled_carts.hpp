#pragma once
/// @file coupled_carts.hpp
/// Policy of the coupled-carts model (§1.6.3, eq. 38–41, docs/method.md §A4.5) for SwitchingEstimator.
#include "lash/identify/estimator_skeleton.hpp"

namespace lash {

/// Free cart loosely coupled to a motor cart. y is the free cart's position; its velocity ẏ
/// (backward difference, eq. 26) equals the motor cart's velocity ẇ while the pin is engaged and
/// 0 inside the position deadband.
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
class CoupledCartsModel : public detail::SideRegressions {
 public:
  static constexpr ModelTraits traits{
      .kind = ModelKind::coupled_carts, .name = "coupled-carts", .has_c = true, .has_shared_d = true};
  static void defaults(EstimatorConfig& c);
  static void tune(EstimatorConfig& c, const DataTraits& d);
  /// c = −e/(1 + a1) of side s's raw velocity model (eq. 38); NaN when a1 = −1.
  double edge(Side s) const noexcept {
    const auto& e = rls_[s].eta();
    return std::fabs(1.0 + e[0]) > 0.0 ? -e[2] / (1.0 + e[0]) : detail::kNaN;
  }
  /// The shared deadband half-width d: mean over the stage-2 slot crossings; NaN before the first.
  double deadband() const noexcept {
    return dcount_[0] + dcount_[1] > 0 ? dsum_ / static_cast<double>(dcount_[0] + dcount_[1]) : detail::kNaN;
  }
  /// Verdict of the shared deadband: not_updated before the first slot crossing, unphysical if d < 0.
  Reason deadband_reason() const noexcept;
  /// Stage-2 slot crossings that ended moving + (plus = true) or −.
  std::uint64_t deadband_updates(bool plus) const noexcept { return dcount_[plus ? 0 : 1]; }
  /// Simulated motor-cart velocity ŵ̇.
  double simulated_velocity() const noexcept { return wdot_; }

 protected:
  explicit CoupledCartsModel(const EstimatorConfig& cfg)
      : SideRegressions(cfg, {}), stage2_k_(detail::start_index(cfg.stage2_start_s, cfg.dt_s)) {}

 private:
  template <class>
  friend class SwitchingEstimator;
  double update(EstimatorCore& c, const Conditioned& s, bool warming) noexcept;
  void free_run(EstimatorCore& c) noexcept;
  verdict_rules::Evidence evidence(const EstimatorCore& c, Side s) const noexcept {
    verdict_rules::Evidence ev = side_evidence(c, s, edge(s), true);
    ev.negative_a1 = true;
    return ev;
  }
  /// The signal history of stage 1 and the open slot crossing (never measured across a gap).
  void restart() noexcept {
    vel1_ = 0.0;
    dir1_ = dir2_ = 0;
    r_ok_ = false;
  }
  void refresh(const EstimatorCore& c, Side s) noexcept;

  std::array<std::uint64_t, 2> dcount_{};  // stage-2 crossings ending in motion + / −
  double dsum_ = 0.0, r_last_ = 0.0, osum_ = 0.0, odir_ = 0.0;
  std::uint64_t on_ = 0;
  int dir_last_ = 0;
  bool r_ok_ = false;
  PerSide<bool> valid_{};  // side usable at least once
  double vel1_ = 0.0;
  int dir1_ = 0, dir2_ = 0;
  double x_ = 0.0, wdot_ = 0.0, w_ = 0.0, ydb_ = 0.0;
  std::uint64_t k_ = 0, stage2_k_ = 0;
  // this sample, from update() to free_run(): direction, output, warm-up
  int dir_ = 0;
  double y_ = 0.0;
  bool warming_ = false;
};

extern template class SwitchingEstimator<CoupledCartsModel>;
using CoupledCartsEstimator = SwitchingEstimator<CoupledCartsModel>;

}  // namespace lash
