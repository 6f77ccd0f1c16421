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
  } else if (d.noise_sigma > 0.0) {
    // White measurement noise: inside the deadzone y is 0 + e, and the regression of §A4.3 holds
    // only outside it, so samples within 3σ of 0 are not taken for either side (z =
    // zero_threshold); with z = 0 every noise sample above 0 was a right-side update.
    c.zero_threshold = 3.0 * d.noise_sigma;
  }
  // A whole record whose output is not quantised: the switching estimate is refined by output
  // error (docs/method.md §A4.4c). Not on a quantised one: that is the motor cart's encoder
  // velocity, whose rig (armature pole, stiction) the first-order model does not hold, and there
  // the free run's best fit lies further from the rig's effective K, τ, c than the switching
  // estimate (E3's traced runs: 35 of 198 sides within 5 %, 96 above 20 %, against 169 and 1;
  // docs/sweep.md).
  if (d.quantum <= 0.0) c.output_error = true;
}

void OutputDeadzoneModel::free_run(EstimatorCore& c) noexcept {
  // x = G(v), y_sim = DZ(x); the side follows x against the deadzone
  c.ysim = detail::output_dz_free_run(c.vraw1, sc_, sa1_, sb1_, sim_last_, x_);
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
