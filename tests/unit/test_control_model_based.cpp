// Beyond the thesis: gains and deadzone inverse from the online input-deadzone RLS estimate,
// on the virtual pilot-valve rig (second pole, pressure-dependent τ) and on B1 + a second pole,
// against the thesis gains. Targets from the issue: same 90 % rise (0.11 s, ±20 %), overshoot ≤ 10 %.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "lash/control/gains_file.hpp"
#include "lash/control/model_based.hpp"

namespace {
using namespace lash;

TEST(ModelBased, ImcPiByHand) {
  // K = 2, τ = 0.1, rise 0.23026 s → λ = 0.1: Kp = τ/(Kλ) = 0.5, Ki = 1/(Kλ) = 5
  const auto c = design_from_model({2.0, 0.1, 300.0}, 0.1 * std::log(10.0), 0.005, 0.97);
  EXPECT_NEAR(c.pid.gains.kp, 0.5, 1e-12);
  EXPECT_NEAR(c.pid.gains.ki_per_s, 5.0, 1e-12);
  EXPECT_NEAR(c.dz_inverse.offset_right, 291.0, 1e-12);
  EXPECT_EQ(c.pid.anti_windup, AntiWindup::clamp);
  EXPECT_NEAR(c.pid.output_max, 2000.0 - 291.0, 1e-12);
}

TEST(ModelBased, OnlineEstimateGivesThesisRiseWithoutOvershoot) {
  const rigs::PilotValveRigParams rp;  // the virtual bench, σ = 7.28 kPa
  const double dt = 0.005;
  const FirstOrderDeadzoneModel m = identify_online_on_rig(rp, dt, 1);
  const StepTest st;  // 0 → 1000 kPa after 1 s at 0, as for the thesis gains
  const ControllerConfig online = design_for_rise(m, rp.bias_kPa, 0.11, dt, st);
  const ControllerConfig thesis =
      load_controller_config(std::string(LASH_SOURCE_DIR) + "/config/control/thesis_gains.toml");
  const auto on_rig = run_step_on_rig(rp, online, st, 1).metrics;
  const auto th_rig = run_step_on_rig(rp, thesis, st, 1).metrics;
  PilotValveParams b1;  // B1 model + a faster second pole (8 ms), with noise
  b1.tau2_s = 0.008;
  const auto on_b1 = run_step_test(Solver::discrete, b1, online, st).metrics;
  const auto th_b1 = run_step_test(Solver::discrete, b1, thesis, st).metrics;
  std::printf("online estimate: K %.4f kPa/mA, tau %.4f s, c %.2f mA -> kp %.4f ki %.4f offset %.2f mA\n",
              m.gain_kPa_per_mA, m.tau_s, m.deadzone_mA, online.pid.gains.kp, online.pid.gains.ki_per_s,
              online.dz_inverse.offset_right);
  std::printf("rig       thesis gains: rise %.4f settle %.4f overshoot %.2f %% | online: rise %.4f settle %.4f overshoot %.2f %%\n",
              th_rig.rise_s, th_rig.settling_s, th_rig.overshoot_pct, on_rig.rise_s, on_rig.settling_s,
              on_rig.overshoot_pct);
  std::printf("B1+pole   thesis gains: rise %.4f settle %.4f overshoot %.2f %% | online: rise %.4f settle %.4f overshoot %.2f %%\n",
              th_b1.rise_s, th_b1.settling_s, th_b1.overshoot_pct, on_b1.rise_s, on_b1.settling_s, on_b1.overshoot_pct);
  EXPECT_LE(on_rig.overshoot_pct, 10.0);
  EXPECT_NEAR(on_rig.rise_s, 0.11, 0.2 * 0.11);
  EXPECT_LE(on_b1.overshoot_pct, 10.0);
  EXPECT_NEAR(on_b1.rise_s, 0.11, 0.2 * 0.11);
  EXPECT_GT(th_rig.overshoot_pct, 50.0);  // the thesis gains overshoot far more on the richer plant
}

}  // namespace
