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
