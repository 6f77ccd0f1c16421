#pragma once
/// @file input_deadzone.hpp
/// Policy of the input-deadzone model (§1.4.2, eq. 17–22, docs/method.md §A4.2) for SwitchingEstimator.
#include "lash/identify/estimator_skeleton.hpp"

namespace lash {

/// Side r when v(k−1) > c_r*, l when v(k−1) < c_l*; e = −b1·c so c = −e/b1. Inside the guesses
/// nothing is updated.
class InputDeadzoneModel : public detail::SideRegressions {
 public:
  static constexpr ModelTraits traits{
      .kind = ModelKind::input_deadzone, .name = "input-deadzone", .has_c = true, .uses_guesses = true};
  static void defaults(EstimatorConfig& c);
  static void tune(EstimatorConfig& c, const DataTraits& d);
  /// c = −e/b1 of side s's raw estimate (eq. 21–22); NaN when b1 ≈ 0.
  double edge(Side s) const noexcept {
    const auto& e = rls_[s].eta();
    return std::fabs(e[1]) > 1e-12 ? -e[2] / e[1] : detail::kNaN;
  }

 protected:
  explicit InputDeadzoneModel(const EstimatorConfig& cfg) : SideRegressions(cfg, {cfg.guess_right, cfg.guess_left}) {}

 private:
  template <class>
  friend class SwitchingEstimator;
  double update(EstimatorCore& c, const Conditioned& s, bool warming) noexcept;
  void free_run(EstimatorCore& c) noexcept;
  verdict_rules::Evidence evidence(const EstimatorCore& c, Side s) const noexcept {
    const double e = edge(s);
    // the method's premise (eq. 18): the guesses lie outside the deadzone, c_l* < c < c_r*
    return side_evidence(c, s, e, e > c.cfg.guess_left && e < c.cfg.guess_right);
  }
  void restart() noexcept {}
  void restart_side(EstimatorCore& c, Side s) noexcept;

  double w_ = 0.0;  // free-run output
  Side last_ = Side::right;
};

extern template class SwitchingEstimator<InputDeadzoneModel>;
using InputDeadzoneEstimator = SwitchingEstimator<InputDeadzoneModel>;

}  // namespace lash
