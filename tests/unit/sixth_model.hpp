#pragma once
// A sixth model written against the estimator skeleton only (issue 28: adding a model touches its
// policy, its traits and its registration): a linear first-order model behind a symmetric input
// deadzone [−c, c],
//   y(k) = −a1·y(k−1) + b1·DZ(v(k−1); −c, c),
// identified outside the guesses by ONE regression shared by both sides:
//   v(k−1) > c_r*: y(k) = −a1·y(k−1) + b1·v(k−1) − b1·c,  v(k−1) < c_l*: … + b1·c,
// so φ = [−y(k−1), v(k−1), −sgn v(k−1)], η = [a1, b1, b1·c], c = η3/η2. Right reports c, left −c.
// Its whole policy and traits are below; the test's registration is a ModelKind value past the
// library's and, for dispatch, a ModelList with it appended.
#include <cmath>

#include "lash/identify/estimators.hpp"

namespace lash::test {

inline constexpr auto kSymmetricDeadzone = static_cast<ModelKind>(kModelCount);  // the registration's kind

class SymmetricDeadzoneModel {
 public:
  static constexpr ModelTraits traits{
      .kind = kSymmetricDeadzone, .name = "symmetric-deadzone", .has_c = true, .uses_guesses = true};
  static void defaults(EstimatorConfig&) {}
  static void tune(EstimatorConfig&, const DataTraits&) {}
  double edge(Side s) const noexcept {
    const double c = std::fabs(rls_.eta(1)) > 1e-12 ? rls_.eta(2) / rls_.eta(1) : detail::kNaN;
    return s == Side::right ? c : -c;
  }

 protected:
  explicit SymmetricDeadzoneModel(const EstimatorConfig& cfg) : rls_(cfg.rls3()) {}

 private:
  template <class>
  friend class lash::SwitchingEstimator;
  double update(EstimatorCore& c, const Conditioned& s, bool warming) noexcept {
    const auto side = detail::guess_side(c.v1, c.cfg);
    const std::array<double, 3> phi{-c.y1, c.v1, c.v1 > 0.0 ? -1.0 : 1.0};
    if (!side || warming) return rls_.predict({-c.y1, 0.0, 0.0});  // inside the deadzone u = 0
    c.seen(*side, c.v1, c.y1);
    return c.regress(rls_, phi, s.y);
  }
  void free_run(EstimatorCore& c) noexcept {
    const double cc = edge(Side::right);
    const bool ok = rls_.updates() >= c.cfg.min_updates && detail::simulable(rls_.eta(), cc);
    x_ = ok ? -rls_.eta(0) * x_ + rls_.eta(1) * detail::deadzone(c.vraw1, -cc, cc) : 0.0;
    c.ysim = x_;
  }
  verdict_rules::Evidence evidence(const EstimatorCore& c, Side s) const noexcept {
    verdict_rules::Evidence ev;
    ev.side = s;
    ev.updated = rls_.updates() >= c.cfg.min_updates;
    ev.excited = c.excited(s);
    ev.a1 = rls_.eta(0);
    ev.b1 = rls_.eta(1);
    ev.has_c = true;
    ev.c = edge(s);
    ev.guess_ok = edge(Side::right) < c.cfg.guess_right && edge(Side::left) > c.cfg.guess_left;
    return ev;
  }
  bool conditioned(const EstimatorCore& c, Side) const noexcept { return c.conditioned(rls_); }
  std::uint64_t side_updates(Side) const noexcept { return rls_.updates(); }
  std::uint64_t rls_skipped() const noexcept { return rls_.skipped(); }
  void restart() noexcept {}
  void restart_side(EstimatorCore&, Side) noexcept { rls_.reset(); }  // one regression serves both sides

  Rls<3> rls_;
  double x_ = 0.0;
};

using SymmetricDeadzoneEstimator = SwitchingEstimator<SymmetricDeadzoneModel>;
static_assert(Estimator<SymmetricDeadzoneEstimator>);

/// The registration, as the library's (estimators.hpp) with the sixth model appended.
using SixModels = ModelList<LinearModel, InputDeadzoneModel, OutputDeadzoneModel, DeadzoneDeadbandModel,
                            CoupledCartsModel, SymmetricDeadzoneModel>;
static_assert(detail::in_kind_order(SixModels{}));

}  // namespace lash::test
