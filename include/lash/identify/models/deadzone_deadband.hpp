#pragma once
/// @file deadzone_deadband.hpp
/// Policy of the input deadzone + output deadband model (§1.4.3, eq. 23–32, docs/method.md §A4.3)
/// for SwitchingEstimator.
#include "lash/identify/estimator_skeleton.hpp"

namespace lash {

/// Four RLS keyed l+, l−, r+, r−. Side from v(k−1) against the guesses; direction + when
/// y(k) > y(k−1) > y(k−2) (with the ẏ dead band: ẏ(k), ẏ(k−1) > threshold), − likewise;
/// otherwise no update. e+ = −d(1 + a1+) − b1+·c, e− = d(1 + a1−) − b1−·c; (d, c) from the 2×2
/// system of eq. 31/32. A side's a1 and b1 are the update-count-weighted means of its + and −
/// estimators. Pooled (lash's default): one 4-parameter regression per side,
/// η = [a1, b1, −b1·c, d(1+a1)].
class DeadzoneDeadbandModel {
 public:
  static constexpr ModelTraits traits{.kind = ModelKind::deadzone_deadband,
                                      .name = "deadzone-deadband",
                                      .has_c = true,
                                      .has_side_d = true,
                                      .keys_by_direction = true,
                                      .uses_guesses = true};
  static void defaults(EstimatorConfig& c);
  static void tune(EstimatorConfig& c, const DataTraits& d);

  enum Key : int { right_plus = 0, right_minus = 1, left_plus = 2, left_minus = 3 };
  static constexpr Key key(Side s, bool plus) noexcept {
    return static_cast<Key>((s == Side::right ? 0 : 2) + (plus ? 0 : 1));
  }
  /// Raw [a1, b1, e] of one key (separate-RLS mode).
  const Rls<3>& rls(Key k) const noexcept { return rls_[k]; }
  /// The 4-parameter regression of one side (pooled mode).
  const Rls<4>& pooled_rls(Side s) const noexcept { return pooled_[s]; }
  /// Pooled mode: side s's raw estimate, η = [a1, b1, −b1·c, d(1 + a1)] solved for (a1, b1, c, d)
  /// without checks (c or d is ±inf or NaN when b1 or 1 + a1 is 0). The verdict's checks are in
  /// derive().
  EstimatorConfig::SwitchSide pooled_params(Side s) const noexcept {
    const auto& e = pooled_[s].eta();
    return {e[0], e[1], -e[2] / e[1], e[3] / (1.0 + e[0])};
  }
  /// Pooled mode: c = −e0/b1 of side s's raw estimate; NaN when b1 ≈ 0 and in separate-RLS mode
  /// (there c needs both keys: params()).
  double edge(Side s) const noexcept {
    if (!pooled_mode_) return detail::kNaN;
    const auto& e = pooled_[s].eta();
    return std::fabs(e[1]) > 1e-12 ? -e[2] / e[1] : detail::kNaN;
  }

 protected:
  explicit DeadzoneDeadbandModel(const EstimatorConfig& cfg);

 private:
  template <class>
  friend class SwitchingEstimator;
  /// A side's raw parameters, whether the 2×2 solve was possible, and whether they may drive the
  /// free run (the method's own premise; see derive()).
  struct Derived {
    double a1, b1, c, d;
    bool updated, solvable, guess_ok, usable;
  };
  Derived derive(const EstimatorCore& core, Side s) const noexcept;
  double update(EstimatorCore& c, const Conditioned& s, bool warming) noexcept;
  /// update() under model switching (EstimatorConfig::model_switching, docs/method.md §A4.4b).
  double update_switched(EstimatorCore& c, const Conditioned& s, bool warming) noexcept;
  void free_run(EstimatorCore& c) noexcept;
  verdict_rules::Evidence evidence(const EstimatorCore& c, Side s) const noexcept;
  /// (c, d) stopped moving (EstimatorConfig::settle_tol): before that a clean verdict is a transient.
  bool settled(const EstimatorCore& c, Side s) const noexcept { return settled_[s] >= c.cfg.settle_updates; }
  bool conditioned(const EstimatorCore& c, Side s) const noexcept {
    return c.cfg.pooled ? c.conditioned(pooled_[s])
                        : c.conditioned(rls_[key(s, true)]) && c.conditioned(rls_[key(s, false)]);
  }
  std::uint64_t side_updates(Side s) const noexcept { return count_[key(s, true)] + count_[key(s, false)]; }
  std::uint64_t key_updates(Side s, bool plus) const noexcept { return count_[key(s, plus)]; }
  std::uint64_t rls_skipped() const noexcept;
  void restart() noexcept {
    regime1_ = 0;
    run_ = 0;
    sw_.started = false;
  }
  void restart_side(EstimatorCore& c, Side s) noexcept;
  void refresh(const EstimatorCore& c, Side s) noexcept;
  double predict_free(const EstimatorCore& c, Side s, double y1, double v1) const noexcept;

  std::array<Rls<3>, 4> rls_;
  PerSide<Rls<4>> pooled_;
  bool pooled_mode_;
  std::array<std::uint64_t, 4> count_{};
  PerSide<bool> usable_{};
  PerSide<detail::DzDbSide> sim_{};  // the free-run model of each side, read together on every sample
  PerSide<double> sc_{};
  PerSide<double> prev_c_{}, prev_d_{};
  PerSide<std::uint32_t> settled_{};
  PerSide<std::uint32_t> since_{};
  double w_ = 0.0;  // free run: the linear part's output before the deadband
  Side last_ = Side::right, sim_last_ = Side::right;
  int regime1_ = 0;  // the last sample's regime: direction of motion × guess side, 0 = not moving
  std::uint32_t run_ = 0;
  /// Model switching: the switching model's state (w before and y after its deadband), its last
  /// engagement (+1 pushed up, −1 down, 0 not), the sign of the v it last read, and how many
  /// samples in a row it has been engaged one way with v on one side of zero.
  struct SwitchState {
    double w = 0.0, y = 0.0;
    int engaged = 0;
    bool positive = true, started = false;
    Side last = Side::right;
    std::uint32_t run = 0;
  };
  SwitchState sw_;
  PerSide<std::uint64_t> beyond_{};  // model switching: updates with v(k−1) beyond the side's edge
};

extern template class SwitchingEstimator<DeadzoneDeadbandModel>;
using DeadzoneDeadbandEstimator = SwitchingEstimator<DeadzoneDeadbandModel>;

}  // namespace lash
