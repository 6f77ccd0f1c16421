#include "lash/identify/models/output_deadzone.hpp"

#include <algorithm>

#include "lash/identify/auto.hpp"

namespace lash {

void OutputDeadzoneModel::defaults(EstimatorConfig& c) {
  // E3 (lash settings): directional forgetting; λ from the sample time (tune). A moving average
  // only where the output is quantised (tune); its start-up samples are no evidence of excitation
  // (EstimatorCore::start).
  c.rls.lambda = 0.9995;
  c.rls.forgetting = Forgetting::directional;
}

void OutputDeadzoneModel::tune(EstimatorConfig& c, const DataTraits& d) {
  // a memory of 2 s, as the linear model's (models/linear.cpp)
  c.rls.lambda = std::clamp(1.0 - c.dt_s / 2.0, 0.99, 0.99995);
  // A quantised output — a velocity differenced from encoder counts — goes through the same short
  // moving average as v (docs/identification.md "Defaults chosen from the data"). The mean of M
  // such velocities is the M-sample difference quotient, so the quantisation error's σ falls as
  // 1/M; the same filter on v keeps the linear relation within a regime; a longer window mixes
  // regimes at reversals and smears the transients that carry c. E3 with lash's defaults, sides
  // within 5 % of the rig's effective K, τ, c for M = 1, 2, 3, 4, 5, 6, 10: 26, 58, 68, 68, 67,
  // 65, 54 % (docs/sweep.md).
  if (d.quantum > 0.0) {
    c.noise.filter_length = kQuantisedOutputFilter;
    c.noise.filter_input = true;
  }
}

void OutputDeadzoneModel::free_run(EstimatorCore& c) noexcept {
  // x = G(v), y_sim = DZ(x); the side follows x against the deadzone
  const Side ss = detail::free_run_side(x_, sc_, sim_last_);
  sim_last_ = ss;
  x_ = -sa1_[ss] * x_ + sb1_[ss] * c.vraw1;
  c.ysim = detail::deadzone(x_, sc_.left, sc_.right);
}

double OutputDeadzoneModel::update(EstimatorCore& c, const Conditioned& s, bool warming) noexcept {
  const double y1 = c.y1, v1 = c.v1, z = c.cfg.zero_threshold;
  for (Side sd : {Side::right, Side::left}) {
    const double sg = sd == Side::right ? 1.0 : -1.0;  // outward
    if (!warming && sg * s.y > z && sg * y1 > z) {
      const double yhat = regress_side(c, sd, s.y);
      const double e = edge(sd);
      if (rls_[sd].updates() >= c.cfg.min_updates && detail::simulable(rls_[sd].eta(), e)) hold(sd, e);
      return yhat;
    }
  }
  if (y1 > c.cfg.zero_threshold) return std::max(rls_.right.predict({-y1, v1, 1.0}), 0.0);
  if (y1 < -c.cfg.zero_threshold) return std::min(rls_.left.predict({-y1, v1, 1.0}), 0.0);
  return 0.0;
}

template class SwitchingEstimator<OutputDeadzoneModel>;

}  // namespace lash
