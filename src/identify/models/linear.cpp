#include "lash/identify/models/linear.hpp"

#include <algorithm>

#include "lash/identify/auto.hpp"

namespace lash {

void LinearModel::defaults(EstimatorConfig& c) { c.rls.lambda = 0.9995; }

void LinearModel::tune(EstimatorConfig& c, const DataTraits&) {
  // a memory of 2 s: several time constants of a mechanical axis and a few reversals (E3 and
  // EMPS at 1 kHz: λ = 0.9995; 10 s followed closed-loop noise less well on EMPS)
  c.rls.lambda = std::clamp(1.0 - c.dt_s / 2.0, 0.99, 0.99995);
}

double LinearModel::update(EstimatorCore& c, const Conditioned& s, bool warming) noexcept {
  const std::array<double, 2> phi{-c.y1, c.v1};
  double yhat;
  if (warming) yhat = rls_.predict(phi);  // after a gap: the regressors are not all from this side of it yet
  else yhat = c.regress(rls_, phi, s.y);
  // the first update's regressors are the zero initial state, not data
  if (!warming && rls_.updates() > 1) c.seen(Side::right, c.v1, c.y1);
  return yhat;
}

void LinearModel::free_run(EstimatorCore& c) noexcept {
  x_ = -rls_.eta(0) * x_ + rls_.eta(1) * c.vraw1;
  c.ysim = x_;
}

verdict_rules::Evidence LinearModel::evidence(const EstimatorCore& c, Side) const noexcept {
  verdict_rules::Evidence ev;
  ev.updated = rls_.updates() >= c.cfg.min_updates;
  ev.excited = c.varies(Side::right);
  ev.a1 = rls_.eta(0);
  ev.b1 = rls_.eta(1);
  return ev;
}

template class SwitchingEstimator<LinearModel>;

}  // namespace lash
