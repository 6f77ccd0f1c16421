// The adaptive compensator template (lash/control/adaptive_compensator.hpp): the command path
// shared by both aliases, and the carts' adapter (lash's deadzone-deadband estimator on the drive
// and driven positions) against a reference backlash written here with known, unequal gaps.
#include <gtest/gtest.h>

#include "ref_backlash.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "lash/control/adaptive_compensator.hpp"
#include "lash/signals/rng.hpp"

using namespace lash;

namespace {
constexpr double kDt = 0.001;

using test::RefBacklash;  // the asymmetric case's oracle (ref_backlash.hpp)

BacklashCompensationConfig carts(CompensationMode mode) {
  BacklashCompensationConfig c;
  c.mode = mode;
  c.nominal = {0.005, 0.005, 0.0};
  static_cast<EstimatorConfig&>(c.estimator) = EstimatorConfig::thesis(ModelKind::deadzone_deadband, kDt);
  c.estimator.input_shift = 0.01;
  c.estimator.guess_right = 0.015;
  c.estimator.guess_left = -0.015;
  c.estimator.rls.lambda = 0.999;
  c.estimator.rls.forgetting = Forgetting::directional;
  return c;
}

DeadzoneCompensationConfig valve(CompensationMode mode) {
  DeadzoneCompensationConfig c;
  c.mode = mode;
  c.nominal.offset_right = 288.0;
  c.nominal.offset_left = 296.0;
  c.estimator = EstimatorConfig::thesis(ModelKind::input_deadzone, c.estimator.dt_s);
  c.estimator.guess_right = 432.0;
  c.estimator.guess_left = -444.0;
  return c;
}
}  // namespace

TEST(Compensator, NoneIsIdentityAndFixedIsTheNominalInverse) {
  Rng rng(7);
  DeadzoneCompensator dz_none(valve(CompensationMode::none)), dz_fixed(valve(CompensationMode::fixed));
  BacklashCompensator bl_none(carts(CompensationMode::none)), bl_fixed(carts(CompensationMode::fixed));
  DeadzoneInverse dz_ref(valve(CompensationMode::fixed).nominal);
  BacklashInverse bl_ref(carts(CompensationMode::fixed).nominal);
  for (int k = 0; k < 5000; ++k) {
    const double u = 2000.0 * rng.uniform() - 1000.0, p = 0.1 * rng.uniform() - 0.05;
    EXPECT_EQ(dz_none.command(u), u);
    EXPECT_EQ(bl_none.command(p), p);
    EXPECT_EQ(dz_fixed.command(u), dz_ref.step(u));
    EXPECT_EQ(bl_fixed.command(p), bl_ref.step(p));
    dz_fixed.observe(u, 0.5 * u);  // not adaptive: the estimator is not stepped
    bl_fixed.observe(p, p);
  }
  EXPECT_EQ(dz_fixed.updates(), 0u);
  EXPECT_EQ(bl_fixed.updates(), 0u);
  EXPECT_EQ(bl_none.in_use().right, 0.0);
  EXPECT_EQ(bl_fixed.in_use().right, 0.005);
  EXPECT_EQ(dz_fixed.in_use().left, -296.0);  // edges as the deadzone has them: c_l < 0
  EXPECT_EQ(dz_fixed.reason(), AdaptationReason::nominal);
}

// A drive moving ±50 mm (period 4 s) through a backlash of 4 mm up / 6.5 mm down: the adapted
// inverse reaches those gaps from the nominal 5 mm, each side while its verdict says identified.
TEST(BacklashCompensator, AdaptsToUnequalGapsOfAReferenceBacklash) {
  BacklashCompensator comp(carts(CompensationMode::adaptive));
  RefBacklash b{0.004, 0.0065, -0.0065};
  for (int k = 0; k < 30000; ++k) {
    const double w = 0.05 * std::sin(2.0 * std::numbers::pi * k * kDt / 4.0);
    comp.observe(w, b.step(w));
  }
  EXPECT_TRUE(comp.adapter().identified(Side::right)) << comp.estimator_reason(Side::right);
  EXPECT_TRUE(comp.adapter().identified(Side::left)) << comp.estimator_reason(Side::left);
  EXPECT_NEAR(comp.inverse().params().right, 0.004, 1e-4);
  EXPECT_NEAR(comp.inverse().params().left, 0.0065, 1e-4);
  EXPECT_EQ(comp.reason(), AdaptationReason::adapting);
  EXPECT_GT(comp.updates(), 0u);
  // the raw estimate: d the mean half-width, c = ±s + (c_r − c_l')/2 on each side
  const SideParams r = comp.estimator().params(Side::right);
  EXPECT_NEAR(r.d, 0.00525, 1e-4);
  EXPECT_NEAR(r.c, 0.01 - 0.00125, 1e-4);
}

// The drive never reverses beyond the guesses: the estimator has no updates, the inverse stays
// nominal and the verdict says why.
TEST(BacklashCompensator, NoReversalNoAdaptation) {
  BacklashCompensator comp(carts(CompensationMode::adaptive));
  RefBacklash b{0.005, 0.005, 0.0};
  for (int k = 0; k < 20000; ++k) {
    const double w = 0.03 + 0.002 * std::sin(2.0 * std::numbers::pi * k * kDt);  // ±2 mm: inside the 10 mm gap
    comp.observe(w, b.step(w));
  }
  EXPECT_EQ(comp.updates(), 0u);
  EXPECT_EQ(comp.inverse().params().right, 0.005);
  EXPECT_EQ(comp.reason(), AdaptationReason::not_identified);
  EXPECT_NE(std::string(comp.estimator_reason(Side::left)).find("not_updated"), std::string::npos);
}

TEST(BacklashCompensator, RefusesAShiftInsideTheGuesses) {
  auto c = carts(CompensationMode::adaptive);
  c.estimator.guess_right = 0.008;  // below the shift: the edge would lie outside the guess
  EXPECT_THROW(BacklashCompensator{c}, std::invalid_argument);
  c = carts(CompensationMode::adaptive);
  c.estimator.model = ModelKind::coupled_carts;
  EXPECT_THROW(BacklashCompensator{c}, std::invalid_argument);
}
