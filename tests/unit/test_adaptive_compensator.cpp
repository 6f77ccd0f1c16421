// The adaptive compensator template (lash/control/adaptive_compensator.hpp): the command path
// shared by both aliases, and the carts' adapter (lash's deadzone-deadband estimator on the drive
// and driven positions) against a reference backlash written here with known, unequal gaps.
#include <gtest/gtest.h>

#include "ref_backlash.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>
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
    dz_fixed.observe(u, 0.5 * u, true);  // not adaptive: the estimator is not stepped
    bl_fixed.observe(p, p, true);
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
    comp.observe(w, b.step(w), true);
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
    comp.observe(w, b.step(w), true);
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

// ---------------------------------------------------------------- stale samples (observe, fresh = false)
namespace {
std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }
// The estimator's state that a stale sample must leave alone, bit for bit: per side the verdict's
// parameters, the RLS estimate, covariance and update count.
template <class E>
std::vector<std::uint64_t> estimator_state(const E& e) {
  std::vector<std::uint64_t> v;
  for (Side s : {Side::right, Side::left}) {
    const SideParams p = e.params(s);
    for (double x : {p.a1, p.b1, p.c, p.d}) v.push_back(bits(x));
    v.push_back(p.identified);
    v.push_back(static_cast<std::uint64_t>(p.reason));
    v.push_back(e.updates(s));
  }
  auto rls = [&v](const auto& r) {
    for (double x : r.eta()) v.push_back(bits(x));
    for (const auto& row : r.P())
      for (double x : row) v.push_back(bits(x));
    v.push_back(r.updates());
  };
  if constexpr (std::is_same_v<E, DeadzoneDeadbandEstimator>) {
    for (int k = 0; k < 4; ++k) rls(e.rls(static_cast<DeadzoneDeadbandEstimator::Key>(k)));
    for (Side s : {Side::right, Side::left}) rls(e.pooled_rls(s));
  } else {
    for (Side s : {Side::right, Side::left}) rls(e.rls(s));
  }
  return v;
}
std::vector<std::uint64_t> inverse_state(const DeadzoneCompensator& c) {
  const DeadzoneInverseParams p = c.inverse().params();
  return {bits(p.offset_right), bits(p.offset_left), bits(c.gate(Side::right).value()),
          bits(c.gate(Side::left).value()), c.updates()};
}
bool stale_step(int k) { return k % 97 == 41 || k % 1013 == 500 || k % 1013 == 501; }  // singles and pairs
}  // namespace

// A valve-like loop (first-order pressure, deadzone 288 → 380 mA at 30 s, uniform sensor noise)
// with the master's rule on a late sensor frame: the command is held and the compensator told
// the sample is stale. Each stale step leaves the estimator's estimates and the inverse bit-
// unchanged; the estimator inside equals a bare InputDeadzoneEstimator driven by hand with the
// same samples, restart() at each stale step instead of the sample (docs/compensation.md); and
// treating those samples as fresh gives a different estimate (the test can fail).
TEST(DeadzoneCompensator, StaleSamplesNeitherUpdateTheEstimatorNorMoveTheInverse) {
  DeadzoneCompensationConfig cfg = valve(CompensationMode::adaptive);
  cfg.estimator.dt_s = 0.005;
  cfg.estimator.method = EstimationMethod::iv;
  cfg.estimator.rls.lambda = 0.995;
  DeadzoneCompensator comp(cfg), all_fresh(cfg);
  InputDeadzoneEstimator by_hand(cfg.estimator);
  Rng rng(3);
  double x = 0.0, y = 0.0, i = 0.0, integ = 0.0;
  int stale = 0;
  for (int k = 0; k < 12000; ++k) {
    const double edge = k < 6000 ? 288.0 : 380.0;
    const double r = 600.0 * std::sin(2.0 * std::numbers::pi * k * 0.005 / 4.0);
    const bool fresh = !stale_step(k);
    if (fresh) y = x + 20.0 * (rng.uniform() - 0.5);  // a stale step keeps the last value received
    if (fresh) {  // PI + feedforward, then the compensator, as the master's scenario law
      integ += 10.0 * 0.005 * (r - y);
      i = std::clamp(comp.command(0.5 * (r - y) + integ + 0.465 * r), -2000.0, 2000.0);
    }  // else: the command of the last step is held and y is the last value received
    const auto est_before = estimator_state(comp.estimator());
    const auto inv_before = inverse_state(comp);
    comp.observe(i, y, fresh);
    all_fresh.observe(i, y, true);
    if (fresh) {
      by_hand.step(i, y);
    } else {
      by_hand.restart();
      ++stale;
      ASSERT_EQ(estimator_state(comp.estimator()), est_before) << "stale step " << k;
      ASSERT_EQ(inverse_state(comp), inv_before) << "stale step " << k;
    }
    ASSERT_EQ(estimator_state(comp.estimator()), estimator_state(by_hand)) << "step " << k;
    const double dz = i > edge ? i - edge : (i < -296.0 ? i + 296.0 : 0.0);
    x = 0.93 * x + 0.07 * 2.15 * dz;
  }
  EXPECT_EQ(comp.stale_samples(), static_cast<std::uint64_t>(stale));
  EXPECT_GT(stale, 100);
  // The loop adapted: the right edge moved from 288 towards the drifted 380 mA.
  EXPECT_GT(comp.updates(), 0u);
  EXPECT_GT(comp.inverse().params().offset_right, 340.0) << comp.estimator_reason(Side::right);
  EXPECT_NE(estimator_state(comp.estimator()), estimator_state(all_fresh.estimator()));
}

// Drift events (DriftDetectSettings): the valve loop of the test above, every sample fresh, sensor
// noise ±1 kPa, a first-order plant y(k) = 0.93 y(k−1) + 0.1505 DZ(i(k−1)) whose right edge steps
// 288 → 380 mA at 30 s. No event before the step; the right edge's first event comes within 3 s,
// with old and new the plant's two edges (the probe's mean before and after the change time).
TEST(DeadzoneCompensator, DriftEventGivesTheEdgesBeforeAndAfterAStep) {
  DeadzoneCompensationConfig cfg = valve(CompensationMode::adaptive);
  cfg.estimator.dt_s = 0.005;
  cfg.estimator.method = EstimationMethod::iv;
  cfg.estimator.rls.lambda = 0.995;
  DeadzoneCompensator comp(cfg);
  Rng rng(5);
  double x = 0.0, y = 0.0, i = 0.0, integ = 0.0;
  for (int k = 0; k < 12000; ++k) {
    const double edge = k < 6000 ? 288.0 : 380.0;
    const double r = 600.0 * std::sin(2.0 * std::numbers::pi * k * 0.005 / 4.0);
    y = x + 2.0 * (rng.uniform() - 0.5);
    integ += 10.0 * 0.005 * (r - y);
    i = std::clamp(comp.command(0.5 * (r - y) + integ + 0.465 * r), -2000.0, 2000.0);
    comp.observe(i, y, true);
    const double dz = i > edge ? i - edge : (i < -296.0 ? i + 296.0 : 0.0);
    x = 0.93 * x + 0.07 * 2.15 * dz;
  }
  const AdaptationEvents& ev = comp.events();
  const AdaptationEvent* first = nullptr;
  for (std::uint32_t n = 0; n < ev.n; ++n) {
    const AdaptationEvent& e = ev.events[n];
    if (e.kind != AdaptationEvent::Kind::drift) continue;
    EXPECT_GE(e.sample, 6000u) << "false alarm on side " << (e.side == Side::right ? "right" : "left");
    if (!first && e.side == Side::right) first = &e;
  }
  ASSERT_NE(first, nullptr);
  EXPECT_LE(first->sample, 6000u + 600u);
  EXPECT_NEAR(first->old_value, 288.0, 2.0);
  EXPECT_NEAR(first->new_value, 380.0, 2.0);
  EXPECT_EQ(comp.drifts(Side::left), 0u);
}

// The carts' probe is the gap of the face in contact: a reference backlash whose up gap grows
// 4 → 7 mm at 20 s gives one event on the right (up) gap, 4 → 7 mm, none on the down gap.
TEST(BacklashCompensator, DriftEventGivesTheGapsBeforeAndAfterAStep) {
  BacklashCompensator comp(carts(CompensationMode::adaptive));
  RefBacklash b{0.004, 0.0065, -0.0065};
  for (int k = 0; k < 40000; ++k) {
    if (k == 20000) b.cr = 0.007;
    const double w = 0.05 * std::sin(2.0 * std::numbers::pi * k * kDt / 4.0);
    comp.observe(w, b.step(w), true);
  }
  ASSERT_GE(comp.events().n, 1u);
  EXPECT_EQ(comp.drifts(Side::right), 1u);
  EXPECT_EQ(comp.drifts(Side::left), 0u);
  const AdaptationEvent& e = comp.events().events[0];
  EXPECT_EQ(e.kind, AdaptationEvent::Kind::drift);
  EXPECT_GE(e.sample, 20000u);
  EXPECT_LE(e.sample, 23000u);
  EXPECT_NEAR(e.old_value, 0.004, 1e-6);
  EXPECT_NEAR(e.new_value, 0.007, 1e-6);
}

// The carts' adapter regresses the driven position one sample late: after a stale sample the
// next one only refills that delay (the estimator is stepped from the sample after it on).
TEST(BacklashCompensator, StaleSamplesRestartTheEstimatorAndHoldTheInverse) {
  BacklashCompensator comp(carts(CompensationMode::adaptive));
  const auto cfg = carts(CompensationMode::adaptive).estimator;
  DeadzoneDeadbandEstimator by_hand(cfg);
  RefBacklash b{0.004, 0.0065, -0.0065};
  double y1 = 0.0;
  bool refill = false;
  for (int k = 0; k < 30000; ++k) {
    const double w = 0.05 * std::sin(2.0 * std::numbers::pi * k * kDt / 4.0);
    const double y = b.step(w);
    const bool fresh = !stale_step(k);
    const auto before = estimator_state(comp.estimator());
    const BacklashInverseParams inv = comp.inverse().params();
    comp.observe(w, y, fresh);
    if (!fresh) {
      by_hand.restart();
      refill = true;
      ASSERT_EQ(estimator_state(comp.estimator()), before) << k;
      ASSERT_EQ(bits(comp.inverse().params().right), bits(inv.right)) << k;
      ASSERT_EQ(bits(comp.inverse().params().left), bits(inv.left)) << k;
      continue;
    }
    if (!refill) by_hand.step(w >= 0.0 ? w + cfg.input_shift : w - cfg.input_shift, y1);
    refill = false;
    y1 = y;
    ASSERT_EQ(estimator_state(comp.estimator()), estimator_state(by_hand)) << "step " << k;
  }
  EXPECT_NEAR(comp.inverse().params().right, 0.004, 1e-4);
  EXPECT_NEAR(comp.inverse().params().left, 0.0065, 1e-4);
}

// Calibration setters (docs/xcp.md): between samples, noexcept; numbers by hand from the
// inverse's definition (slopes 1, no smoothing: v = u + c_r for u > 0, v = u − |c_l| for u < 0).
TEST(CompensatorCalibration, ModeSwitchNominalEdgesAndDither) {
  DeadzoneCompensator c(valve(CompensationMode::fixed));
  EXPECT_EQ(c.command(100.0), 388.0);  // 100 + 288
  EXPECT_EQ(c.command(-100.0), -396.0);  // −100 − 296
  ASSERT_TRUE(c.set_mode(CompensationMode::none));
  EXPECT_EQ(c.command(100.0), 100.0);
  EXPECT_EQ(c.in_use().right, 0.0);
  ASSERT_TRUE(c.set_nominal(300.0, 310.0));  // in none: kept for fixed/adaptive
  ASSERT_TRUE(c.set_mode(CompensationMode::fixed));
  EXPECT_EQ(c.command(100.0), 400.0);
  EXPECT_EQ(c.command(-100.0), -410.0);
  EXPECT_EQ(c.in_use().left, -310.0);
  // refused: nothing changes
  EXPECT_FALSE(c.set_nominal(-1.0, 310.0));
  EXPECT_FALSE(c.set_nominal(300.0, std::nan("")));
  EXPECT_FALSE(c.set_mode(static_cast<CompensationMode>(4)));  // 3 is oracle
  EXPECT_FALSE(c.set_oracle(250.0, 260.0));  // only in oracle mode
  EXPECT_EQ(c.command(100.0), 400.0);
  EXPECT_EQ(c.config().mode, CompensationMode::fixed);
  // adaptive with a dither of 5 mA, period 4 samples: +5, +5, −5, −5, +5 on u before the inverse
  AdaptationSettings a = c.config().adaptation;
  a.dither_amplitude = 5.0;
  a.dither_period_s = 4.0 * c.config().estimator.dt_s;
  ASSERT_TRUE(c.set_adaptation(a));
  ASSERT_TRUE(c.set_mode(CompensationMode::adaptive));
  const double want[] = {405.0, 405.0, 395.0, 395.0, 405.0};
  for (double w : want) EXPECT_EQ(c.command(100.0), w);
  // a mode change restarts the dither at +A
  ASSERT_TRUE(c.set_mode(CompensationMode::fixed));
  ASSERT_TRUE(c.set_mode(CompensationMode::adaptive));
  EXPECT_EQ(c.command(100.0), 405.0);
  a.rate_limit_per_s = 0.0;  // invalid (ρ > 0)
  EXPECT_FALSE(c.set_adaptation(a));
  EXPECT_EQ(c.config().adaptation.dither_amplitude, 5.0);
}

// The gate: nominal 300, T = 0.01 s, ρ = 100/s (1 per sample), dead band 0.08 × 300 = 24,
// settle 0: an estimate of 350 (gap 50 > 24) is followed at 1 per sample; after retune(ρ = 500)
// at 5 per sample from where it is; restart(200) puts it at 200, never adapted.
TEST(CompensatorCalibration, GateRetuneKeepsItsValueAndRestartDropsIt) {
  AdaptationSettings s;
  s.settle_s = 0.0;
  ParameterGate g(300.0, 0.01, s);
  EXPECT_EQ(g.step(true, 350.0), 301.0);
  EXPECT_EQ(g.step(true, 350.0), 302.0);
  s.rate_limit_per_s = 500.0;
  g.retune(s, 0.01);
  EXPECT_EQ(g.step(true, 350.0), 307.0);
  EXPECT_EQ(g.nominal(), 300.0);
  g.restart(200.0, s, 0.01);
  EXPECT_EQ(g.value(), 200.0);
  EXPECT_EQ(g.reason(), AdaptationReason::nominal);
  // 350 lies inside [0.25, 4] × 200 = [50, 800], gap 150 > dead band 0.08 × 200 = 16: +5 per sample
  EXPECT_EQ(g.step(true, 350.0), 205.0);
}

// An adapted inverse switched to fixed is the nominal inverse again, and back to adaptive it
// starts from the nominal values (the carts' gaps, adapted to 4 / 6.5 mm from nominal 5 mm).
TEST(CompensatorCalibration, AdaptedValuesDroppedOnAModeSwitch) {
  BacklashCompensator comp(carts(CompensationMode::adaptive));
  RefBacklash b{0.004, 0.0065, -0.0065};
  for (int k = 0; k < 30000; ++k) {
    const double w = 0.05 * std::sin(2.0 * std::numbers::pi * k * kDt / 4.0);
    comp.observe(w, b.step(w), true);
  }
  ASSERT_NEAR(comp.inverse().params().right, 0.004, 1e-4);
  ASSERT_TRUE(comp.set_mode(CompensationMode::fixed));
  EXPECT_EQ(comp.inverse().params().right, 0.005);
  EXPECT_EQ(comp.inverse().params().left, 0.005);
  ASSERT_TRUE(comp.set_mode(CompensationMode::adaptive));
  EXPECT_EQ(comp.gate(Side::right).value(), 0.005);
  EXPECT_EQ(comp.reason(), AdaptationReason::nominal);
}

// Switched to adaptive before its first sample, a compensator equals one built adaptive (the
// estimator is not restarted: nothing to clear), sample for sample; so does one switched
// adaptive -> fixed -> adaptive with no sample between (the master's replay applies such pages
// as the last one alone).
TEST(CompensatorCalibration, SwitchesBeforeTheFirstSampleEqualTheLastAlone) {
  // The valve: v beyond the right guess (432 mA) from the first sample, y = v − 288 (+ a first-order
  // lag), so the estimator updates from its first samples (a restart's warm-up would show).
  DeadzoneCompensator built(valve(CompensationMode::adaptive)), switched(valve(CompensationMode::fixed)),
      twice(valve(CompensationMode::adaptive));
  ASSERT_TRUE(switched.set_mode(CompensationMode::adaptive));
  ASSERT_TRUE(twice.set_mode(CompensationMode::fixed));
  ASSERT_TRUE(twice.set_mode(CompensationMode::adaptive));
  double y = 0.0;
  for (int k = 0; k < 400; ++k) {
    const double v = 700.0 + 200.0 * std::sin(0.05 * k);
    y = 0.9 * y + 0.1 * (v - 288.0);
    built.observe(v, y, true);
    switched.observe(v, y, true);
    twice.observe(v, y, true);
    const double c = built.estimator().params(Side::right).c;
    ASSERT_EQ(std::bit_cast<std::uint64_t>(switched.estimator().params(Side::right).c), std::bit_cast<std::uint64_t>(c)) << k;
    ASSERT_EQ(std::bit_cast<std::uint64_t>(twice.estimator().params(Side::right).c), std::bit_cast<std::uint64_t>(c)) << k;
  }
  EXPECT_TRUE(std::isfinite(built.estimator().params(Side::right).c));  // it did update
}
