#include "lash/control/closed_loop.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "lash/control/ode3.hpp"
#include "lash/signals/rng.hpp"
#include "lash/io/numeric.hpp"

namespace lash {

const char* to_string(Solver s) noexcept { return s == Solver::discrete ? "discrete" : "ode3"; }

namespace {

void reserve(ClosedLoopTrace& tr, std::size_t n) {
  for (auto* v : {&tr.t_s, &tr.reference_kPa, &tr.measured_kPa, &tr.pressure_kPa, &tr.command_mA, &tr.pid_mA})
    v->reserve(n);
}

ClosedLoopTrace run_discrete(const PilotValveParams& pp, const ControllerConfig& cc, const std::vector<double>& ref,
                             std::size_t delay) {
  PilotValvePlant plant(pp);
  ClosedLoopDiscrete ctl(cc);
  std::vector<double> pipe(delay + 1, 0.0);  // bus delay line: pipe[(k) % (d+1)]
  ClosedLoopTrace tr;
  reserve(tr, ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const double p_true = plant.true_pressure_kPa();
    const double y = plant.measure();
    const double i = ctl.step(ref[k], y);
    pipe[k % (delay + 1)] = i;
    const double applied = pipe[(k + 1) % (delay + 1)];  // i(k − d) (0 before the first command)
    plant.apply(delay == 0 ? i : applied);
    tr.t_s.push_back(static_cast<double>(k) * pp.dt_s);
    tr.reference_kPa.push_back(ref[k]);
    tr.measured_kPa.push_back(y);
    tr.pressure_kPa.push_back(p_true);
    tr.command_mA.push_back(i);
    tr.pid_mA.push_back(ctl.pid_output());
  }
  return tr;
}

// Continuous PID + continuous plant, integrated with ode3 at the sample period.
// State: x = [w1, w2, I, z]: w1 first lag, w2 second lag (unused without τ₂),
// I = ∫e dt, z = derivative filter state (D = Kd·N·(e − z), ż = N·(e − z)).
ClosedLoopTrace run_ode3(const PilotValveParams& pp, const ControllerConfig& cc, const std::vector<double>& ref,
                         std::size_t delay) {
  if (delay != 0) throw std::invalid_argument("the ode3 simulation has no bus delay (bus_delay_steps must be 0)");
  const auto& g = cc.pid.gains;
  validate(g);
  PilotValvePlant shape(pp);  // validates and provides the deadzone
  const DeadzoneInverse dzi(cc.dz_inverse);
  const Saturation sat(cc.current_min_mA, cc.current_max_mA);
  const bool two = pp.tau2_s > 0.0;
  Rng rng(pp.seed);
  const double T = pp.dt_s;
  std::array<double, 4> x{0.0, 0.0, 0.0, 0.0};
  double r = 0.0, noise = 0.0;
  auto sensor = [&](const std::array<double, 4>& s) {
    const double p = pp.bias_kPa + (two ? s[1] : s[0]) + noise;
    return pp.quantize ? quantize_pressure(p) : p;
  };
  // Unfiltered derivative (N = 0): Simulink's du/dt block under a fixed-step solver,
  // Δe/Δt since the last major step: the backward difference at the major step,
  // (e(t) − e(t_n))/(t − t_n) at the solver's intermediate stages.
  const bool pure_d = !(g.n_per_s > 0.0);
  double t_major = 0.0, e_major = 0.0, d_major = 0.0;
  double t_eval = 0.0;
  auto controller = [&](const std::array<double, 4>& s, double& e, double& u) {
    e = r - sensor(s);
    double d = 0.0;
    if (!pure_d)
      d = g.kd_s * g.n_per_s * (e - s[3]);
    else if (t_eval > t_major)
      d = g.kd_s * (e - e_major) / (t_eval - t_major);
    else
      d = d_major;
    u = g.kp * e + g.ki_per_s * s[2] + d;
    return sat.step(dzi.step(u));
  };
  auto f = [&](double t, const std::array<double, 4>& s, std::array<double, 4>& dx) {
    t_eval = t;
    double e = 0.0, u = 0.0;
    const double i = controller(s, e, u);
    dx[0] = (pp.gain_kPa_per_mA * shape.deadzone(i) - s[0]) / pp.tau_s;
    dx[1] = two ? (s[0] - s[1]) / pp.tau2_s : 0.0;
    dx[2] = e;
    dx[3] = g.n_per_s > 0.0 ? g.n_per_s * (e - s[3]) : 0.0;
  };
  ClosedLoopTrace tr;
  reserve(tr, ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    r = ref[k];
    noise = pp.noise_sigma_kPa > 0.0 ? pp.noise_sigma_kPa * rng.gaussian() : 0.0;
    const double t = static_cast<double>(k) * T;
    double e = 0.0, u = 0.0;
    if (pure_d) {  // major step: output the backward difference, then store (t_n, e_n)
      const double e_now = r - sensor(x);
      d_major = k == 0 ? 0.0 : g.kd_s * (e_now - e_major) / T;
      e_major = e_now;
      t_major = t;
    }
    t_eval = t;
    const double i = controller(x, e, u);
    tr.t_s.push_back(t);
    tr.reference_kPa.push_back(r);
    tr.measured_kPa.push_back(sensor(x));
    tr.pressure_kPa.push_back(pp.bias_kPa + (two ? x[1] : x[0]));
    tr.command_mA.push_back(i);
    tr.pid_mA.push_back(u);
    ode3_step(f, t, x, T);
  }
  return tr;
}

}  // namespace

ClosedLoopTrace simulate_closed_loop(Solver solver, const PilotValveParams& plant, const ControllerConfig& controller,
                                     const std::vector<double>& reference_kPa, std::size_t bus_delay_steps) {
  plant.validate();
  if (std::fabs(controller.pid.dt_s - plant.dt_s) > 1e-12 * plant.dt_s)
    throw std::invalid_argument("controller dt (" + std::to_string(controller.pid.dt_s) + " s) differs from plant dt (" +
                                std::to_string(plant.dt_s) + " s)");
  return solver == Solver::discrete ? run_discrete(plant, controller, reference_kPa, bus_delay_steps)
                                    : run_ode3(plant, controller, reference_kPa, bus_delay_steps);
}

std::vector<double> StepTest::reference(double dt_s) const {
  const std::size_t n0 = steps_or_throw(settle_s, dt_s, "settle_s");
  const std::size_t n1 = steps_or_throw(after_s, dt_s, "after_s");
  std::vector<double> r(n0 + n1, r1_kPa);
  for (std::size_t k = 0; k < n0; ++k) r[k] = r0_kPa;
  return r;
}

double StepTest::t_step_s(double dt_s) const { return static_cast<double>(steps_or_throw(settle_s, dt_s, "settle_s")) * dt_s; }

namespace {
constexpr double kMaxLevel_kPa = 1e5;
}  // namespace

StepResult run_step_test(Solver solver, const PilotValveParams& plant, const ControllerConfig& controller,
                         const StepTest& test, std::size_t bus_delay_steps) {
  if (!(test.settle_s > 0) || !(test.after_s > 0) || !(test.r0_kPa != test.r1_kPa))
    throw std::invalid_argument("step test needs settle_s > 0, after_s > 0 and r0 != r1");
  // A level beyond ±1e5 kPa (100 MPa, above any hydraulic system) is a typo, and its square in
  // the metrics overflows long before 1e300: refused, never a NaN result.
  for (const auto& [name, r] : {std::pair{"r0_kPa (--r0)", test.r0_kPa}, std::pair{"r1_kPa (--r1)", test.r1_kPa}})
    if (!(std::fabs(r) <= kMaxLevel_kPa))
      throw std::invalid_argument(std::string(name) + " must be a finite level in [-1e5, 1e5] kPa");
  const std::size_t n = steps_or_throw(test.settle_s, plant.dt_s, "settle_s") + steps_or_throw(test.after_s, plant.dt_s, "after_s");
  if (bus_delay_steps > n)
    throw std::invalid_argument("bus delay (--bus-delay) must be at most the test's " + std::to_string(n) +
                                " samples, got " + std::to_string(bus_delay_steps));
  StepResult res;
  res.trace = simulate_closed_loop(solver, plant, controller, test.reference(plant.dt_s), bus_delay_steps);
  const double ts = test.t_step_s(plant.dt_s);
  res.metrics = step_metrics(res.trace.t_s, res.trace.pressure_kPa, ts, test.r0_kPa, test.r1_kPa);
  res.measured_metrics = step_metrics(res.trace.t_s, res.trace.measured_kPa, ts, test.r0_kPa, test.r1_kPa);
  return res;
}

}  // namespace lash
