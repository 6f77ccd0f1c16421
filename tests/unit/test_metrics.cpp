// metrics module: every expected number is computed by hand in the comment beside it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "lash/blocks/first_order.hpp"
#include "lash/metrics/error.hpp"
#include "lash/metrics/first_order.hpp"
#include "lash/metrics/fit.hpp"
#include "lash/metrics/step_response.hpp"

namespace lash {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(Metrics, NrmseWholeRecord) {
  // errors 0, −1, 2, 0 → Σe² = 5, mean 1.25, √1.25 = 1.118033988749895, max|y| = 4
  const std::vector<double> y{1, -2, 3, 4}, ysim{1, -1, 1, 4};
  EXPECT_NEAR(nrmse(y, ysim), 1.118033988749895 / 4.0, 1e-15);
  // identical → 0
  EXPECT_EQ(nrmse(y, y), 0.0);
}

TEST(Metrics, NrmseWindow) {
  // t ∈ [1, 2]: errors −1, 2 → mean 2.5, √2.5 = 1.5811388300841898, max|y| there = 3
  const std::vector<double> t{0, 1, 2, 3}, y{1, -2, 3, 4}, ysim{1, -1, 1, 4};
  EXPECT_NEAR(nrmse(t, y, ysim, 1.0, 2.0), 1.5811388300841898 / 3.0, 1e-15);
  EXPECT_TRUE(std::isnan(nrmse(t, y, ysim, 10.0, 20.0)));  // empty window
}

TEST(Metrics, NrmseDegenerate) {
  const std::vector<double> zero{0, 0, 0}, sim{1, 2, 3};
  EXPECT_TRUE(std::isnan(nrmse(zero, sim)));  // no scale
  const std::vector<double> y{1, 2, 3}, bad{1, kNaN, 3};
  EXPECT_EQ(nrmse(y, bad), kInf);  // a diverged free run is the worst fit, never skipped
  NrmseAccumulator acc;
  EXPECT_TRUE(std::isnan(acc.value()));
  acc.add(2.0, 1.0);  // e = 1, max|y| = 2 → 1/2
  EXPECT_EQ(acc.value(), 0.5);
}

TEST(Metrics, Outside3Sigma) {
  // σ = 1: |e| = 0, 4, 4, NaN → 3 of 4 outside → 750 per 1000
  const std::vector<double> t{0, 1, 2, 3}, y{0, 0, 0, 0}, yhat{0, 4, -4, kNaN};
  EXPECT_EQ(outside_3sigma_per_1000(t, y, yhat, 1.0, 0.0, 3.0), 750.0);
  EXPECT_EQ(outside_3sigma_per_1000(t, y, yhat, 1.0, 0.0, 0.5), 0.0);
  EXPECT_TRUE(std::isnan(outside_3sigma_per_1000(t, y, yhat, 1.0, 5.0, 6.0)));
}

TEST(Metrics, RelativeError) {
  EXPECT_NEAR(relative_error(105.0, 100.0), 0.05, 1e-15);
  EXPECT_NEAR(relative_error(-95.0, -100.0), 0.05, 1e-15);
  EXPECT_EQ(relative_error(1.0, 0.0), kInf);
  EXPECT_EQ(relative_error(kNaN, 1.0), kInf);
  EXPECT_EQ(relative_error(1.0, kInf), kInf);
  EXPECT_NEAR(error_percent(110.0, 100.0), 10.0, 1e-12);
  EXPECT_TRUE(std::isnan(error_percent(kNaN, 100.0)));
}

TEST(Metrics, GainAndTimeConstant) {
  EXPECT_NEAR(static_gain(-0.96, 0.1), 2.5, 1e-12);  // 0.1 / 0.04
  EXPECT_NEAR(static_gain(0.5, 3.0), 2.0, 1e-15);    // 3 / 1.5
  EXPECT_TRUE(std::isnan(static_gain(-1.0, 1.0)));   // integrator: no static gain
  EXPECT_TRUE(std::isnan(static_gain(kNaN, 1.0)));
  // a1 = −1/2, T = 5 ms: τ = 0.005 / ln 2 = 0.0072134752044448170
  EXPECT_NEAR(time_constant_s(-0.5, 0.005), 0.0072134752044448170, 1e-17);
  EXPECT_NEAR(time_constant_s(-std::exp(-0.1), 0.01), 0.1, 1e-14);
  EXPECT_TRUE(std::isnan(time_constant_s(0.5, 0.005)));   // oscillating: no τ
  EXPECT_TRUE(std::isnan(time_constant_s(-1.0, 0.005)));  // integrator
  EXPECT_TRUE(std::isnan(time_constant_s(-1.2, 0.005)));  // unstable
  EXPECT_TRUE(std::isnan(time_constant_s(-0.5, 0.0)));
  // FirstOrderParams delegates to the same functions
  const FirstOrderParams p{-0.5, 1.5};
  EXPECT_EQ(p.gain(), static_gain(-0.5, 1.5));
  EXPECT_EQ(p.tau_s(0.005), time_constant_s(-0.5, 0.005));
}

TEST(Metrics, StepResponse) {
  // y0 = 0 → y1 = 1 at t = 0. 90 % between t = 1 (0.5) and t = 2 (1.0): 1 + 0.4/0.5 = 1.8 s.
  // Peak 1.2 → 20 % overshoot. Last outside the ±10 % band at t = 3 (1.2); the band edge 1.1
  // is crossed halfway to t = 4 (1.0): 3.5 s.
  const std::vector<double> t{0, 1, 2, 3, 4, 5}, y{0, 0.5, 1.0, 1.2, 1.0, 1.0};
  const StepMetrics m = step_metrics(t, y, 0.0, 0.0, 1.0);
  EXPECT_NEAR(m.rise_s, 1.8, 1e-12);
  EXPECT_NEAR(m.overshoot_pct, 20.0, 1e-12);
  EXPECT_NEAR(m.settling_s, 3.5, 1e-12);
  EXPECT_EQ(m.peak, 1.2);
}

}  // namespace
}  // namespace lash
