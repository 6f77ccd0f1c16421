// Issue 29: runs that stream instead of keeping whole traces, figures computed sample by sample,
// worst-case bounds checked before a run, and no non-finite figure passed on silently.
// Expected values: hand computations (geometric sums, the metrics' definitions) and identities
// (the streamed figures equal the ones computed from the kept trace, by an independent path).
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lash/control/closed_loop.hpp"
#include "lash/control/gains_file.hpp"
#include "lash/experiments/closed_loop_scenario.hpp"
#include "lash/hil/report.hpp"
#include "lash/hil/settings.hpp"
#include "lash/rigs/drift.hpp"
#include "lash/io/memory.hpp"
#include "lash/metrics/step_response.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"
#include "lash/signals/signal.hpp"

namespace {
using namespace lash;

const std::string kSrc = LASH_SOURCE_DIR;

// ---- step metrics, one sample at a time ----

TEST(StepMetricsStream, StatusSaysWhyAFigureIsMissing) {
  // Never reaches 0.9: rise not_reached; outside the ±0.1 band at the end: not_settled.
  StepMetricsAccumulator a(0.0, 0.0, 1.0);
  for (int k = 0; k <= 10; ++k) a.add(k * 0.1, 0.5);
  const StepMetrics m = a.result();
  EXPECT_TRUE(std::isnan(m.rise_s));
  EXPECT_EQ(m.rise_status, FigureStatus::not_reached);
  EXPECT_TRUE(std::isnan(m.settling_s));
  EXPECT_EQ(m.settling_status, FigureStatus::not_settled);
  EXPECT_EQ(m.overshoot_pct, 0.0);
  EXPECT_EQ(m.overshoot_status, FigureStatus::ok);
  EXPECT_EQ(m.samples, 11u);
  EXPECT_NEAR(m.record_s, 1.0, 1e-12);
  EXPECT_STREQ(to_string(m.rise_status), "not_reached");
}

TEST(StepMetricsStream, ANonFiniteSampleVoidsEveryFigure) {
  // Before: a NaN compared false everywhere, and the figures of the finite samples were
  // reported as if nothing had happened (overshoot 0 %). Now none is reported, with the reason.
  const std::vector<double> t{0, 1, 2, 3, 4, 5}, y{0, 0.5, 1.0, NAN, 1.0, 1.0};
  const StepMetrics m = step_metrics(t, y, 0.0, 0.0, 1.0);
  EXPECT_EQ(m.nonfinite, 1u);
  EXPECT_EQ(m.first_nonfinite_s, 3.0);
  for (double x : {m.rise_s, m.settling_s, m.overshoot_pct}) EXPECT_TRUE(std::isnan(x));
  for (FigureStatus s : {m.rise_status, m.settling_status, m.overshoot_status}) EXPECT_EQ(s, FigureStatus::not_finite);
}

TEST(StepMetricsStream, HandTraceFigures) {
  // The hand trace of test_metrics with samples before the step that must be ignored:
  // rise 0.9 crossed at 1.8 s, overshoot 20 %, band entered for good at 3.5 s (after the step at 0).
  StepMetricsAccumulator a(0.0, 0.0, 1.0);
  a.add(-2.0, 5.0);
  a.add(-1.0, -5.0);
  const double t[] = {0, 1, 2, 3, 4, 5}, y[] = {0, 0.5, 1.0, 1.2, 1.0, 1.0};
  for (int i = 0; i < 6; ++i) a.add(t[i], y[i]);
  const StepMetrics m = a.result();
  EXPECT_NEAR(m.rise_s, 1.8, 1e-12);
  EXPECT_NEAR(m.overshoot_pct, 20.0, 1e-12);
  EXPECT_NEAR(m.settling_s, 3.5, 1e-12);
  EXPECT_EQ(m.samples, 6u);
  EXPECT_THROW(StepMetricsAccumulator(0.0, 1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(StepMetricsAccumulator(1.0, 0.0, 1.0).result(), std::invalid_argument);
}

// ---- closed loop: both solvers in lockstep, nothing kept ----

TEST(ClosedLoopStream, LockstepFiguresAndRowsEqualTheKeptTraces) {
  const ControllerConfig c = load_controller_config(kSrc + "/config/control/thesis_gains.toml");
  PilotValveParams p;
  p.noise_sigma_kPa = 7.28;
  const StepTest st;
  const StepResult d = run_step_test(Solver::discrete, p, c, st, 2);
  const StepResult o = run_step_test(Solver::ode3, p, c, st);
  std::size_t k = 0;
  bool rows_equal = true;
  const StepComparison s = run_step_comparison(p, c, st, 2, [&](const ClosedLoopSample& a, const ClosedLoopSample& b) {
    rows_equal = rows_equal && a.t_s == d.trace.t_s[k] && a.measured_kPa == d.trace.measured_kPa[k] &&
                 a.pressure_kPa == d.trace.pressure_kPa[k] && a.command_mA == d.trace.command_mA[k] &&
                 b.measured_kPa == o.trace.measured_kPa[k] && b.pressure_kPa == o.trace.pressure_kPa[k] &&
                 b.command_mA == o.trace.command_mA[k];
    ++k;
  });
  EXPECT_TRUE(rows_equal);
  EXPECT_EQ(k, d.trace.samples());
  EXPECT_EQ(s.discrete.samples, k);
  for (auto [a, b] : {std::pair{s.discrete.metrics, d.metrics}, std::pair{s.discrete.measured_metrics, d.measured_metrics},
                      std::pair{s.ode3.metrics, o.metrics}, std::pair{s.ode3.measured_metrics, o.measured_metrics}}) {
    EXPECT_EQ(a.rise_s, b.rise_s);
    EXPECT_EQ(a.overshoot_pct, b.overshoot_pct);
    EXPECT_TRUE(a.settling_s == b.settling_s || (std::isnan(a.settling_s) && std::isnan(b.settling_s)));
  }
  EXPECT_EQ(s.discrete.nonfinite_commands, 0u);
}

TEST(ClosedLoopStream, OptionsThatMakeAFigureNonFiniteAreRefusedNamingTheOption) {
  const ControllerConfig c0 = load_controller_config(kSrc + "/config/control/thesis_gains.toml");
  auto refused = [&](PilotValveParams p, ControllerConfig c, StepTest st, const char* option) {
    try {
      check_step_comparison(p, c, st);
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(option), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << option << " not refused";
  };
  PilotValveParams p;
  StepTest st;
  {
    ControllerConfig c = c0;
    c.pid.gains.kp = 1e308;
    c.pid.gains.ki_per_s = 1e308;  // kp·e overflows, inf − inf = nan: before, a silent 0 % overshoot
    refused(p, c, st, "--kp");
  }
  {
    ControllerConfig c = c0;
    c.pid.gains.kd_s = 1e300;
    refused(p, c, st, "--kd-s");
  }
  {
    PilotValveParams q = p;
    q.gain_kPa_per_mA = 1e300;  // 2e303 kPa: overshoot 1e301 % before
    refused(q, c0, st, "--gain");
  }
  {
    PilotValveParams q = p;
    q.tau_s = 1e-300;  // ode3 beyond its stability interval: 3.6e299 % before
    refused(q, c0, st, "--tau");
  }
  {
    StepTest s2 = st;
    s2.r1_kPa = 1e-320;  // a step of 1e-320 kPa: the normalised response overflows
    refused(p, c0, s2, "--r1");
  }
  {
    PilotValveParams q = p;
    q.dt_s = 1e300;
    ControllerConfig c = c0;
    c.pid.dt_s = 1e300;  // no sample after the step
    refused(q, c, st, "--settle");
  }
  EXPECT_NO_THROW(check_step_comparison(p, c0, st));
}

TEST(ClosedLoopStream, ADelayLineLargerThanTheMachineIsRefusedWithTheFigure) {
  PilotValveParams p;
  ControllerConfig c;
  c.pid.gains = {0.5, 0.0, 0.0, 0.0};
  try {
    ClosedLoopStepper s(Solver::discrete, p, c, 99999999999ULL);
    FAIL() << "not refused";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--bus-delay"), std::string::npos) << m;
    EXPECT_NE(m.find("800 GB"), std::string::npos) << m;  // 8 bytes × 1e11 samples
  }
}

TEST(Memory, FiguresInDecimalUnits) {
  EXPECT_EQ(format_bytes(8e11), "800 GB");
  EXPECT_EQ(format_bytes(1536.0), "1.54 kB");
  EXPECT_EQ(format_bytes(12.0), "12 B");
  EXPECT_GT(memory_available_bytes(), 0u);
  EXPECT_THROW(require_memory(std::numeric_limits<double>::infinity(), "x"), std::invalid_argument);
  EXPECT_NO_THROW(require_memory(1024.0, "x"));
}

// ---- simulate: rows streamed, worst case bounded before the run ----

TEST(SimulateStream, RowsAreTheTraceBitForBit) {
  Plant plant = load_plant(kSrc + "/config/plants/thesis_eq34.toml");
  SimulationSpec spec;
  spec.input.kind = Waveform::randomized;
  spec.input.variance = 1e5;
  spec.duration_s = 5.0;
  spec.noise_variance = 200.0;
  spec.seed = 3;
  const SimulationTrace tr = simulate(plant, spec);
  std::size_t k = 0, mismatches = 0;
  const std::size_t n = simulate_rows(plant, spec, [&](std::span<const double> row) {
    for (std::size_t c = 0; c < row.size(); ++c) mismatches += row[c] != tr.cols[c][k];
    ++k;
  });
  EXPECT_EQ(n, tr.samples());
  EXPECT_EQ(k, n);
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(simulation_columns(plant), tr.names);
}

TEST(SimulateStream, OutputBoundByHandForEq34) {
  // DZ(−300, 200) → w(k) = −a1 w(k−1) + b1 u(k−1) with max|a1| = 0.96, max|b1| = 0.15 → DB(50, 30):
  // |w| ≤ 0.15·Σ_{i<n} 0.96^i·(max|v| + 300), |y| ≤ that + 50.
  const Plant plant = load_plant(kSrc + "/config/plants/thesis_eq34.toml");
  for (std::size_t n : {1u, 10u, 200u, 100000u}) {
    const double S = (1.0 - std::pow(0.96, static_cast<double>(n))) / 0.04;
    const OutputBound b = output_bound(plant, n);
    EXPECT_NEAR(b.gain, 0.15 * S, 1e-12 * S) << n;
    EXPECT_NEAR(b.offset, 0.15 * S * 300.0 + 50.0, 1e-9 * S) << n;
    EXPECT_NEAR(max_input_magnitude(plant, n), (1e300 - b.offset) / b.gain, 1e-12 * 1e300 / b.gain);
  }
  // The bound holds on the plant itself: a square wave of 5000 over 2000 samples.
  Plant p2 = load_plant(kSrc + "/config/plants/thesis_eq34.toml");
  SimulationSpec spec;
  spec.input.kind = Waveform::square;
  spec.input.amplitude = 5000.0;
  spec.input.frequency_rad_s = 0.3;
  spec.duration_s = 10.0;
  double ymax = 0.0;
  simulate_rows(p2, spec, [&](std::span<const double> r) { ymax = std::max(ymax, std::fabs(r[3])); });
  EXPECT_LE(ymax, output_bound(p2, 2000).at(5000.0));
  EXPECT_GT(ymax, 0.5 * output_bound(p2, 2000).at(5000.0));  // and it is not loose by orders of magnitude
}

TEST(SimulateStream, UnstableLagBoundGrowsGeometrically) {
  std::vector<Block> b;
  b.emplace_back(FirstOrder(PerSide<FirstOrderParams>::both({-1.01, 2.0})));
  b.emplace_back(Saturation(-5.0, 7.0));
  std::vector<Block> b2;
  b2.emplace_back(FirstOrder(PerSide<FirstOrderParams>::both({-1.01, 2.0})));
  const Plant sat(std::move(b), 0.01), open(std::move(b2), 0.01);
  EXPECT_NEAR(output_bound(open, 100).gain, 2.0 * (std::pow(1.01, 100.0) - 1.0) / 0.01, 1e-9);
  EXPECT_TRUE(std::isinf(output_bound(open, 1000000).gain));
  EXPECT_EQ(max_input_magnitude(open, 1000000), 0.0);
  // A saturation caps whatever comes before it: any input is safe.
  EXPECT_EQ(output_bound(sat, 1000000).gain, 0.0);
  EXPECT_EQ(output_bound(sat, 1000000).offset, 7.0);
  EXPECT_TRUE(std::isinf(max_input_magnitude(sat, 1000000)));
}

TEST(SimulateStream, SignalMagnitudeBounds) {
  SignalSpec s;
  s.amplitude = -3.0;
  s.offset = 1.5;
  for (Waveform w : {Waveform::sine, Waveform::square, Waveform::triangle}) {
    s.kind = w;
    EXPECT_EQ(max_abs_value(s), 4.5);
  }
  s.kind = Waveform::constant;
  EXPECT_EQ(max_abs_value(s), 1.5);
  s.kind = Waveform::steps;
  s.steps = {{0.0, 2.0}, {1.0, -7.0}};
  EXPECT_EQ(max_abs_value(s), 8.5);
  s.kind = Waveform::randomized;
  s.variance = 4.0;
  EXPECT_NEAR(max_abs_value(s), 1.5 + 12.1 * 2.0, 1e-12);
  // The polar method's bound: |g| ≤ sqrt(−2 ln 2^−104) = 12.01 (the smallest s it can draw).
  EXPECT_LT(std::sqrt(-2.0 * std::log(std::ldexp(1.0, -104))), 12.1);
}

TEST(SimulateStream, AnOverflowStopsBeforeTheRowIsPassedOn) {
  std::vector<Block> b;
  b.emplace_back(FirstOrder(PerSide<FirstOrderParams>::both({-2.0, 1.0})));
  Plant plant(std::move(b), 0.01);
  SimulationSpec spec;
  spec.input.kind = Waveform::constant;
  spec.input.amplitude = 1e300;
  spec.duration_s = 100.0;
  std::size_t rows = 0;
  bool finite = true;
  EXPECT_THROW(simulate_rows(plant, spec,
                             [&](std::span<const double> r) {
                               ++rows;
                               for (double x : r) finite = finite && std::isfinite(x);
                             }),
               std::invalid_argument);
  EXPECT_TRUE(finite);
  EXPECT_GT(rows, 0u);
  EXPECT_LT(rows, 10000u);
}

// ---- closed-loop scenario: streamed rows, tracking accumulated on the way ----

TEST(ScenarioStream, CartsTrackingEqualsTheFiguresOfTheStreamedRows) {
  experiments::ClosedLoopScenario s =
      experiments::load_closed_loop_scenario(kSrc + "/config/scenarios/closed_loop/carts_no_drift.toml");
  s.duration_s = 12.0;
  s.score_t0_s = 4.0;
  s.score_t1_s = 12.0;
  std::vector<double> r, y;
  const auto res = experiments::run_closed_loop_scenario(s, CompensationMode::fixed,
                                                         [&](const experiments::ClosedLoopScenarioRow& row) {
                                                           r.push_back(row.reference);
                                                           y.push_back(row.output);
                                                         });
  EXPECT_EQ(r.size(), 12000u);
  EXPECT_EQ(res.samples, 12000u);
  const hil::Tracking w = hil::tracking(r, y, s.dt_s, s.score_t0_s, s.score_t1_s);
  EXPECT_EQ(res.rms_error, w.rms_error);
  EXPECT_EQ(res.max_abs_error, w.max_abs_error);
  EXPECT_GT(w.samples, 7000u);
  // No row asked for: the same figures.
  const auto res2 = experiments::run_closed_loop_scenario(s, CompensationMode::fixed);
  EXPECT_EQ(res2.rms_error, res.rms_error);
}

// The valve runs on the bench's nodes one control step at a time: every row streamed, the
// figures accumulated on the way equal to a hand computation over the rows (window, before and
// after the drift), the same as the nodes' logs (hil::simulate_bench) and with the rig's true
// edges in use at each step under the oracle (the slave and the master walk the same ramp).
TEST(ScenarioStream, ValveFiguresEqualAHandComputationOverTheStreamedRows) {
  experiments::ClosedLoopScenario s =
      experiments::load_closed_loop_scenario(kSrc + "/config/scenarios/closed_loop/valve_slow_ramp.toml");
  s.duration_s = 20.0;
  s.score_t0_s = 12.0;
  s.score_t1_s = 20.0;
  s.drift[0].at_s = 4.0;
  s.drift[0].ramp_s = 8.0;  // 1600 control steps, edge 288 -> 380 mA
  std::vector<experiments::ClosedLoopScenarioRow> rows;
  const auto res = experiments::run_closed_loop_scenario(
      s, CompensationMode::oracle, [&](const experiments::ClosedLoopScenarioRow& r) { rows.push_back(r); });
  ASSERT_EQ(rows.size(), 4000u);
  ASSERT_EQ(res.samples, 4000u);
  ASSERT_TRUE(res.bench.has_value());
  // By hand: RMS and max of r − y with sample m at t = m·5 ms in [t0, t1] (both ends included).
  auto by_hand = [&](std::size_t m0, std::size_t m1, const hil::Tracking& got) {
    double sum2 = 0.0, mx = 0.0;
    for (std::size_t m = m0; m <= m1; ++m) {
      const double e = rows[m].reference - rows[m].output;
      sum2 += e * e;
      mx = std::max(mx, std::fabs(e));
    }
    EXPECT_EQ(got.samples, m1 - m0 + 1);
    EXPECT_NEAR(got.rms_error, std::sqrt(sum2 / static_cast<double>(m1 - m0 + 1)), 1e-12 * got.rms_error);
    EXPECT_EQ(got.max_abs_error, mx);
  };
  by_hand(2400, 3999, res.bench->window);  // [12, 20] s
  EXPECT_EQ(res.rms_error, res.bench->window.rms_error);
  ASSERT_TRUE(res.bench->before_drift && res.bench->after_drift);
  by_hand(0, 799, *res.bench->before_drift);  // [0, 4) s
  by_hand(800, 3999, *res.bench->after_drift);  // [4, 20] s
  // The oracle's inverse: the rig's true right edge of each control step, the ramp interpolated
  // in place: 288 mA up to step 800, 288 + 92·(k − 800)/1600 on the ramp, 380 mA from step 2400.
  for (std::size_t k : {0u, 799u, 800u, 801u, 1600u, 2399u, 2400u, 3999u}) {
    const double f = k <= 800 ? 0.0 : (k >= 2400 ? 1.0 : (static_cast<double>(k) - 800.0) / 1600.0);
    EXPECT_NEAR(rows[k].param_right, 288.0 + 92.0 * f, 1e-9) << "k = " << k;
    EXPECT_EQ(rows[k].param_left, -296.0) << "k = " << k;
  }
  // The bench holds the ramp as one segment (it held one rig change per control step).
  hil::BenchSettings b;
  experiments::apply_to_bench(s, CompensationMode::oracle, b);
  ASSERT_EQ(b.scenario->plant.drift.size(), 1u);
  EXPECT_EQ(b.scenario->plant.drift[0].k0, 800);
  EXPECT_EQ(b.scenario->plant.drift[0].n, 1600);
  ASSERT_TRUE(b.scenario->law.oracle.has_value());
}

// rigs::DriftCursor walks the segments to the values of rig_config_at (the direct formula) at
// every step, reporting a change exactly where the rig changes: a ramp's steps k0 + 1 … k0 + n
// and a step's k0, also when a step follows a ramp at its last step and when k jumps.
TEST(ScenarioStream, DriftCursorWalksTheValuesOfRigConfigAt) {
  experiments::ClosedLoopScenario s =
      experiments::load_closed_loop_scenario(kSrc + "/config/scenarios/closed_loop/valve_slow_ramp.toml");
  s.dt_s = 1.0;
  s.duration_s = 100.0;
  experiments::Drift ramp = s.drift[0];  // 288 -> 380 mA over [10, 20]
  ramp.at_s = 10.0;
  ramp.ramp_s = 10.0;
  experiments::Drift step = ramp;  // then a step to 300 mA at 20 (where the ramp ends)
  step.at_s = 20.0;
  step.ramp_s = 0.0;
  step.before = ramp.after;
  step.after = ramp.after;
  step.after.pilot_valve.deadzone_right_mA = 300.0;
  s.drift = {ramp, step};
  std::vector<rigs::DriftSegment<rigs::PilotValveRigParams>> seg;
  for (const auto& d : s.drift)
    seg.push_back({std::llround(d.at_s), std::llround(d.ramp_s), d.before.pilot_valve, d.after.pilot_valve});
  rigs::DriftCursor<rigs::PilotValveRigParams> c;
  double now = 288.0;
  for (std::int64_t k = 0; k < 40; ++k) {
    const rigs::PilotValveRigParams* p = c.advance(seg, k);
    EXPECT_EQ(p != nullptr, k >= 11 && k <= 20) << "k = " << k;
    if (p) now = p->deadzone_right_mA;
    EXPECT_EQ(now, experiments::rig_config_at(s, k).pilot_valve.deadzone_right_mA) << "k = " << k;
  }
  EXPECT_EQ(now, 300.0);
  EXPECT_DOUBLE_EQ(experiments::rig_config_at(s, 15).pilot_valve.deadzone_right_mA, 334.0);  // (288 + 380)/2
  rigs::DriftCursor<rigs::PilotValveRigParams> jump;  // k jumps into the ramp, then past the step
  ASSERT_NE(jump.advance(seg, 15), nullptr);
  EXPECT_DOUBLE_EQ(jump.advance(seg, 16)->deadzone_right_mA, 288.0 + 92.0 * 0.6);
  EXPECT_EQ(jump.advance(seg, 30)->deadzone_right_mA, 300.0);
  EXPECT_EQ(jump.advance(seg, 31), nullptr);
}

}  // namespace
