// Model switching (docs/method.md §A4.4): with the true plant as its switching model, every
// sample it selects obeys the pooled regression exactly on noise-free data, so one run returns
// the plant's (a1, b1, c, d) on both sides — here from a random-phase multisine, the input the
// ẏ switching cannot use (issue 30). A mathematical identity, checked to 1e-6 relative.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "lash/blocks/deadband.hpp"
#include "lash/blocks/deadzone.hpp"
#include "lash/blocks/first_order.hpp"
#include "lash/identify/estimators.hpp"
#include "lash/identify/any_estimator.hpp"

namespace lash {
namespace {

struct Plant {
  double a1 = -0.97, b1 = 0.05, cl = -150.0, cr = 220.0, dl = 20.0, dr = 35.0;
};

// v: a 25-line random-phase multisine (0.05-1.5 Hz) scaled to +-500; y: DZ -> G -> DB (lash's blocks)
void record(const Plant& p, std::vector<double>& v, std::vector<double>& y) {
  constexpr double dt = 0.005;
  constexpr int n = 30000;
  std::mt19937_64 rng(30);
  std::uniform_real_distribution<double> ph(0.0, 2.0 * M_PI);
  std::vector<double> phase(25);
  for (double& x : phase) x = ph(rng);
  v.assign(n, 0.0);
  double peak = 0.0;
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < 25; ++i) v[k] += std::sin(2.0 * M_PI * (0.05 + i * 1.45 / 24.0) * k * dt + phase[i]);
    peak = std::max(peak, std::fabs(v[k]));
  }
  for (double& x : v) x *= 500.0 / peak;
  Deadzone dz({p.cl, p.cr});
  FirstOrder g(PerSide<FirstOrderParams>::both({p.a1, p.b1}));
  Deadband db({p.dr, p.dl});
  y.assign(n, 0.0);
  for (int k = 0; k < n; ++k) {
    const double w = g.step(dz.step(v[k]));  // w(k) from u(k−1) (FirstOrder holds u one sample)
    y[k] = db.step(w, side_of(k > 0 ? v[k - 1] : 0.0));
  }
}

TEST(ModelSwitching, TheTruePlantAsSwitchingModelGivesThePlantExactly) {
  const Plant p;
  std::vector<double> v, y;
  record(p, v, y);
  EstimatorConfig cfg(ModelKind::deadzone_deadband, 0.005);
  cfg.model_switching = true;
  cfg.method = EstimationMethod::iv;
  cfg.noise = NoiseSettings{};
  cfg.rls.p0 = 1e9;  // a prior too weak to show at 1e-6 (P0 = 1000 pulls b1 by 3e-5)
  cfg.switch_model.right = {p.a1, p.b1, p.cr, p.dr};
  cfg.switch_model.left = {p.a1, p.b1, p.cl, p.dl};
  DeadzoneDeadbandEstimator est(cfg);
  for (std::size_t k = 0; k < v.size(); ++k) est.step(v[k], y[k]);
  for (const Side s : {Side::right, Side::left}) {
    const SideParams q = est.params(s);
    ASSERT_TRUE(q.identified) << (s == Side::right ? "right" : "left");
    EXPECT_NEAR(q.a1, p.a1, 1e-6 * std::fabs(p.a1));
    EXPECT_NEAR(q.b1, p.b1, 1e-6 * p.b1);
    EXPECT_NEAR(q.c, s == Side::right ? p.cr : p.cl, 1e-6 * 220.0);
    EXPECT_NEAR(q.d, s == Side::right ? p.dr : p.dl, 1e-6 * 35.0);
    // both directions, and samples beyond the edge, were used on each side
    EXPECT_GE(est.updates(s, true), cfg.min_updates);
    EXPECT_GE(est.updates(s, false), cfg.min_updates);
  }
}

TEST(ModelSwitching, WithoutAUsableSwitchingModelTheEstimatorIsRefused) {
  // an estimator that could never update must not pass for one that has not updated yet
  EstimatorConfig cfg(ModelKind::deadzone_deadband, 0.005);
  cfg.model_switching = true;
  cfg.noise = NoiseSettings{};
  cfg.switch_model.right = {-0.97, 0.05, 220.0, 35.0};  // left unset (NaN)
  try {
    DeadzoneDeadbandEstimator est(cfg);
    FAIL() << "constructed";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("model-switching"), std::string::npos) << e.what();
  }
  cfg.switch_model.left = {-0.97, 0.05, -150.0, -1.0};  // a negative d
  EXPECT_THROW(DeadzoneDeadbandEstimator{cfg}, std::invalid_argument);
  cfg.switch_model.left = {-1.0, 0.05, -150.0, 20.0};  // not stable
  EXPECT_THROW(DeadzoneDeadbandEstimator{cfg}, std::invalid_argument);
  cfg.switch_model.left = {-0.97, 0.05, -150.0, 20.0};
  EXPECT_NO_THROW(DeadzoneDeadbandEstimator{cfg});
}

namespace {
// add_intervals under model switching with lambda = 1 attaches the jackknife of intervals.hpp,
// recomputed here from its definition. Replicate b is a separate record (the samples without
// group b, made here) run from the start, restarted where the group was cut out and at the
// record's gaps (`gaps`: rows of the whole record; those inside group b are cut out with it); the
// interval is theta +- t_{0.975,9} sqrt((B - 1)/B sum (theta_b - mean)^2), t from scipy.stats.t.ppf.
void expect_delete_a_group_jackknife(const std::vector<std::size_t>& gaps) {
  const Plant p;
  std::vector<double> v, y;
  record(p, v, y);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 2.0);
  for (double& x : y) x += noise(rng);
  EstimatorConfig cfg(ModelKind::deadzone_deadband, 0.005);
  cfg.model_switching = true;
  cfg.method = EstimationMethod::iv;
  cfg.noise = NoiseSettings{};
  cfg.rls.lambda = 1.0;
  cfg.switch_model.right = {p.a1, p.b1, p.cr, p.dr};
  cfg.switch_model.left = {p.a1, p.b1, p.cl, p.dl};
  const auto run = [&](const std::vector<double>& vv, const std::vector<double>& yy,
                       const std::vector<std::size_t>& restarts) {
    DeadzoneDeadbandEstimator est(cfg);
    for (std::size_t k = 0; k < vv.size(); ++k) {
      if (k > 0 && std::find(restarts.begin(), restarts.end(), k) != restarts.end()) est.restart();
      est.step(vv[k], yy[k]);
    }
    return PerSide<SideParams>{est.params(Side::right), est.params(Side::left)};
  };
  const PerSide<SideParams> whole = run(v, y, gaps);
  EstimationRun attached;
  attached.report.model = ModelKind::deadzone_deadband;
  attached.report.right.params = whole.right;
  attached.report.left.params = whole.left;
  add_intervals(attached, cfg, v, y, gaps);
  const PerSide<SideIntervals> ci{attached.report.right.ci95, attached.report.left.ci95};
  constexpr std::size_t B = 10;
  const std::size_t n = v.size(), len = n / B;
  std::vector<PerSide<SideParams>> rep;
  for (std::size_t b = 0; b < B; ++b) {
    const std::size_t g0 = b * len, g1 = b + 1 == B ? n : g0 + len;
    std::vector<double> vb(v.begin(), v.begin() + static_cast<long>(g0)), yb(y.begin(), y.begin() + static_cast<long>(g0));
    vb.insert(vb.end(), v.begin() + static_cast<long>(g1), v.end());
    yb.insert(yb.end(), y.begin() + static_cast<long>(g1), y.end());
    std::vector<std::size_t> restarts{g0};  // the cut
    for (const std::size_t g : gaps)
      if (g < g0) restarts.push_back(g);
      else if (g >= g1) restarts.push_back(g - (g1 - g0));
    rep.push_back(run(vb, yb, restarts));
  }
  constexpr double t975_9 = 2.2621571627409915;  // scipy.stats.t.ppf(0.975, 9)
  for (const Side s : {Side::right, Side::left}) {
    ASSERT_TRUE(whole[s].identified);
    const auto check = [&](double centre, const Interval& iv, double SideParams::*f) {
      double mean = 0.0, ss = 0.0;
      for (const auto& r : rep) {
        ASSERT_TRUE(r[s].identified);
        mean += r[s].*f / B;
      }
      for (const auto& r : rep) ss += (r[s].*f - mean) * (r[s].*f - mean);
      const double half = t975_9 * std::sqrt((B - 1.0) / B * ss);
      ASSERT_TRUE(iv.valid());
      EXPECT_GT(half, 0.0);
      EXPECT_NEAR(iv.lo, centre - half, 1e-8 * half);  // student_t975 holds t to 9 digits
      EXPECT_NEAR(iv.hi, centre + half, 1e-8 * half);
    };
    check(whole[s].a1, ci[s].a1, &SideParams::a1);
    check(whole[s].b1, ci[s].b1, &SideParams::b1);
    check(whole[s].c, ci[s].c, &SideParams::c);
    check(whole[s].d, ci[s].d, &SideParams::d);
  }
}
}  // namespace

TEST(ModelSwitching, IntervalsAreTheDeleteAGroupJackknife) { expect_delete_a_group_jackknife({}); }

TEST(ModelSwitching, TheJackknifeRestartsAtTheRecordsGaps) {
  // 30000 rows, groups of 3000: a gap on a group's first row (where add_intervals' run over the
  // groups before it ends and the next begins), one inside a group, one inside the last
  expect_delete_a_group_jackknife({9000, 16517, 28000});
}

TEST(ModelSwitching, ConfigIsChecked) {
  EstimatorConfig cfg(ModelKind::deadzone_deadband, 0.005);
  cfg.model_switching = true;
  cfg.pooled = false;
  EXPECT_THROW(cfg.validate(), std::invalid_argument);
  cfg.pooled = true;
  cfg.switch_hold = 0;
  EXPECT_THROW(cfg.validate(), std::invalid_argument);
  cfg.switch_hold = 3;
  cfg.switch_margin = 1.0;
  EXPECT_THROW(cfg.validate(), std::invalid_argument);
  cfg.switch_margin = 0.05;
  EXPECT_NO_THROW(cfg.validate());
}

}  // namespace
}  // namespace lash
