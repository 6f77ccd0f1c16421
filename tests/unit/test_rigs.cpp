// Virtual rigs (E3–E5): physics checked against hand-computed steady states,
// thresholds and conservation laws (docs/rigs.md), never against the rig itself.
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "lash/rigs/coupled_carts.hpp"
#include "lash/rigs/motor_cart.hpp"
#include "lash/rigs/pilot_valve_rig.hpp"
#include "lash/rigs/rig.hpp"

using namespace lash::rigs;

namespace {

MotorCartParams quiet_cart() {
  MotorCartParams p;
  p.voltage_noise_V = 0.0;
  p.friction_ripple = 0.0;
  return p;
}

}  // namespace

TEST(MotorCart, DerivedConstantsByHand) {
  const MotorCartParams p;
  // α = K_t·G/(r·R) = 0.05·8/(0.02·2) = 10 N/V; β = (0.05·8/0.02)²/2 = 200 N·s/m; B = 205 N·s/m.
  EXPECT_DOUBLE_EQ(p.force_per_volt(), 10.0);
  EXPECT_NEAR(p.emf_damping(), 200.0, 1e-12);
  EXPECT_NEAR(p.total_damping(), 205.0, 1e-12);
  // m_eff = 7.35 + 1e-5·(8/0.02)² = 8.95 kg.
  EXPECT_NEAR(p.effective_mass(), 8.95, 1e-12);
  const EffectiveModel m = p.effective(0.001);
  EXPECT_NEAR(m.side.right.tau_s, 8.95 / 205.0, 1e-12);
  EXPECT_NEAR(m.side.right.gain, 10.0 / 205.0, 1e-12);
  EXPECT_NEAR(m.side.right.c, 4.0 / 205.0, 1e-12);
  EXPECT_NEAR(m.side.left.c, -4.4 / 205.0, 1e-12);
  EXPECT_NEAR(m.side.right.a1, -std::exp(-0.001 * 205.0 / 8.95), 1e-15);
  // Encoder: 2π·0.02/(8·8000) m per count.
  EXPECT_NEAR(p.encoder_step_m(), 2.0 * M_PI * 0.02 / 64000.0, 1e-18);
}

TEST(MotorCart, SteadyVelocityIsForceBalance) {
  MotorCart cart(quiet_cart(), 0.001, 7);
  for (int k = 0; k < 3000; ++k) cart.step(6.0);
  // (α·V − F_c+)/B = (60 − 4)/205.
  EXPECT_NEAR(cart.true_velocity_m_s(), 56.0 / 205.0, 1e-6);
  for (int k = 0; k < 3000; ++k) cart.step(-6.0);
  EXPECT_NEAR(cart.true_velocity_m_s(), -(60.0 - 4.4) / 205.0, 1e-6);
}

TEST(MotorCart, StictionHoldsBelowBreakAway) {
  // Break-away force 1.3·4 N = 5.2 N ↔ 0.52 V; at 0.5 V (5 N) the cart never moves …
  MotorCart still(quiet_cart(), 0.001, 1);
  for (int k = 0; k < 2000; ++k) still.step(0.5);
  EXPECT_EQ(still.true_velocity_m_s(), 0.0);
  EXPECT_EQ(still.true_position_m(), 0.0);
  // … at 0.55 V (5.5 N) it breaks away and settles at (5.5 − 4)/205 m/s.
  MotorCart moving(quiet_cart(), 0.001, 1);
  for (int k = 0; k < 3000; ++k) moving.step(0.55);
  EXPECT_NEAR(moving.true_velocity_m_s(), 1.5 / 205.0, 1e-6);
  // Between kinetic and break-away level a moving cart keeps moving (4 N < 4.5 N < 5.2 N).
  for (int k = 0; k < 3000; ++k) moving.step(0.45);
  EXPECT_NEAR(moving.true_velocity_m_s(), 0.5 / 205.0, 1e-6);
  // Below the kinetic level it stops and stays stopped.
  for (int k = 0; k < 3000; ++k) moving.step(0.35);
  EXPECT_EQ(moving.true_velocity_m_s(), 0.0);
}

TEST(MotorCart, MeasuredVelocityIsQuantisedEncoderDifference) {
  const MotorCartParams p = quiet_cart();
  MotorCart cart(p, 0.001, 3);
  const double q = p.encoder_step_m() / 0.001;
  double x_meas = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const double y = cart.step(4.0 * std::sin(4.0 * k * 0.001));
    const double counts = y / q;
    ASSERT_NEAR(counts, std::round(counts), 1e-6);
    x_meas += y * 0.001;
    ASSERT_LE(std::fabs(x_meas - cart.true_position_m()), p.encoder_step_m() * 1.000001);
  }
}

TEST(MotorCart, BatchLeastSquaresRecoversEffectiveModel) {
  // With a very fine encoder and no amplifier noise, an ordinary batch least-squares fit of
  // eq. 36 (Eigen QR) lands within 2.5 % of the effective values: the remaining difference
  // (≈ 1.5 % on c and τ) is the 1 ms armature pole and the stiction, which the first-order model
  // does not have.
  MotorCartParams p = quiet_cart();
  p.encoder_counts_per_rev = 4e8;
  const double T = 0.001;
  MotorCart cart(p, T, 5);
  const int n = 30000;
  std::vector<double> v(n), y(n + 1, 0.0);
  for (int k = 0; k < n; ++k) {
    v[k] = 6.0 * std::sin(4.0 * k * T);
    y[k + 1] = cart.step(v[k]);
  }
  const EffectiveModel truth = cart.effective();
  for (int side = 0; side < 2; ++side) {
    Eigen::MatrixXd phi(n, 3);
    Eigen::VectorXd out(n);
    int m = 0;
    for (int k = 1; k < n; ++k) {
      const bool ok = side == 0 ? (y[k] > 0 && y[k - 1] > 0) : (y[k] < 0 && y[k - 1] < 0);
      if (!ok) continue;
      phi.row(m) << -y[k - 1], v[k - 1], 1.0;
      out(m++) = y[k];
    }
    const Eigen::Vector3d eta = phi.topRows(m).colPivHouseholderQr().solve(out.head(m));
    const auto& t = side == 0 ? truth.side.right : truth.side.left;
    const double K = eta(1) / (1 + eta(0)), c = -eta(2) / (1 + eta(0));
    EXPECT_NEAR(K / t.gain, 1.0, 0.025) << "side " << side;
    EXPECT_NEAR(c / t.c, 1.0, 0.025) << "side " << side;
    EXPECT_NEAR(-T / std::log(-eta(0)) / t.tau_s, 1.0, 0.025) << "side " << side;
  }
}

TEST(MotorCart, SeedFixesEveryBit) {
  MotorCart a(MotorCartParams{}, 0.001, 42), b(MotorCartParams{}, 0.001, 42), c(MotorCartParams{}, 0.001, 43);
  bool differs = false;
  for (int k = 0; k < 3000; ++k) {
    const double v = 5.0 * std::sin(3.0 * k * 0.001);
    const double ya = a.step(v), yb = b.step(v), yc = c.step(v);
    ASSERT_EQ(ya, yb);
    differs = differs || ya != yc;
  }
  EXPECT_TRUE(differs);
}

TEST(MotorCart, RejectsBadParameters) {
  MotorCartParams p;
  p.mass_kg = 0.0;
  EXPECT_THROW(MotorCart(p, 0.001), std::invalid_argument);
  p = MotorCartParams{};
  p.breakaway_ratio = 0.9;
  EXPECT_THROW(MotorCart(p, 0.001), std::invalid_argument);
  EXPECT_THROW(MotorCart(MotorCartParams{}, 0.0), std::invalid_argument);
}

TEST(PilotValveRig, SteadyStateIsDeadzoneTimesGain) {
  PilotValveRigParams p;
  p.noise_sigma_kPa = 0.0;
  PilotValveRig rig(p, 0.005, 1);
  EXPECT_NEAR(rig.bias_estimate_kPa(), 90.1, p.quantum_kPa);
  double y = 0;
  for (int k = 0; k < 1000; ++k) y = rig.step(1000.0);
  // docs/method.md §B1: 2.15 kPa/mA beyond 288 mA.
  EXPECT_NEAR(rig.true_pressure_kPa(), 2.15 * (1000.0 - 288.0), 1e-6);
  EXPECT_NEAR(y, 2.15 * 712.0, p.quantum_kPa);
  for (int k = 0; k < 1000; ++k) y = rig.step(-1000.0);
  EXPECT_NEAR(rig.true_pressure_kPa(), 2.08 * (-1000.0 + 296.0), 1e-6);
  // Inside the deadzone the pressure relaxes to 0.
  for (int k = 0; k < 2000; ++k) y = rig.step(250.0);
  EXPECT_NEAR(rig.true_pressure_kPa(), 0.0, 1e-6);
}

TEST(PilotValveRig, BiasRemovedAndNoiseSigma) {
  const PilotValveRigParams p;
  PilotValveRig rig(p, 0.005, 11);
  // The bias record has 200 samples: its mean is within 4σ/√200 of 90.1 kPa.
  EXPECT_NEAR(rig.bias_estimate_kPa(), 90.1, 4 * 7.28 / std::sqrt(200.0));
  const int n = 20000;
  double sum = 0, sum2 = 0;
  for (int k = 0; k < n; ++k) {
    const double y = rig.step(0.0);
    sum += y;
    sum2 += y * y;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 90.1 - rig.bias_estimate_kPa(), 4 * 7.28 / std::sqrt(double(n)));
  EXPECT_NEAR(sd, 7.28, 0.15);
}

TEST(PilotValveRig, TimeConstantShortensWithPressure) {
  // τ(p) = τ0/(1 + |p|/p_half): 0.075 s at 0 kPa, 0.075/(1 + 3000/7500) s at 3000 kPa.
  const PilotValveRigParams p;
  EXPECT_DOUBLE_EQ(p.tau_at(0.0), 0.075);
  EXPECT_NEAR(p.tau_at(3000.0), 0.075 / 1.4, 1e-15);
  EXPECT_NEAR(p.tau_at(-3000.0), 0.075 / 1.4, 1e-15);
  // Step responses: the time to 63 % of the final value is shorter for the large step.
  auto t63 = [&](double current) {
    PilotValveRigParams q = p;
    q.noise_sigma_kPa = 0.0;
    PilotValveRig rig(q, 0.0005, 1);
    const double target = q.gain_right_kPa_mA * (current - q.deadzone_right_mA);
    for (int k = 1; k < 100000; ++k) {
      rig.step(current);
      if (rig.true_pressure_kPa() >= (1 - std::exp(-1.0)) * target) return k * 0.0005;
    }
    return 1e9;
  };
  const double small = t63(400.0), large = t63(2000.0);
  EXPECT_LT(large, small);
  // Small step: pressure 0 … 240 kPa, τ ≈ 0.075…0.073 s, plus the solenoid lag: the force needs
  // −8 ms·ln(1 − 288/400) = 10.2 ms to reach the deadzone edge and then lags 8 ms.
  EXPECT_GT(small, 0.074 + 0.008);
  EXPECT_LT(small, 0.075 + 0.0102 + 0.008 + 0.002);
  // Large step: τ falls to 0.075/(1 + 3680/7500) = 0.050 s near the end.
  EXPECT_LT(large, 0.075 + 0.0102);
}

TEST(CoupledCarts, PushesAtFullVelocityThenWaitsInTheSlot) {
  CoupledCartsParams p;
  p.motor.voltage_noise_V = 0.0;
  p.motor.friction_ripple = 0.0;
  CoupledCarts rig(p, 0.001, 2);
  for (int k = 0; k < 4000; ++k) rig.step(6.0);
  // Pushing: one body, (α·V − F_c1 − F_f2)/B = (60 − 4 − 2.5)/205.
  EXPECT_NEAR(rig.motor_velocity_m_s(), 53.5 / 205.0, 1e-6);
  EXPECT_NEAR(rig.free_velocity_m_s(), 53.5 / 205.0, 1e-6);
  EXPECT_NEAR(rig.motor_position_m() - rig.free_position_m(), p.half_clearance_m, 1e-9);
  // Reverse: the free cart stops (bearing friction) while the pin crosses the slot, 2d.
  const double x2_before = rig.free_position_m();
  double x2_stop = 0;
  int k = 0;
  for (; k < 4000; ++k) {
    rig.step(-6.0);
    if (rig.free_velocity_m_s() == 0.0) {
      x2_stop = rig.free_position_m();
      break;
    }
  }
  ASSERT_LT(k, 4000);
  // Coasting from 0.261 m/s at 2.5/0.42 m/s² takes v²/(2a) = 5.7 mm < 2d = 10 mm, plus at most one
  // sample period (0.26 mm) of pushing before the pin lets go.
  const double v0 = 53.5 / 205.0, a = 2.5 / 0.42;
  EXPECT_LE(x2_stop - x2_before, v0 * v0 / (2 * a) + v0 * 0.001);
  EXPECT_GE(x2_stop - x2_before, v0 * v0 / (2 * a) - 5e-6);
  // It then waits while the pin crosses the slot …
  for (int j = 0; j < 20; ++j) {
    rig.step(-6.0);
    ASSERT_EQ(rig.free_position_m(), x2_stop);
  }
  // … and is pulled along at (α·V − F_c1− − F_f2)/B.
  for (k = 0; k < 4000; ++k) rig.step(-6.0);
  EXPECT_NEAR(rig.free_velocity_m_s(), -(60 - 4.4 - 2.5) / 205.0, 1e-6);
  EXPECT_NEAR(rig.free_position_m() - rig.motor_position_m(), p.half_clearance_m, 1e-9);
  EXPECT_GT(rig.impacts(), 0);
}

TEST(Rigs, ParseKind) {
  EXPECT_EQ(parse_rig_kind("motor_cart"), RigKind::motor_cart);
  EXPECT_EQ(parse_rig_kind("pilot_valve"), RigKind::pilot_valve);
  EXPECT_EQ(parse_rig_kind("coupled_carts"), RigKind::coupled_carts);
  EXPECT_THROW(parse_rig_kind("cart"), std::invalid_argument);
}
