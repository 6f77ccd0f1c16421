#include "lash/identify/models/input_deadzone.hpp"

#include <algorithm>

#include "lash/identify/auto.hpp"

namespace lash {

void InputDeadzoneModel::defaults(EstimatorConfig& c) {
  // E4 (lash settings): λ 0.995, a1 ∈ [−1, 0] (stable, non-oscillating first order), b1 ≥ 0.
  c.rls.lambda = 0.995;
  c.rls.lower = {-1.0, 0.0, -std::numeric_limits<double>::infinity()};
  c.rls.upper = {0.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
}

void InputDeadzoneModel::tune(EstimatorConfig& c, const DataTraits& d) {
  // Projection box from the record's scales (Goodwin & Sin §3.7): a1 ∈ [−1, 0], 0 < b1 ≤ B and
  // |e| = |b1·c| ≤ B·max|v|, B = 2·span(y)/span(v) (at least twice the largest static gain the
  // record can show). Without it a side with few samples (amplitude just above the deadzone)
  // can run away under forgetting (E4: b1 ~ 1e74).
  const double vspan = d.v_hi - d.v_lo;
  if (vspan > 0.0 && d.y_span > 0.0) {
    const double B = 2.0 * d.y_span / vspan;
    const double E = B * std::max(std::fabs(d.v_lo), std::fabs(d.v_hi));
    c.rls.lower = {-1.0, 1e-4 * B, -E};
    c.rls.upper = {0.0, B, E};
  }
  // a whole record: the switching estimate is refined by output error (docs/method.md §A4.4c)
  c.output_error = true;
}

double InputDeadzoneModel::update(EstimatorCore& c, const Conditioned& s, bool) noexcept {
  const auto side = detail::guess_side(c.v1, c.cfg);
  // after a gap no update (restart()); this model resumes on the warm-up's last sample
  if (side && c.warm == 0) {
    const double yhat = regress_side(c, *side, s.y);
    const double e = edge(*side);
    if (rls_[*side].updates() >= c.cfg.min_updates && detail::simulable(rls_[*side].eta(), e)) hold(*side, e);
    last_ = *side;
    return yhat;
  }
  return -rls_[last_].eta(0) * c.y1;  // inside the deadzone u = 0 (eq. 17), a1 of the side last used
}

void InputDeadzoneModel::free_run(EstimatorCore& c) noexcept {
  // eq. 17 driven by the raw v
  const Side ss = detail::free_run_side(c.vraw1, sc_, sim_last_, c.cfg.sim_side_by_sign);
  sim_last_ = ss;
  w_ = -sa1_[ss] * w_ + sb1_[ss] * detail::deadzone(c.vraw1, sc_.left, sc_.right);
  c.ysim = w_;
}

void InputDeadzoneModel::restart_side(EstimatorCore& c, Side s) noexcept {
  rls_[s].reset();
  sa1_[s] = sb1_[s] = 0.0;  // no output from that side until its new estimate is simulable
  sc_[s] = c.cfg.guess(s);
}

template class SwitchingEstimator<InputDeadzoneModel>;

}  // namespace lash
