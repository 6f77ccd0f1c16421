// Control: one sample of the master's controller (PID → deadzone inverse → saturation),
// one sample of the SPEC B1 plant (measure + apply), one discrete closed-loop step test and
// one ode3 step test (2 s at 5 ms = 400 samples). See docs/control.md.
#include <benchmark/benchmark.h>

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

void BM_StepTest(benchmark::State& state) {
  const Solver s = state.range(0) == 0 ? Solver::discrete : Solver::ode3;
  PilotValveParams p;
  p.noise_sigma_kPa = 0.0;
  const auto c = thesis_like();
  for (auto _ : state) benchmark::DoNotOptimize(run_step_test(s, p, c, StepTest{}).metrics.overshoot_pct);
}
BENCHMARK(BM_StepTest)->Arg(0)->Arg(1);

}  // namespace
