#pragma once
/// @file linear.hpp
/// Policy of the linear first-order model (eq. 9–12, docs/method.md §A4.1) for SwitchingEstimator.
#include "lash/identify/estimator_skeleton.hpp"

namespace lash {

/// φ = [−y(k−1), v(k−1)], η = [a1, b1]; every sample updates. The verdict is that of the whole
/// model (reported on Side::right and Side::left alike).
class LinearModel {
 public:
  static constexpr ModelTraits traits{.kind = ModelKind::linear, .name = "linear", .two_sided = false};
  /// lash's settings before the record is seen (EstimatorConfig(model)).
  static void defaults(EstimatorConfig& c);
  /// Settings chosen from the record (tune_to_data, auto.hpp).
  static void tune(EstimatorConfig& c, const DataTraits& d);

  const Rls<2>& rls() const noexcept { return rls_; }

 protected:
  explicit LinearModel(const EstimatorConfig& cfg) : rls_(cfg.rls2()) {}

 private:
  template <class>
  friend class SwitchingEstimator;
  double update(EstimatorCore& c, const Conditioned& s, bool warming) noexcept;
  void free_run(EstimatorCore& c) noexcept;
  verdict_rules::Evidence evidence(const EstimatorCore& c, Side) const noexcept;
  bool conditioned(const EstimatorCore& c, Side) const noexcept { return c.conditioned(rls_); }
  std::uint64_t side_updates(Side) const noexcept { return rls_.updates(); }
  std::uint64_t rls_skipped() const noexcept { return rls_.skipped(); }
  void restart() noexcept {}
  void restart_side(EstimatorCore&, Side) noexcept {}

  Rls<2> rls_;
  double x_ = 0.0;  // free-run output
};

extern template class SwitchingEstimator<LinearModel>;
using LinearEstimator = SwitchingEstimator<LinearModel>;

}  // namespace lash
