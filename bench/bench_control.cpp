// Control: one sample of the master's controller (PID → deadzone inverse → saturation),
// one sample of the plant of docs/method.md §B1 (measure + apply), one discrete closed-loop step test and
// one ode3 step test (2 s at 5 ms = 400 samples). See docs/control.md.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>

#include "lash/control/adaptive_compensator.hpp"
#include "lash/control/closed_loop.hpp"
#include "lash/control/controller.hpp"
#include "lash/rigs/pilot_valve_model.hpp"

namespace {
using namespace lash;

ControllerConfig thesis_like() {
  ControllerConfig c;
  c.pid.gains = {7.857, 1343.1, 0.02112, 0.0};
  return c;
}

void BM_ControllerStep(benchmark::State& state) {
  ClosedLoopDiscrete ctl(thesis_like());
  double y = 500.0;
  for (auto _ : state) {
    const double i = ctl.step(1000.0, y);
    y += 1e-6 * i - 1e-3 * (y - 500.0);
    benchmark::DoNotOptimize(i);
  }
}
BENCHMARK(BM_ControllerStep);

void BM_PilotValvePlantSample(benchmark::State& state) {
  PilotValvePlant plant(PilotValveParams{});
  for (auto _ : state) {
    const double y = plant.measure();
    plant.apply(800.0);
    benchmark::DoNotOptimize(y);
  }
}
BENCHMARK(BM_PilotValvePlantSample);

// One adaptive controller step of the valve scenario (docs/compensation.md): PID, the
// input-deadzone estimator (IV, both sides in use), the gates and the deadzone inverse, on a
// first-order plant with the 288/−296 mA deadzone driven by a 4 s sine reference.
// `mode`: the fixed inverse or adaptive (re-guessing and drift detection on);
// BM_ControllerStepFixedVsAdaptive runs both side by side in one run (issue 24: adaptive
// within +2 us of fixed), its state.range(0): 0 = fixed, 1 = adaptive.
void compensated_loop(benchmark::State& state, CompensationMode mode) {
  PidConfig pc;
  pc.gains = {0.5, 10.0, 0.0, 0.0};
  pc.anti_windup = AntiWindup::clamp;
  pc.output_min = -2000;
  pc.output_max = 2000;
  Pid pid(pc);
  DeadzoneCompensationConfig cc;
  cc.mode = mode;
  cc.nominal.offset_right = 288.0;
  cc.nominal.offset_left = 296.0;
  cc.estimator.model = ModelKind::input_deadzone;
  cc.estimator.guess_right = 432.0;
  cc.estimator.guess_left = -444.0;
  cc.estimator.rls.lambda = 0.995;
  cc.estimator.method = EstimationMethod::iv;
  DeadzoneCompensator comp(cc);
  double y = 0.0, x = 0.0;
  std::array<double, 800> ref{};  // one 4 s period at 5 ms, computed outside the timed loop
  for (std::size_t j = 0; j < ref.size(); ++j) ref[j] = 600.0 * std::sin(1.5707963 * 0.005 * static_cast<double>(j));
  std::size_t k = 0;
  for (auto _ : state) {
    const double r = ref[k];
    k = k + 1 == ref.size() ? 0 : k + 1;
    const double u = pid.step(r - y) + 0.465 * r;
    const double i = comp.command(u);
    comp.observe(i, y, true);
    const double dz = i > 288.0 ? i - 288.0 : (i < -296.0 ? i + 296.0 : 0.0);
    x = 0.93 * x + 0.07 * 2.15 * dz;
    y = x;
    benchmark::DoNotOptimize(i);
  }
}
void BM_AdaptiveControllerStep(benchmark::State& state) { compensated_loop(state, CompensationMode::adaptive); }
BENCHMARK(BM_AdaptiveControllerStep);

void BM_ControllerStepFixedVsAdaptive(benchmark::State& state) {
  compensated_loop(state, state.range(0) == 0 ? CompensationMode::fixed : CompensationMode::adaptive);
}
BENCHMARK(BM_ControllerStepFixedVsAdaptive)->Arg(0)->Arg(1);

void BM_StepTest(benchmark::State& state) {
  const Solver s = state.range(0) == 0 ? Solver::discrete : Solver::ode3;
  PilotValveParams p;
  p.noise_sigma_kPa = 0.0;
  const auto c = thesis_like();
  for (auto _ : state) benchmark::DoNotOptimize(run_step_test(s, p, c, StepTest{}).metrics.overshoot_pct);
}
BENCHMARK(BM_StepTest)->Arg(0)->Arg(1);

}  // namespace
