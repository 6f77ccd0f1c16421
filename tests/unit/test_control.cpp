// PID, deadzone inverse, controller chain and the pilot-valve model of docs/method.md §B1.
// Expected numbers are hand computations (shown inline) or Python's round().
#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "lash/control/controller.hpp"
#include "lash/control/deadzone_inverse.hpp"
#include "lash/control/pid.hpp"
#include "lash/rigs/pilot_valve_model.hpp"

namespace {
using namespace lash;

TEST(Pid, ForwardEulerIntegratorAndBackwardDifferenceByHand) {
  PidConfig c;
  c.gains = {2.0, 10.0, 0.01, 0.0};
  c.dt_s = 0.1;
  Pid pid(c);
  // k=0: P=2·1, I=0, D=0.01·(1−0)/0.1=0.1 → 2.1
  EXPECT_NEAR(pid.step(1.0), 2.1, 1e-12);
  // k=1: P=4, I=0+10·0.1·1=1, D=0.01·(2−1)/0.1=0.1 → 5.1
  EXPECT_NEAR(pid.step(2.0), 5.1, 1e-12);
  // k=2: P=1, I=1+10·0.1·2=3, D=0.01·(0.5−2)/0.1=−0.15 → 3.85
  EXPECT_NEAR(pid.step(0.5), 3.85, 1e-12);
  EXPECT_NEAR(pid.integrator(), 3.0, 1e-12);
}

TEST(Pid, BackwardEulerAndTrapezoidalIntegrators) {
  PidConfig c;
  c.gains = {0.0, 10.0, 0.0, 0.0};
  c.dt_s = 0.1;
  c.integrator = IntegratorMethod::backward_euler;
  Pid be(c);
  EXPECT_NEAR(be.step(1.0), 1.0, 1e-12);  // 10·0.1·1
  EXPECT_NEAR(be.step(2.0), 3.0, 1e-12);  // + 10·0.1·2
  c.integrator = IntegratorMethod::trapezoidal;
  Pid tr(c);
  EXPECT_NEAR(tr.step(1.0), 0.5, 1e-12);  // 10·0.1·(1+0)/2
  EXPECT_NEAR(tr.step(2.0), 2.0, 1e-12);  // + 10·0.1·(2+1)/2
  EXPECT_EQ(parse_integrator_method("trapezoidal"), IntegratorMethod::trapezoidal);
  EXPECT_THROW(parse_integrator_method("rk4"), std::invalid_argument);
}

TEST(Pid, FilteredDerivativeByHandAndLimit) {
  PidConfig c;
  c.gains = {0.0, 0.0, 0.01, 20.0};
  c.dt_s = 0.1;
  Pid pid(c);
  // D0 = (0 + 0.01·20·1)/(1 + 20·0.1) = 0.2/3
  EXPECT_NEAR(pid.step(1.0), 0.2 / 3.0, 1e-15);
  // D1 = (0.2/3 + 0.2·1)/3
  EXPECT_NEAR(pid.step(2.0), (0.2 / 3.0 + 0.2) / 3.0, 1e-15);
  // N → ∞ tends to the backward difference Kd·Δe/T = 0.1
  c.gains.n_per_s = 1e9;
  Pid fast(c);
  EXPECT_NEAR(fast.step(1.0), 0.1, 1e-9);
}

TEST(Pid, ClampAntiWindupFreezesIntegrator) {
  PidConfig c;
  c.gains = {1.0, 100.0, 0.0, 0.0};
  c.dt_s = 0.01;
  c.integrator = IntegratorMethod::backward_euler;
  c.anti_windup = AntiWindup::clamp;
  c.output_min = -5.0;
  c.output_max = 5.0;
  Pid pid(c);
  for (int k = 0; k < 100; ++k) EXPECT_LE(pid.step(10.0), 5.0);
  EXPECT_DOUBLE_EQ(pid.output(), 5.0);
  EXPECT_DOUBLE_EQ(pid.integrator(), 0.0);  // P alone (10) already saturates → never integrates
  // Without anti-windup the integrator would hold 100·0.01·10·100 = 1000.
  c.anti_windup = AntiWindup::none;
  Pid wind(c);
  for (int k = 0; k < 100; ++k) wind.step(10.0);
  EXPECT_NEAR(wind.integrator(), 1000.0, 1e-9);
}

TEST(Pid, RejectsBadConfig) {
  PidConfig c;
  c.gains.kp = -1.0;
  EXPECT_THROW(Pid{c}, std::invalid_argument);
  c.gains.kp = 1.0;
  c.dt_s = 0.0;
  EXPECT_THROW(Pid{c}, std::invalid_argument);
  c.dt_s = 0.005;
  c.gains.ki_per_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(Pid{c}, std::invalid_argument);
}

TEST(Controller, ChainPidThenInverseThenSaturation) {
  ControllerConfig c;
  c.pid.gains = {1.5, 0.0, 0.0, 0.0};
  ClosedLoopDiscrete ctl(c);
  EXPECT_NEAR(ctl.step(100.0, 0.0), 150.0 + 279.36, 1e-12);  // P = 1.5·100
  EXPECT_DOUBLE_EQ(ctl.step(0.0, 100.0), 0.0);              // −150 − 279.36 → clamped at 0
  EXPECT_NEAR(ctl.pid_output(), -150.0, 1e-12);
  EXPECT_DOUBLE_EQ(ctl.step(5000.0, 0.0), 2000.0);          // driver limit
  c.current_min_mA = 10.0;
  c.current_max_mA = 5.0;
  EXPECT_THROW(ClosedLoopDiscrete{c}, std::invalid_argument);
}

TEST(PilotValve, SensorCodeMatchesPythonRound) {
  // Python: round((p/48.82 + 5.98)·65535/100)
  EXPECT_EQ(encode_pressure_raw(90.1), 5128);
  EXPECT_EQ(encode_pressure_raw(0.0), 3919);
  EXPECT_EQ(encode_pressure_raw(1000.0), 17343);
  EXPECT_EQ(encode_pressure_raw(3770.0), 54527);
  EXPECT_EQ(encode_pressure_raw(-400.0), 0);
  EXPECT_EQ(encode_pressure_raw(5000.0), 65535);
  EXPECT_NEAR(decode_pressure_raw(5128), 90.06442624551762, 1e-9);
  EXPECT_NEAR(decode_pressure_raw(17343), 1000.0152921950103, 1e-9);
}

TEST(PilotValve, NoiseFreeStepIsSampledFirstOrderAboveDeadzone) {
  PilotValveParams p;
  p.noise_sigma_kPa = 0.0;
  p.quantize = false;
  PilotValvePlant plant(p);
  EXPECT_DOUBLE_EQ(plant.measure(), 90.1);
  plant.apply(500.0);
  for (int n = 1; n <= 40; ++n) {
    // K·(500 − 288)·(1 − e^{−nT/τ}) above the bias
    const double expect = 90.1 + 2.15 * 212.0 * (1.0 - std::exp(-n * 0.005 / 0.07));
    EXPECT_NEAR(plant.measure(), expect, 1e-9) << n;
    plant.apply(500.0);
  }
  // Inside the deadzone nothing moves.
  PilotValvePlant quiet(p);
  for (int n = 0; n < 10; ++n) quiet.apply(280.0);
  EXPECT_DOUBLE_EQ(quiet.measure(), 90.1);
}

TEST(PilotValve, SeededNoiseIsReproducibleAndHasSigma) {
  PilotValveParams p;
  p.quantize = false;
  PilotValvePlant a(p), b(p);
  double s = 0, s2 = 0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const double ya = a.measure();
    EXPECT_EQ(ya, b.measure());
    a.apply(0.0);
    b.apply(0.0);
    s += ya - 90.1;
    s2 += (ya - 90.1) * (ya - 90.1);
  }
  const double sd = std::sqrt(s2 / n - (s / n) * (s / n));
  EXPECT_NEAR(sd, 7.28, 7.28 * 0.03);  // 3 % ≈ 6 standard errors of a 20000-sample σ
  PilotValveParams q = p;
  q.quantize = true;
  PilotValvePlant qp(q);
  const double y = qp.measure();
  EXPECT_EQ(y, decode_pressure_raw(qp.last_raw()));
}

TEST(PilotValve, SecondLagSlowsTheStep) {
  PilotValveParams p;
  p.noise_sigma_kPa = 0.0;
  p.quantize = false;
  p.tau2_s = 0.02;
  PilotValvePlant two(p);
  p.tau2_s = 0.0;
  PilotValvePlant one(p);
  double y1 = 0, y2 = 0;
  for (int n = 0; n < 400; ++n) {
    y1 = one.measure();
    y2 = two.measure();
    if (n == 10) {
      EXPECT_LT(y2, y1);
    }
    one.apply(1000.0);
    two.apply(1000.0);
  }
  EXPECT_NEAR(y2, y1, 1e-6);  // same steady state 90.1 + 2.15·712
  EXPECT_NEAR(y1, 90.1 + 2.15 * 712.0, 1e-6);
  PilotValveParams bad;
  bad.tau_s = 0.0;
  EXPECT_THROW(PilotValvePlant{bad}, std::invalid_argument);
}

}  // namespace
