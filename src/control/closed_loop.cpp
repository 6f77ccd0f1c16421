#include "lash/control/closed_loop.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <fmt/core.h>

#include "lash/control/ode3.hpp"
#include "lash/signals/rng.hpp"
#include "lash/io/memory.hpp"
#include "lash/io/numeric.hpp"

namespace lash {

const char* to_string(Solver s) noexcept { return s == Solver::discrete ? "discrete" : "ode3"; }

struct ClosedLoopStepper::Impl {
  virtual ~Impl() = default;
  virtual ClosedLoopSample step(double r) = 0;
};

namespace {

// The discrete loop: y(k) = plant.measure(); i(k) = controller.step(r(k), y(k)); plant.apply(i(k − d)).
class DiscreteLoop final : public ClosedLoopStepper::Impl {
 public:
  DiscreteLoop(const PilotValveParams& pp, const ControllerConfig& cc, std::size_t delay)
      : plant_(pp), ctl_(cc), dt_(pp.dt_s), delay_(delay) {
    // The delay line holds d + 1 commands: refused with the figure if the machine cannot hold it.
    require_memory(8.0 * (static_cast<double>(delay) + 1.0),
                   "a bus delay (--bus-delay) of " + std::to_string(delay) + " samples (its delay line, 8 bytes a sample)");
    pipe_.assign(delay + 1, 0.0);  // bus delay line: pipe[(k) % (d+1)]
  }
  ClosedLoopSample step(double r) override {
    const std::size_t k = k_++;
    const double p_true = plant_.true_pressure_kPa();
    const double y = plant_.measure();
    const double i = ctl_.step(r, y);
    pipe_[k % (delay_ + 1)] = i;
    const double applied = pipe_[(k + 1) % (delay_ + 1)];  // i(k − d) (0 before the first command)
    plant_.apply(delay_ == 0 ? i : applied);
    return {static_cast<double>(k) * dt_, r, y, p_true, i, ctl_.pid_output()};
  }

 private:
  PilotValvePlant plant_;
  ClosedLoopDiscrete ctl_;
  double dt_;
  std::size_t delay_;
  std::vector<double> pipe_;
  std::size_t k_ = 0;
};

// Continuous PID + continuous plant, integrated with ode3 at the sample period.
// State: x = [w1, w2, I, z]: w1 first lag, w2 second lag (unused without τ₂),
// I = ∫e dt, z = derivative filter state (D = Kd·N·(e − z), ż = N·(e − z)).
class Ode3Loop final : public ClosedLoopStepper::Impl {
 public:
  Ode3Loop(const PilotValveParams& pp, const ControllerConfig& cc, std::size_t delay)
      : pp_(pp), g_(cc.pid.gains), shape_(pp), dzi_(cc.dz_inverse), sat_(cc.current_min_mA, cc.current_max_mA),
        two_(pp.tau2_s > 0.0), rng_(pp.seed), T_(pp.dt_s), pure_d_(!(cc.pid.gains.n_per_s > 0.0)) {
    if (delay != 0) throw std::invalid_argument("the ode3 simulation has no bus delay (bus_delay_steps must be 0)");
    validate(g_);
  }
  ClosedLoopSample step(double ref) override {
    const std::size_t k = k_++;
    r_ = ref;
    noise_ = pp_.noise_sigma_kPa > 0.0 ? pp_.noise_sigma_kPa * rng_.gaussian() : 0.0;
    const double t = static_cast<double>(k) * T_;
    double e = 0.0, u = 0.0;
    if (pure_d_) {  // major step: output the backward difference, then store (t_n, e_n)
      const double e_now = r_ - sensor(x_);
      d_major_ = k == 0 ? 0.0 : g_.kd_s * (e_now - e_major_) / T_;
      e_major_ = e_now;
      t_major_ = t;
    }
    t_eval_ = t;
    const double i = controller(x_, e, u);
    const ClosedLoopSample out{t, r_, sensor(x_), pp_.bias_kPa + (two_ ? x_[1] : x_[0]), i, u};
    ode3_step([this](double tt, const std::array<double, 4>& s, std::array<double, 4>& dx) { f(tt, s, dx); }, t, x_,
              T_);
    return out;
  }

 private:
  double sensor(const std::array<double, 4>& s) const {
    const double p = pp_.bias_kPa + (two_ ? s[1] : s[0]) + noise_;
    return pp_.quantize ? quantize_pressure(p) : p;
  }
  // Unfiltered derivative (N = 0): Simulink's du/dt block under a fixed-step solver,
  // Δe/Δt since the last major step: the backward difference at the major step,
  // (e(t) − e(t_n))/(t − t_n) at the solver's intermediate stages.
  double controller(const std::array<double, 4>& s, double& e, double& u) const {
    e = r_ - sensor(s);
    double d = 0.0;
    if (!pure_d_)
      d = g_.kd_s * g_.n_per_s * (e - s[3]);
    else if (t_eval_ > t_major_)
      d = g_.kd_s * (e - e_major_) / (t_eval_ - t_major_);
    else
      d = d_major_;
    u = g_.kp * e + g_.ki_per_s * s[2] + d;
    return sat_.step(dzi_.step(u));
  }
  void f(double t, const std::array<double, 4>& s, std::array<double, 4>& dx) {
    t_eval_ = t;
    double e = 0.0, u = 0.0;
    const double i = controller(s, e, u);
    dx[0] = (pp_.gain_kPa_per_mA * shape_.deadzone(i) - s[0]) / pp_.tau_s;
    dx[1] = two_ ? (s[0] - s[1]) / pp_.tau2_s : 0.0;
    dx[2] = e;
    dx[3] = g_.n_per_s > 0.0 ? g_.n_per_s * (e - s[3]) : 0.0;
  }

  PilotValveParams pp_;
  PidGains g_;
  PilotValvePlant shape_;  // validates and provides the deadzone
  DeadzoneInverse dzi_;
  Saturation sat_;
  bool two_;
  Rng rng_;
  double T_;
  bool pure_d_;
  std::array<double, 4> x_{0.0, 0.0, 0.0, 0.0};
  double r_ = 0.0, noise_ = 0.0;
  double t_major_ = 0.0, e_major_ = 0.0, d_major_ = 0.0, t_eval_ = 0.0;
  std::size_t k_ = 0;
};

void push(ClosedLoopTrace& tr, const ClosedLoopSample& s) {
  tr.t_s.push_back(s.t_s);
  tr.reference_kPa.push_back(s.reference_kPa);
  tr.measured_kPa.push_back(s.measured_kPa);
  tr.pressure_kPa.push_back(s.pressure_kPa);
  tr.command_mA.push_back(s.command_mA);
  tr.pid_mA.push_back(s.pid_mA);
}

}  // namespace

ClosedLoopStepper::ClosedLoopStepper(Solver solver, const PilotValveParams& plant, const ControllerConfig& controller,
                                     std::size_t bus_delay_steps) {
  plant.validate();
  if (std::fabs(controller.pid.dt_s - plant.dt_s) > 1e-12 * plant.dt_s)
    throw std::invalid_argument("controller dt (" + std::to_string(controller.pid.dt_s) + " s) differs from plant dt (" +
                                std::to_string(plant.dt_s) + " s)");
  if (solver == Solver::discrete)
    impl_ = std::make_unique<DiscreteLoop>(plant, controller, bus_delay_steps);
  else
    impl_ = std::make_unique<Ode3Loop>(plant, controller, bus_delay_steps);
}
ClosedLoopStepper::ClosedLoopStepper(ClosedLoopStepper&&) noexcept = default;
ClosedLoopStepper& ClosedLoopStepper::operator=(ClosedLoopStepper&&) noexcept = default;
ClosedLoopStepper::~ClosedLoopStepper() = default;
ClosedLoopSample ClosedLoopStepper::step(double reference_kPa) { return impl_->step(reference_kPa); }

ClosedLoopTrace simulate_closed_loop(Solver solver, const PilotValveParams& plant, const ControllerConfig& controller,
                                     const std::vector<double>& reference_kPa, std::size_t bus_delay_steps) {
  ClosedLoopStepper loop(solver, plant, controller, bus_delay_steps);
  ClosedLoopTrace tr;
  for (auto* v : {&tr.t_s, &tr.reference_kPa, &tr.measured_kPa, &tr.pressure_kPa, &tr.command_mA, &tr.pid_mA})
    v->reserve(reference_kPa.size());
  for (const double r : reference_kPa) push(tr, loop.step(r));
  return tr;
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

std::size_t step_test_samples(const StepTest& test, double dt_s) {
  if (!(test.settle_s > 0) || !(test.after_s > 0) || !(test.r0_kPa != test.r1_kPa))
    throw std::invalid_argument("step test needs settle_s > 0, after_s > 0 and r0 != r1");
  // A level beyond ±1e5 kPa (100 MPa, above any hydraulic system) is a typo, and its square in
  // the metrics overflows long before 1e300: refused, never a NaN result.
  for (const auto& [name, r] : {std::pair{"r0_kPa (--r0)", test.r0_kPa}, std::pair{"r1_kPa (--r1)", test.r1_kPa}})
    if (!(std::fabs(r) <= kMaxLevel_kPa))
      throw std::invalid_argument(std::string(name) + " must be a finite level in [-1e5, 1e5] kPa");
  return steps_or_throw(test.settle_s, dt_s, "settle_s") + steps_or_throw(test.after_s, dt_s, "after_s");
}

namespace {
void check_delay(std::size_t bus_delay_steps, std::size_t n) {
  if (bus_delay_steps > n)
    throw std::invalid_argument("bus delay (--bus-delay) must be at most the test's " + std::to_string(n) +
                                " samples, got " + std::to_string(bus_delay_steps));
}
}  // namespace

StepResult run_step_test(Solver solver, const PilotValveParams& plant, const ControllerConfig& controller,
                         const StepTest& test, std::size_t bus_delay_steps) {
  const std::size_t n = step_test_samples(test, plant.dt_s);
  check_delay(bus_delay_steps, n);
  StepResult res;
  res.trace = simulate_closed_loop(solver, plant, controller, test.reference(plant.dt_s), bus_delay_steps);
  const double ts = test.t_step_s(plant.dt_s);
  res.metrics = step_metrics(res.trace.t_s, res.trace.pressure_kPa, ts, test.r0_kPa, test.r1_kPa);
  res.measured_metrics = step_metrics(res.trace.t_s, res.trace.measured_kPa, ts, test.r0_kPa, test.r1_kPa);
  return res;
}

void check_step_comparison(const PilotValveParams& p, const ControllerConfig& c, const StepTest& test) {
  step_test_samples(test, p.dt_s);
  p.validate();
  const auto fmt_num = [](double x) { return fmt::format("{:.6g}", x); };
  for (const auto& [name, secs] : {std::pair{"settle_s (--settle)", test.settle_s}, std::pair{"after_s (--after)", test.after_s}})
    if (steps_or_throw(secs, p.dt_s, name) < 1)
      throw std::invalid_argument(fmt::format("{} of {} s is shorter than one sample of dt_s (--dt-s) = {} s", name,
                                              fmt_num(secs), fmt_num(p.dt_s)));
  if (!(std::fabs(test.r1_kPa - test.r0_kPa) >= 1e-6))
    throw std::invalid_argument(fmt::format("the step r1 - r0 (--r1, --r0) must be at least 1e-6 kPa in size, got {} kPa",
                                            fmt_num(test.r1_kPa - test.r0_kPa)));
  const double imax = std::max(std::fabs(c.current_min_mA), std::fabs(c.current_max_mA));
  const double pmax = std::fabs(p.bias_kPa) + p.gain_kPa_per_mA * imax;
  if (!(pmax <= 1e6))
    throw std::invalid_argument(fmt::format(
        "plant gain_kPa_per_mA (--gain) = {} kPa/mA at currents up to {} mA (--min-mA/--max-mA) and bias {} kPa gives "
        "pressures up to {} kPa: |bias| + gain x max current must be at most 1e6 kPa",
        fmt_num(p.gain_kPa_per_mA), fmt_num(imax), fmt_num(p.bias_kPa), fmt_num(pmax)));
  const double T = p.dt_s;
  // The PID output's worst case, |u| ≤ Kp·E + Ki·E·t_end + D with E the largest error and D the
  // derivative's (Kd·4E/T unfiltered: ode3's intermediate stages divide by T/2; Kd·N·2E
  // filtered): it must stay a number.
  const auto& g = c.pid.gains;
  const double emax = std::max(std::fabs(test.r0_kPa), std::fabs(test.r1_kPa)) + pmax + 12.1 * p.noise_sigma_kPa + 5000.0;
  const double t_end = test.settle_s + test.after_s;
  const double terms[3] = {g.kp * emax, g.ki_per_s * emax * t_end,
                           g.n_per_s > 0 ? g.kd_s * g.n_per_s * 2.0 * emax : g.kd_s * 4.0 * emax / T};
  if (!(terms[0] + terms[1] + terms[2] <= 1e300)) {
    const char* names[3] = {"pid.kp (--kp)", "pid.ki_per_s (--ki-per-s)", "pid.kd_s (--kd-s)"};
    const std::size_t worst = terms[0] >= terms[1] ? (terms[0] >= terms[2] ? 0 : 2) : (terms[1] >= terms[2] ? 1 : 2);
    throw std::invalid_argument(fmt::format(
        "{}: the PID output could reach {} mA (errors up to {} kPa over {} s), which must stay within 1e300: "
        "kp x E + ki x E x t + the derivative term; reduce the gain",
        names[worst], fmt_num(terms[0] + terms[1] + terms[2]), fmt_num(emax), fmt_num(t_end)));
  }
  if (!(T / p.tau_s <= 2.5))
    throw std::invalid_argument(fmt::format("plant tau_s (--tau) must be at least dt/2.5 = {} s for the ode3 solver "
                                            "(unstable beyond), got {} s",
                                            fmt_num(T / 2.5), fmt_num(p.tau_s)));
  if (p.tau2_s > 0 && !(T / p.tau2_s <= 2.5))
    throw std::invalid_argument(fmt::format("plant tau2_s (--tau2) must be 0 or at least dt/2.5 = {} s for the ode3 "
                                            "solver (unstable beyond), got {} s",
                                            fmt_num(T / 2.5), fmt_num(p.tau2_s)));
  if (!(c.pid.gains.n_per_s * T <= 2.5))
    throw std::invalid_argument(fmt::format("pid.n_per_s (--n-per-s) must be at most 2.5/dt = {} 1/s for the ode3 "
                                            "solver (unstable beyond), got {} 1/s",
                                            fmt_num(2.5 / T), fmt_num(c.pid.gains.n_per_s)));
}

StepComparison run_step_comparison(const PilotValveParams& plant, const ControllerConfig& controller,
                                   const StepTest& test, std::size_t bus_delay_steps, const StepRowFn& row) {
  check_step_comparison(plant, controller, test);
  const std::size_t n = step_test_samples(test, plant.dt_s);
  check_delay(bus_delay_steps, n);
  const std::size_t n0 = steps_or_throw(test.settle_s, plant.dt_s, "settle_s");
  const double ts = test.t_step_s(plant.dt_s);
  ClosedLoopStepper d(Solver::discrete, plant, controller, bus_delay_steps);
  ClosedLoopStepper o(Solver::ode3, plant, controller);
  StepMetricsAccumulator dp(ts, test.r0_kPa, test.r1_kPa), dm(ts, test.r0_kPa, test.r1_kPa);
  StepMetricsAccumulator op(ts, test.r0_kPa, test.r1_kPa), om(ts, test.r0_kPa, test.r1_kPa);
  std::size_t bad_d = 0, bad_o = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double r = k < n0 ? test.r0_kPa : test.r1_kPa;
    const ClosedLoopSample a = d.step(r), b = o.step(r);
    dp.add(a.t_s, a.pressure_kPa);
    dm.add(a.t_s, a.measured_kPa);
    op.add(b.t_s, b.pressure_kPa);
    om.add(b.t_s, b.measured_kPa);
    if (!std::isfinite(a.command_mA) || !std::isfinite(a.pid_mA)) ++bad_d;
    if (!std::isfinite(b.command_mA) || !std::isfinite(b.pid_mA)) ++bad_o;
    if (row) row(a, b);
  }
  StepComparison c;
  c.discrete = {dp.result(), dm.result(), n, bad_d};
  c.ode3 = {op.result(), om.result(), n, bad_o};
  return c;
}

}  // namespace lash
