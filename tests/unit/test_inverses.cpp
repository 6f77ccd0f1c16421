// The deadzone and backlash inverses (Tao & Kokotović's characteristic inverses) against lash's
// own Deadzone and Deadband blocks: the composition nonlinearity ∘ inverse is the identity on
// random signals (exactly outside the smoothing band, within it up to the band), per side.
#include <gtest/gtest.h>

#include "ref_backlash.hpp"

#include <cmath>
#include <stdexcept>

#include "lash/blocks.hpp"
#include "lash/signals/rng.hpp"

using namespace lash;

namespace {
constexpr int kSamples = 20000;

// Deadzone with a slope per side: m·Deadzone(v) on the side v is on (lash's Deadzone has slope 1).
double sloped_deadzone(const Deadzone& dz, double mr, double ml, double v) {
  const double out = dz.step(v);
  return out > 0 ? mr * out : ml * out;
}

using test::RefBacklash;  // the asymmetric case's oracle (ref_backlash.hpp)
}  // namespace

TEST(DeadzoneInverse, ThesisHandValues) {
  const auto p = DeadzoneInverseParams::from_deadzone(288.0);
  EXPECT_DOUBLE_EQ(p.offset_right, 0.97 * 288.0);  // 279.36 mA
  DeadzoneInverse dzi(p);
  EXPECT_NEAR(dzi.step(10.0), 289.36, 1e-12);
  EXPECT_NEAR(dzi.step(-10.0), -289.36, 1e-12);
  EXPECT_EQ(dzi.step(0.0), 0.0);
  // Slopes 2 (right) and 0.5 (left): v = c_r + u/m_r, c_l + u/m_l.
  DeadzoneInverse s({300.0, 200.0, 2.0, 0.5, 0.0});
  EXPECT_DOUBLE_EQ(s.step(100.0), 350.0);
  EXPECT_DOUBLE_EQ(s.step(-100.0), -400.0);
  // Smoothing band 40: u = 10 lies on the line from 0 to (40, 300 + 20): v = 10·320/40 = 80.
  DeadzoneInverse sm({300.0, 200.0, 2.0, 0.5, 40.0});
  EXPECT_DOUBLE_EQ(sm.step(10.0), 80.0);
  EXPECT_DOUBLE_EQ(sm.step(-10.0), -10.0 * (200.0 + 80.0) / 40.0);  // −70
  EXPECT_DOUBLE_EQ(sm.step(40.0), 320.0);  // meets the exact branch at u = δ
}

TEST(DeadzoneInverse, RejectsBadParameters) {
  EXPECT_THROW(DeadzoneInverse({-1.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(DeadzoneInverse({1.0, NAN}), std::invalid_argument);
  EXPECT_THROW(DeadzoneInverse({1.0, 1.0, 0.0, 1.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(DeadzoneInverse({1.0, 1.0, 1.0, -1.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(DeadzoneInverse({1.0, 1.0, 1.0, 1.0, -0.1}), std::invalid_argument);
}

// DZ(DI(u)) = u on random u, per side, with asymmetric edges and slopes.
TEST(DeadzoneInverse, CompositionIsIdentityOnRandomSignalsPerSide) {
  Rng rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const double cr = 500 * rng.uniform(), cl = -500 * rng.uniform();
    const double mr = 0.2 + 3 * rng.uniform(), ml = 0.2 + 3 * rng.uniform();
    const Deadzone dz({cl, cr});
    DeadzoneInverse dzi({cr, -cl, mr, ml, 0.0});
    int right = 0, left = 0;
    for (int k = 0; k < kSamples / 20; ++k) {
      const double u = 2000 * (rng.uniform() - 0.5);
      const double v = dzi.step(u);
      (u > 0 ? right : left)++;
      ASSERT_NEAR(sloped_deadzone(dz, mr, ml, v), u, 1e-9 * (1 + std::fabs(u) + cr - cl)) << "u = " << u;
      // The command lies outside the band on u's own side.
      if (u > 0) { ASSERT_GT(v, cr); }
      if (u < 0) { ASSERT_LT(v, cl); }
    }
    EXPECT_GT(right, 0);
    EXPECT_GT(left, 0);
  }
}

// With a smoothing band δ: exact for |u| ≥ δ; inside, DZ(DI(u)) lies between 0 and u; the command
// is continuous (no jump larger than the slope of the band's lines allows).
TEST(DeadzoneInverse, SmoothingBandBoundsTheErrorAndRemovesTheJump) {
  Rng rng(11);
  const double cr = 288, cl = -296, mr = 1.0, ml = 0.9, delta = 30;
  const Deadzone dz({cl, cr});
  DeadzoneInverse dzi({cr, -cl, mr, ml, delta});
  double worst_inside = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double u = 4 * delta * (rng.uniform() - 0.5);
    const double out = sloped_deadzone(dz, mr, ml, dzi.step(u));
    if (std::fabs(u) >= delta) {
      ASSERT_NEAR(out, u, 1e-9 * (1 + std::fabs(u) + cr - cl));
    } else {
      ASSERT_LE(std::fabs(out - u), std::fabs(u) + 1e-12);
      ASSERT_GE(out * u, -1e-12);  // same sign as u (or 0)
      worst_inside = std::max(worst_inside, std::fabs(out - u));
    }
  }
  EXPECT_LT(worst_inside, delta);
  EXPECT_GT(worst_inside, 0.5 * delta);  // the band really costs accuracy near ±δ
  // Continuity at 0: ±1e-9 maps to ±(tiny), no jump across the deadzone.
  EXPECT_LT(std::fabs(dzi.step(1e-9) - dzi.step(-1e-9)), 1e-6);
}

TEST(DeadzoneInverse, ParametersChangeBetweenSteps) {
  DeadzoneInverse dzi(DeadzoneInverseParams::from_deadzone(288.0, 1.0));
  EXPECT_DOUBLE_EQ(dzi.step(12.0), 300.0);
  DeadzoneInverseParams p = dzi.params();
  p.offset_right = 380.0;
  dzi.set_params(p);
  EXPECT_DOUBLE_EQ(dzi.step(12.0), 392.0);
  p.slope_right = -1.0;  // outside its domain: the old slope stays
  dzi.set_params(p);
  EXPECT_DOUBLE_EQ(dzi.params().slope_right, 1.0);
  dzi.set_offsets(NAN, -5.0);
  EXPECT_EQ(dzi.params().offset_right, 0.0);
  EXPECT_EQ(dzi.params().offset_left, 0.0);
}

TEST(BacklashInverse, HandSequenceJumpsAcrossTheGapOnReversal) {
  BacklashInverse bi({2.0, 3.0, 0.0});
  bi.reset(0.0, true);
  // Rising: w = u + 2; falling: w = u − 3; holding: w holds.
  EXPECT_DOUBLE_EQ(bi.step(1.0), 3.0);
  EXPECT_DOUBLE_EQ(bi.step(2.0), 4.0);
  EXPECT_DOUBLE_EQ(bi.step(2.0), 4.0);
  EXPECT_DOUBLE_EQ(bi.step(1.5), -1.5);  // reversal: jump by 2 + 3 = 5
  EXPECT_DOUBLE_EQ(bi.step(1.0), -2.0);
  EXPECT_DOUBLE_EQ(bi.step(1.25), 3.25);
  EXPECT_THROW(BacklashInverse({-1.0, 0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(BacklashInverse({1.0, INFINITY, 0.0}), std::invalid_argument);
  EXPECT_THROW(BacklashInverse({1.0, 1.0, NAN}), std::invalid_argument);
}

// B(BI(u)) = u exactly on random walks, against lash's Deadband (symmetric half-width d,
// each side's value in turn) and against the reference backlash (asymmetric gaps).
TEST(BacklashInverse, CompositionIsIdentityOnRandomSignalsPerSide) {
  Rng rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const double dr = 0.01 * rng.uniform(), dl = 0.01 * rng.uniform();
    // Per side against lash's Deadband: half-width dr, then dl.
    for (double d : {dr, dl}) {
      Deadband db(PerSide<double>::both(d));
      BacklashInverse bi({d, d, 0.0});
      double u = 0;
      db.reset(u);
      bi.reset(u, true);
      db.step(bi.step(u));  // w = u + d: engaged pushing up, output stays 0
      int reversals = 0;
      double du1 = 0;
      for (int k = 0; k < kSamples / 40; ++k) {
        const double du = rng.uniform() < 0.2 ? 0.0 : 0.004 * (rng.uniform() - 0.5);
        if (du * du1 < 0) ++reversals;
        if (du != 0) du1 = du;
        u += du;
        ASSERT_NEAR(db.step(bi.step(u)), u, 1e-12) << "k = " << k;
      }
      EXPECT_GT(reversals, 50);
    }
    // Asymmetric gaps against the reference.
    RefBacklash b{dr, dl, 0.0};
    BacklashInverse bi({dr, dl, 0.0});
    bi.reset(0.0, true);
    double u = 0;
    for (int k = 0; k < kSamples / 40; ++k) {
      u += 0.004 * (rng.uniform() - 0.5);
      ASSERT_NEAR(b.step(bi.step(u)), u, 1e-12);
    }
  }
}

// Smoothing band δ: the command never jumps by more than (1 + (c_r + c_l')/δ)·|Δu| and the output
// error stays within δ.
TEST(BacklashInverse, SmoothingBandBoundsTheErrorAndTheJump) {
  Rng rng(5);
  const double cr = 0.005, cl = 0.007, delta = 0.002;
  RefBacklash b{cr, cl, 0.0};
  BacklashInverse bi({cr, cl, delta});
  bi.reset(0.0, true);
  double u = 0, w1 = bi.offset(), worst = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double du = 0.001 * (rng.uniform() - 0.5);
    u += du;
    const double w = bi.step(u);
    ASSERT_LE(std::fabs(w - w1), (1 + (cr + cl) / delta) * std::fabs(du) + 1e-15);
    w1 = w;
    const double err = std::fabs(b.step(w) - u);
    ASSERT_LE(err, delta + 1e-12);
    worst = std::max(worst, err);
  }
  EXPECT_GT(worst, 0.2 * delta);
}

TEST(BacklashInverse, WidthsChangeBetweenStepsKeepingTheEngagedSide) {
  BacklashInverse bi({0.005, 0.005, 0.0});
  bi.reset(0.0, true);
  EXPECT_DOUBLE_EQ(bi.step(0.001), 0.006);
  bi.set_params({0.008, 0.008, 0.0});
  EXPECT_DOUBLE_EQ(bi.offset(), 0.008);
  EXPECT_DOUBLE_EQ(bi.step(0.001), 0.009);  // holding: same side, new width
  EXPECT_DOUBLE_EQ(bi.step(0.0), -0.008);
  bi.set_params({-1.0, NAN, 0.0});  // outside the domain: kept
  EXPECT_DOUBLE_EQ(bi.params().right, 0.008);
  EXPECT_DOUBLE_EQ(bi.params().left, 0.008);
}
