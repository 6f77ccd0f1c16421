// 95 % intervals by batch means (identify/intervals.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "lash/experiments/scenario.hpp"
#include "lash/identify/any_estimator.hpp"
#include "lash/identify/intervals.hpp"
#include "lash/metrics/first_order.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"

namespace lash {
namespace {

TEST(Intervals, StudentQuantilesMatchScipy) {
  // scipy.stats.t.ppf(0.975, n)
  EXPECT_NEAR(student_t975(1), 12.70620474, 1e-7);
  EXPECT_NEAR(student_t975(9), 2.26215716, 1e-7);
  EXPECT_NEAR(student_t975(30), 2.04227246, 1e-7);
  EXPECT_NEAR(student_t975(40), 2.0210753829953374, 1e-6);
  EXPECT_NEAR(student_t975(100), 1.9839715184496334, 1e-7);
}

// Issue 12 must-show: over 20 seeds of E2 (noise variance 200, 200 s), the 95 % intervals of
// a1, b1, c, d, K and tau per side contain the truth for >= 85 % of (parameter, seed) pairs, and
// none is wider than ±25 % of its parameter. Settings: config/scenarios/e2.toml (pooled IV, MA40
// on v and y, λ 1, direction hold 41).
TEST(Intervals, E2CoverageOverTwentySeeds) {
  const ScenarioSpec s = load_scenario(std::string(LASH_SOURCE_DIR) + "/config/scenarios/e2.toml");
  Plant plant = load_plant(s.plant_file);
  std::size_t pairs = 0, covered = 0, too_wide = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    SimulationSpec spec;
    spec.input = s.input;
    spec.duration_s = s.duration_s;
    spec.noise_variance = s.noise_variance;
    spec.seed = seed;
    plant.reset();
    const SimulationTrace tr = simulate(plant, spec);
    const EstimationRun run = run_estimator(s.estimator, tr.col("v"), tr.col("y"));
    const PerSide<SideParams> est{run.report.right.params, run.report.left.params};
    const auto ci = batch_means_intervals(s.estimator, tr.col("v"), tr.col("y"), est);
    for (Side side : {Side::right, Side::left}) {
      ASSERT_TRUE(est[side].identified) << "seed " << seed << " " << to_string(side) << ": "
                                        << to_string(est[side].reason);
      const SideParams& t = s.truth[side];
      const SideIntervals& c = ci[side];
      const double K = static_gain(t.a1, t.b1), tau = time_constant_s(t.a1, s.estimator.dt_s);
      const std::pair<const Interval*, double> items[] = {{&c.a1, t.a1}, {&c.b1, t.b1}, {&c.c, t.c},
                                                          {&c.d, t.d},   {&c.K, K},      {&c.tau_s, tau}};
      for (const auto& [iv, truth] : items) {
        ++pairs;
        ASSERT_TRUE(iv->valid()) << "seed " << seed << " " << to_string(side);
        if (iv->lo <= truth && truth <= iv->hi) ++covered;
        const double half = 0.5 * (iv->hi - iv->lo);
        if (half > 0.25 * std::fabs(truth)) ++too_wide;
      }
    }
  }
  std::printf("E2, 20 seeds: %zu of %zu (parameter, seed) pairs covered (%.1f %%), %zu wider than +-25 %%\n", covered,
              pairs, 100.0 * static_cast<double>(covered) / static_cast<double>(pairs), too_wide);
  EXPECT_GE(static_cast<double>(covered), 0.85 * static_cast<double>(pairs));
  EXPECT_EQ(too_wide, 0u);
}

}  // namespace
}  // namespace lash

// Verdict check 7 (intervals.hpp): the hand-made intervals below reach an impossible value
// exactly where the comment says.
TEST(Intervals, VerdictUncertainWhereAnIntervalReachesTheImpossible) {
  using lash::Interval;
  using lash::Reason;
  using lash::Side;
  lash::SideIntervals ok;
  ok.a1 = {-1.2, -0.5};  // reaches below -1: an integrator's limit, not tested
  ok.b1 = {-0.1, 0.3};   // b1 alone spans zero: not tested (K is the physical quantity)
  ok.c = {150.0, 250.0};
  ok.d = {0.0, 40.0};
  ok.K = {0.5, 3.0};
  ok.tau_s = {0.01, 0.2};
  EXPECT_EQ(lash::interval_verdict(ok, Side::right), Reason::none);
  EXPECT_EQ(lash::interval_verdict(lash::SideIntervals{}, Side::right), Reason::none);  // no intervals
  auto with = [&](auto edit) {
    lash::SideIntervals c = ok;
    edit(c);
    return lash::interval_verdict(c, Side::right);
  };
  EXPECT_EQ(with([](auto& c) { c.a1 = {-0.5, 0.0}; }), Reason::uncertain);     // a1 = 0: no lag
  EXPECT_EQ(with([](auto& c) { c.K = {-0.26, 1.06}; }), Reason::uncertain);    // K <= 0
  EXPECT_EQ(with([](auto& c) { c.tau_s = {-0.001, 0.1}; }), Reason::uncertain);  // tau <= 0
  EXPECT_EQ(with([](auto& c) { c.d = {-0.5, 3.0}; }), Reason::uncertain);      // d < 0
  EXPECT_EQ(with([](auto& c) { c.c = {-5.0, 10.0}; }), Reason::uncertain);     // c_r < 0
  lash::SideIntervals left = ok;
  left.c = {-250.0, -150.0};
  EXPECT_EQ(lash::interval_verdict(left, Side::left), Reason::none);
  left.c = {-10.0, 5.0};  // c_l > 0
  EXPECT_EQ(lash::interval_verdict(left, Side::left), Reason::uncertain);
}

// attach_intervals: an uncertain side keeps its values and intervals, is not identified, and
// neither is the model; a side not identified gets no intervals.
TEST(Intervals, AttachMarksTheUncertainSide) {
  lash::EstimateReport rep;
  rep.model = lash::ModelKind::input_deadzone;
  rep.identified = true;
  for (lash::SideReport* s : {&rep.right, &rep.left}) {
    s->params.identified = true;
    s->params.reason = lash::Reason::none;
    s->params.c = s == &rep.right ? 203.0 : -174.0;
  }
  lash::PerSide<lash::SideIntervals> ci{};
  ci.right.K = {1.36, 2.97};
  ci.left.K = {-0.26, 1.06};
  lash::attach_intervals(rep, ci);
  EXPECT_TRUE(rep.right.params.identified);
  EXPECT_EQ(rep.right.ci95.K.lo, 1.36);
  EXPECT_FALSE(rep.left.params.identified);
  EXPECT_EQ(rep.left.params.reason, lash::Reason::uncertain);
  EXPECT_EQ(rep.left.params.c, -174.0);
  EXPECT_EQ(rep.left.ci95.K.lo, -0.26);
  EXPECT_FALSE(rep.identified);
  lash::EstimateReport lin;  // linear: only the right side counts
  lin.model = lash::ModelKind::linear;
  lin.identified = true;
  lin.right.params.identified = true;
  lin.right.params.reason = lash::Reason::none;
  lash::attach_intervals(lin, ci);  // right: K positive; left not identified: untouched
  EXPECT_TRUE(lin.identified);
  EXPECT_FALSE(lin.left.ci95.K.valid());
}

// Verdict check 8 (precision_verdict, `ci_tolerance`): by hand, (hi - lo) / |hi + lo| against
// the tolerance for K, tau, c and d; a1 and b1 are not judged; a missing interval fails.
TEST(Intervals, PrecisionVerdictJudgesTheHalfWidthAgainstTheTolerance) {
  using lash::Reason;
  lash::SideIntervals ci;
  ci.a1 = {-1.5, 0.5};      // not judged (K and tau are)
  ci.b1 = {-0.1, 0.3};      // not judged
  ci.K = {1.9, 2.1};        // half-width 0.1 of centre 2: 5 %
  ci.tau_s = {0.098, 0.102};  // 2 %
  ci.c = {190.0, 210.0};    // 5 %
  ci.d = {29.7, 30.3};      // 1 %
  const auto v = [&](double tol, bool has_c = true, bool has_d = true) {
    return lash::precision_verdict(ci, tol, has_c, has_d);
  };
  EXPECT_EQ(v(0.0), Reason::none);    // off
  EXPECT_EQ(v(-1.0), Reason::none);   // off
  EXPECT_EQ(v(0.051), Reason::none);  // K and c at 5 % pass 5.1 %
  EXPECT_EQ(v(0.049), Reason::uncertain);
  ci.K = {1.95, 2.05};                // 2.5 %: now c (5 %) decides
  EXPECT_EQ(v(0.049), Reason::uncertain);
  EXPECT_EQ(v(0.049, false), Reason::none);  // a model without c: c not judged
  EXPECT_EQ(v(0.021, false), Reason::uncertain);  // K 2.5 % > 2.1 %
  ci.d = {};                          // no d interval
  EXPECT_EQ(v(0.03, false, false), Reason::none);
  EXPECT_EQ(v(0.03, false, true), Reason::uncertain);  // the model has d: missing fails
  ci.tau_s = {-0.05, 0.05};           // centre 0: never within a tolerance
  EXPECT_EQ(v(100.0, false, false), Reason::uncertain);
  EXPECT_EQ(lash::precision_verdict(lash::SideIntervals{}, 0.5, false, false), Reason::uncertain);
}

// attach_intervals with a tolerance: no intervals at all (too few sections) is `uncertain`;
// without a tolerance it changes nothing.
TEST(Intervals, AttachWithAToleranceNeedsIntervals) {
  const auto report = [] {
    lash::EstimateReport rep;
    rep.model = lash::ModelKind::input_deadzone;
    rep.has_c = true;
    rep.identified = true;
    for (lash::SideReport* s : {&rep.right, &rep.left}) {
      s->params.identified = true;
      s->params.reason = lash::Reason::none;
    }
    return rep;
  };
  lash::PerSide<lash::SideIntervals> none{};
  lash::EstimateReport a = report();
  lash::attach_intervals(a, none);
  EXPECT_TRUE(a.identified);
  lash::attach_intervals(a, none, 0.05);
  EXPECT_FALSE(a.identified);
  EXPECT_EQ(a.right.params.reason, lash::Reason::uncertain);
  EXPECT_EQ(a.left.params.reason, lash::Reason::uncertain);
  lash::PerSide<lash::SideIntervals> ci{};
  ci.right.K = {1.9, 2.1};
  ci.right.tau_s = {0.099, 0.101};
  ci.right.c = {195.0, 205.0};
  ci.left = ci.right;
  ci.left.c = {-230.0, -170.0};  // 15 %
  lash::EstimateReport b = report();
  lash::attach_intervals(b, ci, 0.1);
  EXPECT_TRUE(b.right.params.identified);
  EXPECT_FALSE(b.left.params.identified);
  EXPECT_EQ(b.left.params.reason, lash::Reason::uncertain);
  EXPECT_EQ(b.left.ci95.c.lo, -230.0);  // kept, to show why
  EXPECT_FALSE(b.identified);
}

// widest_interval by hand: the judged interval widest against its centre.
TEST(Intervals, WidestIntervalByHand) {
  lash::SideIntervals ci;
  ci.K = {1.8, 2.2};     // 10 %
  ci.tau_s = {0.09, 0.11};  // 10 % (not wider: K, first, stays)
  ci.c = {-210.0, -190.0};  // 5 %
  ci.d = {9.0, 11.0};    // 10 %
  auto w = lash::widest_interval(ci, true, true);
  EXPECT_STREQ(w.name, "K");
  EXPECT_NEAR(w.relative, 0.1, 1e-12);
  ci.c = {-260.0, -140.0};  // 30 %
  w = lash::widest_interval(ci, true, true);
  EXPECT_STREQ(w.name, "c");
  EXPECT_NEAR(w.relative, 0.3, 1e-12);
  w = lash::widest_interval(ci, false, true);  // no c in the model
  EXPECT_STREQ(w.name, "K");
  ci.tau_s = {};
  w = lash::widest_interval(ci, true, true);
  EXPECT_STREQ(w.name, "tau_s");
  EXPECT_TRUE(std::isinf(w.relative));
}
