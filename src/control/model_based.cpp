#include "lash/control/model_based.hpp"

#include <cmath>
#include <stdexcept>

#include "lash/identify/estimators.hpp"
#include "lash/io/error.hpp"
#include "lash/metrics/first_order.hpp"
#include "lash/signals/rng.hpp"
#include "lash/io/numeric.hpp"

namespace lash {

ControllerConfig design_from_model(const FirstOrderDeadzoneModel& m, double rise_target_s, double dt_s,
                                   double dz_fraction) {
  if (!(m.gain_kPa_per_mA > 0) || !(m.tau_s > 0) || !(m.deadzone_mA >= 0) || !std::isfinite(m.deadzone_mA))
    throw std::invalid_argument("design_from_model: needs K > 0, tau > 0, deadzone >= 0");
  if (!(rise_target_s > 0) || !(dt_s > 0)) throw std::invalid_argument("design_from_model: rise and dt must be > 0");
  const double lambda = rise_target_s / std::log(10.0);
  ControllerConfig c;
  c.pid.dt_s = dt_s;
  c.pid.gains.kp = m.tau_s / (m.gain_kPa_per_mA * lambda);
  c.pid.gains.ki_per_s = 1.0 / (m.gain_kPa_per_mA * lambda);
  c.pid.gains.kd_s = 0.0;
  c.pid.integrator = IntegratorMethod::forward_euler;
  c.pid.anti_windup = AntiWindup::clamp;
  const double off = dz_fraction * m.deadzone_mA;
  c.dz_inverse = {off, off};
  // PID output range that keeps the command inside 0–2000 mA after the offset.
  c.pid.output_min = -off;
  c.pid.output_max = c.current_max_mA - off;
  return c;
}

ControllerConfig design_for_rise(const FirstOrderDeadzoneModel& m, double bias_kPa, double rise_target_s,
                                 double dt_s, const StepTest& test, double dz_fraction) {
  PilotValveParams p;
  p.deadzone_mA = m.deadzone_mA;
  p.gain_kPa_per_mA = m.gain_kPa_per_mA;
  p.tau_s = m.tau_s;
  p.bias_kPa = bias_kPa;
  p.noise_sigma_kPa = 0.0;
  p.quantize = false;
  p.dt_s = dt_s;
  auto rise_of = [&](double design) {
    const double r = run_step_test(Solver::discrete, p, design_from_model(m, design, dt_s, dz_fraction), test).metrics.rise_s;
    return std::isfinite(r) ? r : 1e9;
  };
  double lo = 2.0 * dt_s, hi = 10.0 * rise_target_s;  // rise grows with the design rise
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (rise_of(mid) > rise_target_s ? hi : lo) = mid;
  }
  return design_from_model(m, 0.5 * (lo + hi), dt_s, dz_fraction);
}

FirstOrderDeadzoneModel identify_online_on_rig(const rigs::PilotValveRigParams& rp, double dt_s, std::uint64_t seed,
                                               double duration_s, double deadzone_guess_mA) {
  rigs::PilotValveRig rig(rp, dt_s, seed);
  EstimatorConfig ec = EstimatorConfig::thesis(ModelKind::input_deadzone, dt_s);
  ec.guess_right = deadzone_guess_mA;
  ec.guess_left = -deadzone_guess_mA;
  ec.rls.lambda = 0.995;
  InputDeadzoneEstimator est(ec);
  Rng rng(seed ^ 0x5eedULL);
  const std::size_t n = steps_or_throw(duration_s, dt_s, "duration_s");
  const std::size_t hold = std::max<std::size_t>(1, steps_or_throw(0.4, dt_s, "dt_s"));
  double y = rig.initial_output();
  double i = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (k % hold == 0) i = 2000.0 * rng.uniform() * (rng.uniform() < 0.2 ? 0.2 : 1.0);  // 0–2000 mA, some low
    est.step(i, y);
    y = rig.step(i);
  }
  const SideParams p = est.params(Side::right);
  if (!p.identified || !(p.a1 < 0 && p.a1 > -1) || !(p.b1 > 0))
    throw RunError("online estimator did not identify the right side");
  FirstOrderDeadzoneModel m;
  m.gain_kPa_per_mA = static_gain(p.a1, p.b1);
  m.tau_s = time_constant_s(p.a1, dt_s);
  m.deadzone_mA = p.c;
  return m;
}

StepResult run_step_on_rig(const rigs::PilotValveRigParams& rp, const ControllerConfig& cc, const StepTest& test,
                           std::uint64_t seed) {
  const double dt = cc.pid.dt_s;
  rigs::PilotValveRig rig(rp, dt, seed);
  ClosedLoopDiscrete ctl(cc);
  const auto ref = test.reference(dt);
  const double bias = rig.bias_estimate_kPa();
  StepResult res;
  auto& tr = res.trace;
  double y = rig.initial_output() + bias;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const double p_true = rig.true_pressure_kPa() + rp.bias_kPa;
    const double i = ctl.step(ref[k], y);
    tr.t_s.push_back(static_cast<double>(k) * dt);
    tr.reference_kPa.push_back(ref[k]);
    tr.measured_kPa.push_back(y);
    tr.pressure_kPa.push_back(p_true);
    tr.command_mA.push_back(i);
    tr.pid_mA.push_back(ctl.pid_output());
    y = rig.step(i) + bias;
  }
  const double ts = test.t_step_s(dt);
  res.metrics = step_metrics(tr.t_s, tr.pressure_kPa, ts, test.r0_kPa, test.r1_kPa);
  res.measured_metrics = step_metrics(tr.t_s, tr.measured_kPa, ts, test.r0_kPa, test.r1_kPa);
  return res;
}

}  // namespace lash
