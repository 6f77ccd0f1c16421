// lash sweep library: scheduling does not change results, seeds differ per repeat, the NRMSE
// window and the summary's counting are what docs/sweep.md says.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "lash/experiments/campaign.hpp"
#include "lash/experiments/sweep.hpp"

using namespace lash::sweep;

namespace {
Campaign small_e3() {
  Campaign c = load_campaign(std::string(LASH_SOURCE_DIR) + "/config/campaigns/e3_motor_cart_lash.toml");
  c.duration_s = 6.0;
  c.window_start_s = 1.5;
  c.window_end_s = 6.0;
  c.runs.resize(12);  // first 12 runs: sine 2 V at 2,4,6,8 rad/s × 3 repeats
  return c;
}
}  // namespace

TEST(Sweep, CampaignMatrixMatchesTheThesis) {
  const std::string dir = std::string(LASH_SOURCE_DIR) + "/config/campaigns/";
  EXPECT_EQ(load_campaign(dir + "e3_motor_cart.toml").runs.size(), 3u * 4 * 4 * 3 + 3);  // 147
  EXPECT_EQ(load_campaign(dir + "e4_pilot_valve.toml").runs.size(), 3u * 4 * 4 * 3 + 20);  // 164
  EXPECT_EQ(load_campaign(dir + "e5_coupled_carts.toml").runs.size(), 3u * 3 * 4 * 3);    // 108
  const Campaign e3 = load_campaign(dir + "e3_motor_cart.toml");
  EXPECT_DOUBLE_EQ(e3.estimator.rls.lambda, 0.99);  // thesis settings by default
  EXPECT_DOUBLE_EQ(e3.estimator.rls.p0, 1000.0);
  // Repeats of one cell have different seeds.
  EXPECT_NE(e3.runs[0].seed, e3.runs[1].seed);
  EXPECT_EQ(e3.runs[0].repeat, 1);
  EXPECT_EQ(e3.runs[2].repeat, 3);
}

TEST(Sweep, ResultsDoNotDependOnThreadCount) {
  const Campaign c = small_e3();
  const auto one = run_campaign(c, 1);
  const auto two = run_campaign(c, 2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].spec.index, i);
    EXPECT_EQ(one[i].nrmse, two[i].nrmse) << i;  // bit-identical
    EXPECT_EQ(one[i].side.right.c, two[i].side.right.c) << i;
  }
  // Different seeds → different noise → different (but close) scores.
  EXPECT_NE(one[0].nrmse, one[1].nrmse);
}

TEST(Sweep, SummaryCountsAndMedian) {
  const Campaign c = small_e3();
  auto r = run_campaign(c, 2);
  r[0].nrmse = 0.5;   // force one bad run
  r[1].nrmse = lash::sweep::kNaN;  // a NaN run counts as bad and as worst
  const Summary s = summarize(c, r);
  std::size_t good = 0;
  for (const auto& x : r) good += x.nrmse < 0.10 ? 1 : 0;
  EXPECT_EQ(s.good, good);
  EXPECT_EQ(s.runs, 12u);
  EXPECT_EQ(s.worst_index, 1u);
  EXPECT_DOUBLE_EQ(s.share_good, static_cast<double>(good) / 12.0);
  ASSERT_EQ(s.per_waveform.size(), 1u);
  EXPECT_EQ(s.per_waveform[0].waveform, "sine");
  EXPECT_EQ(s.unphysical_reported, 0u);
}
