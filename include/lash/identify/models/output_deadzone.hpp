#pragma once
/// @file output_deadzone.hpp
/// Policy of the output-deadzone model (§1.6.1, eq. 36, motor cart; docs/method.md §A4.4) for
/// SwitchingEstimator.
#include "lash/identify/estimator_skeleton.hpp"

namespace lash {

/// Side r when y(k) > 0 and y(k−1) > 0, side l when both < 0 (|y| ≤ zero_threshold counts as 0);
/// e = −c(1 + a1).
class OutputDeadzoneModel : public detail::SideRegressions {
 public:
  static constexpr ModelTraits traits{
      .kind = ModelKind::output_deadzone, .name = "output-deadzone", .has_c = true, .free_run_first = true};
  static void defaults(EstimatorConfig& c);
  /// λ from the sample time; a quantised output (DataTraits::quantum > 0) also gets a moving
  /// average of kQuantisedOutputFilter samples on y and v.
  static void tune(EstimatorConfig& c, const DataTraits& d);
  static constexpr std::size_t kQuantisedOutputFilter = 4;
  /// c = −e/(1 + a1) of side s's raw estimate (eq. 36); NaN when a1 ≈ −1.
  double edge(Side s) const noexcept {
    const auto& e = rls_[s].eta();
    const double den = 1.0 + e[0];
    return std::fabs(den) > 1e-9 ? -e[2] / den : detail::kNaN;
  }

 protected:
  explicit OutputDeadzoneModel(const EstimatorConfig& cfg) : SideRegressions(cfg, {}) {}

 private:
  template <class>
  friend class SwitchingEstimator;
  double update(EstimatorCore& c, const Conditioned& s, bool warming) noexcept;
  void free_run(EstimatorCore& c) noexcept;
  verdict_rules::Evidence evidence(const EstimatorCore& c, Side s) const noexcept {
    return side_evidence(c, s, edge(s), true);
  }
  void restart() noexcept {}

  double x_ = 0.0;  // free run: the linear part's output before the deadzone
};

extern template class SwitchingEstimator<OutputDeadzoneModel>;
using OutputDeadzoneEstimator = SwitchingEstimator<OutputDeadzoneModel>;

}  // namespace lash
