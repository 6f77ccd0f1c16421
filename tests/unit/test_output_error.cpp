// Output-error refinement (include/lash/identify/output_error.hpp, docs/method.md §A4.4c).
// The record comes from lash's plant blocks (deadzone -> first-order lag -> deadband, the side of
// the deadband by the sign of v(k-1)), an implementation independent of the fit's free run.
// Checked: the free run of the plant's parameters is the plant (to rounding); from a start 3-10 %
// off, the noise-free fit returns the plant (1e-6 relative); over 40 noise seeds the fits'
// scatter is the one their covariance sigma^2 (J'J)^-1 predicts and the 95 % intervals hold the
// truth about 95 % of the time (Monte Carlo against the asymptotic theory, Ljung 1999 §9.3), for
// white noise and, through the residual's long-run variance factor, for AR(1) noise; the
// outlier edits and the window do what they say.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <random>
#include <vector>

#include "lash/blocks/deadband.hpp"
#include "lash/blocks/deadzone.hpp"
#include "lash/blocks/first_order.hpp"
#include "lash/identify/output_error.hpp"

namespace lash {
namespace {

// a1_r, b1_r, c_r, d_r, a1_l, b1_l, c_l, d_l: tau = 0.17 s at 5 ms, K = 1.5, edges +220 / -150,
// half-widths 35 / 20 (one linear part: the plant has one lag)
constexpr OutputErrorParams kTruth{-0.97, 0.045, 220.0, 35.0, -0.97, 0.045, -150.0, 20.0};
constexpr double kDt = 0.005;
constexpr int kRows = 12000;  // 60 s

// v: a 25-line random-phase multisine (0.05-1.5 Hz) scaled to +-500 (issue 30's kind of record)
std::vector<double> multisine() {
  std::mt19937_64 rng(30);
  std::uniform_real_distribution<double> ph(0.0, 2.0 * M_PI);
  std::vector<double> phase(25);
  for (double& x : phase) x = ph(rng);
  std::vector<double> v(kRows, 0.0);
  double peak = 0.0;
  for (int k = 0; k < kRows; ++k) {
    for (int i = 0; i < 25; ++i) v[k] += std::sin(2.0 * M_PI * (0.05 + i * 1.45 / 24.0) * k * kDt + phase[i]);
    peak = std::max(peak, std::fabs(v[k]));
  }
  for (double& x : v) x *= 500.0 / peak;
  return v;
}

// the plant's output through lash's blocks: y(k) from v up to k-1
std::vector<double> plant_output(const std::vector<double>& v) {
  Deadzone dz({kTruth[6], kTruth[2]});
  FirstOrder g(PerSide<FirstOrderParams>::both({kTruth[0], kTruth[1]}));
  Deadband db({kTruth[3], kTruth[7]});
  std::vector<double> y(v.size(), 0.0);
  for (std::size_t k = 0; k < v.size(); ++k) {
    const double w = g.step(dz.step(v[k]));  // w(k) from u(k-1): FirstOrder holds u one sample
    y[k] = db.step(w, side_of(k > 0 ? v[k - 1] : 0.0));
  }
  return y;
}

// `truth` with each parameter times its factor in `off` (a start some per cent away)
OutputErrorParams scaled(OutputErrorParams truth, const std::array<double, 8>& off) {
  for (std::size_t i = 0; i < 8; ++i) truth[i] *= off[i];
  return truth;
}
constexpr std::array<double, 8> kOff{1.003, 1.10, 0.95, 1.08, 1.002, 0.92, 1.06, 0.93};  // a1 by 0.3 %: tau 10 %

OutputErrorOptions by_sign() {
  OutputErrorOptions o;
  o.side_by_sign = true;
  return o;
}

TEST(OutputError, FreeRunOfThePlantsParametersIsThePlant) {
  const auto v = multisine();
  const auto y = plant_output(v);
  FreeRunDzDb run(kTruth, true);
  double worst = 0.0, peak = 0.0;
  for (std::size_t k = 0; k < v.size(); ++k) {
    const double ys = run.step(k > 0 ? v[k - 1] : 0.0);
    worst = std::max(worst, std::fabs(ys - y[k]));
    peak = std::max(peak, std::fabs(y[k]));
  }
  EXPECT_GT(peak, 200.0);  // the record leaves the deadzone and the deadband
  EXPECT_LT(worst, 1e-9 * peak);
}

TEST(OutputError, NoiseFreeFitFromAStartSeveralPercentOffReturnsThePlant) {
  const auto v = multisine();
  const auto y = plant_output(v);
  const OutputErrorParams start = scaled(kTruth, kOff);
  const OutputErrorFit f = fit_output_error(RecordColumns::of(v, y), start, by_sign());
  ASSERT_TRUE(f.ok);
  EXPECT_TRUE(f.converged);
  EXPECT_EQ(f.n, static_cast<std::size_t>(kRows));
  EXPECT_GT(f.rms_start, 1.0);
  EXPECT_LT(f.rms, 1e-6);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(f.theta[i], kTruth[i], 1e-6 * std::fabs(kTruth[i])) << "theta " << i;
}

// A dead time of n samples (NoiseSettings::dead_time): the plant driven by v delayed by n
// (v(k - n), 0 before the record) is fitted with OutputErrorOptions::dead_time = n; without it
// the same start stops far from the plant.
TEST(OutputError, ADeadTimeDelaysTheFreeRunsInput) {
  const auto v = multisine();
  constexpr std::size_t kDead = 2;
  std::vector<double> vd(v.size(), 0.0);
  for (std::size_t k = kDead; k < v.size(); ++k) vd[k] = v[k - kDead];
  const auto y = plant_output(vd);
  const OutputErrorParams start = scaled(kTruth, kOff);
  OutputErrorOptions o = by_sign();
  o.dead_time = kDead;
  const OutputErrorFit f = fit_output_error(RecordColumns::of(v, y), start, o);
  ASSERT_TRUE(f.ok);
  EXPECT_TRUE(f.converged);
  EXPECT_LT(f.rms, 1e-6);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(f.theta[i], kTruth[i], 1e-6 * std::fabs(kTruth[i])) << "theta " << i;
  const OutputErrorFit g = fit_output_error(RecordColumns::of(v, y), start, by_sign());
  ASSERT_TRUE(g.ok);
  EXPECT_GT(g.rms, 0.1);  // one sample of lag instead of three: a misfit the residual shows
}

// A record with 10 s missing (the reader's gap row 5000: rows 7000..11999 of the plant's run
// follow row 4999): with OutputErrorOptions::restart_rows the free run restarts there from the
// measured y (the linear part's state then differs from the plant's by at most d, which decays as
// a1^k) and the 1 000 rows after it (5 s, 30 tau) are not summed; the noise-free fit returns the
// plant. Without the restart the free run carries its state across the gap and the same start
// stops away from it.
TEST(OutputError, AGapRestartsTheFreeRunFromTheMeasuredOutput) {
  const auto v0 = multisine();
  const auto y0 = plant_output(v0);
  std::vector<double> v(v0.begin(), v0.begin() + 5000), y(y0.begin(), y0.begin() + 5000);
  v.insert(v.end(), v0.begin() + 7000, v0.end());
  y.insert(y.end(), y0.begin() + 7000, y0.end());
  const OutputErrorParams start = scaled(kTruth, kOff);
  OutputErrorOptions o = by_sign();
  const std::array<std::size_t, 1> gap{5000};
  o.restart_rows = gap;
  o.restart_settle = 1000;
  const OutputErrorFit f = fit_output_error(RecordColumns::of(v, y), start, o);
  ASSERT_TRUE(f.ok);
  EXPECT_EQ(f.n, static_cast<std::size_t>(10000 - 1001));  // the gap row and the settling rows
  EXPECT_LT(f.rms, 1e-6);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(f.theta[i], kTruth[i], 1e-6 * std::fabs(kTruth[i])) << "theta " << i;
  const OutputErrorFit g = fit_output_error(RecordColumns::of(v, y), start, by_sign());
  ASSERT_TRUE(g.ok);
  EXPECT_GT(g.rms, 100.0 * f.rms + 1e-3);
  double worst = 0.0;
  for (std::size_t i = 0; i < 8; ++i) worst = std::max(worst, std::fabs(g.theta[i] / kTruth[i] - 1.0));
  EXPECT_GT(worst, 1e-5);  // measured 4.6e-5 here; on E2's noisy sine with a 7 s gap, b1 23 % off
  // the restart: the free run outputs the measured y, the deadband's state w = y
  FreeRunDzDb run(kTruth, true);
  EXPECT_EQ(run.restart(42.5), 42.5);
  EXPECT_EQ(run.step(0.0), 42.5);  // w decays to 41.2 (inside y +- d): the output holds
}

// The output-deadzone model (G -> DZ, the motor cart's Coulomb friction on the output;
// OutputErrorOptions::output_deadzone): lash's FirstOrder then Deadzone blocks, edges +60 / -45 in
// the output's unit. The free run of the plant's parameters is the plant; from a start with the
// edges 30 % off and the lag 0.2 % (tau 7 %) off, the noise-free fit returns it; d is not fitted.
TEST(OutputError, TheOutputDeadzoneModelIsFittedOnItsSixParameters) {
  constexpr OutputErrorParams kOut{-0.97, 0.045, 60.0, 0.0, -0.97, 0.045, -45.0, 0.0};
  const auto v = multisine();
  FirstOrder g(PerSide<FirstOrderParams>::both({kOut[0], kOut[1]}));
  Deadzone dz({kOut[6], kOut[2]});
  std::vector<double> y(v.size(), 0.0);
  double peak = 0.0;
  for (std::size_t k = 0; k < v.size(); ++k) {
    y[k] = dz.step(g.step(v[k]));  // x(k) from v(k-1)
    peak = std::max(peak, std::fabs(y[k]));
  }
  EXPECT_GT(peak, 200.0);
  FreeRunDzDb run(kOut, false, true);
  double worst = 0.0;
  for (std::size_t k = 0; k < v.size(); ++k) worst = std::max(worst, std::fabs(run.step(k > 0 ? v[k - 1] : 0.0) - y[k]));
  EXPECT_LT(worst, 1e-9 * peak);
  const OutputErrorParams start = scaled(kOut, {1.002, 0.9, 1.3, 1.0, 0.998, 1.1, 0.7, 1.0});
  OutputErrorOptions o;
  o.output_deadzone = true;
  o.fit_d = true;  // ignored: the model has no deadband
  const OutputErrorFit f = fit_output_error(RecordColumns::of(v, y), start, o);
  ASSERT_TRUE(f.ok);
  EXPECT_TRUE(f.converged);
  EXPECT_GT(f.rms_start, 1.0);
  EXPECT_LT(f.rms, 1e-6);
  for (const std::size_t i : {0u, 1u, 2u, 4u, 5u, 6u}) EXPECT_NEAR(f.theta[i], kOut[i], 1e-6 * std::fabs(kOut[i])) << i;
  EXPECT_EQ(f.theta[3], 0.0);
  EXPECT_EQ(f.theta[7], 0.0);
  EXPECT_TRUE(std::isnan(f.half95[3]) && std::isnan(f.half95[7]));
}

struct Scatter {
  std::array<double, 8> sd_over_predicted{}, bias_over_sd{};
  int inside = 0, intervals = 0;
  double rho1 = 0.0;  // mean over the seeds
};

// 40 fits of the plant's record plus noise e(k) = rho e(k-1) + sqrt(1 - rho^2) sigma n(k)
// (n white, unit): the fits' scatter against the half-widths they report
Scatter scatter(double rho) {
  const auto v = multisine();
  const auto y0 = plant_output(v);
  constexpr int kSeeds = 40;
  constexpr double kSigma = 4.0;  // 1.4 % of the output's amplitude (E2-level)
  std::array<double, 8> sum{}, sum2{}, pred{};
  Scatter out;
  for (int s = 0; s < kSeeds; ++s) {
    std::mt19937_64 rng(1000 + s);
    std::normal_distribution<double> n(0.0, 1.0);
    std::vector<double> y = y0;
    double e = 0.0;
    for (double& x : y) x += (e = rho * e + std::sqrt(1.0 - rho * rho) * kSigma * n(rng));
    const OutputErrorFit f = fit_output_error(RecordColumns::of(v, y), kTruth, by_sign());
    EXPECT_TRUE(f.ok) << "seed " << s;
    EXPECT_NEAR(f.rms, kSigma, 0.15 * kSigma) << "seed " << s;  // the residual is the noise
    out.rho1 += f.rho1 / kSeeds;
    for (std::size_t i = 0; i < 8; ++i) {
      EXPECT_TRUE(std::isfinite(f.half95[i]));
      sum[i] += f.theta[i];
      sum2[i] += f.theta[i] * f.theta[i];
      pred[i] += f.half95[i] / 1.96 / kSeeds;
      out.inside += std::fabs(f.theta[i] - kTruth[i]) <= f.half95[i];
      ++out.intervals;
    }
  }
  for (std::size_t i = 0; i < 8; ++i) {
    const double mean = sum[i] / kSeeds;
    const double sd = std::sqrt((sum2[i] - kSeeds * mean * mean) / (kSeeds - 1));
    out.sd_over_predicted[i] = sd / pred[i];
    out.bias_over_sd[i] = (mean - kTruth[i]) / sd;
    std::printf("rho %.2f theta %zu: sd/predicted %.3f, (mean - truth)/sd %+.3f\n", rho, i, out.sd_over_predicted[i],
                out.bias_over_sd[i]);
  }
  std::printf("rho %.2f: mean rho1 %.3f, %d of %d intervals hold the truth\n", rho, out.rho1, out.inside, out.intervals);
  return out;
}

TEST(OutputError, ScatterOverNoiseSeedsIsTheOnePredictedByTheCovariance) {
  // white noise: the sample standard deviation of 40 draws is within about +-22 % of the true one
  // (2 sigma of its chi distribution, 1/sqrt(2*39) = 11 %); a bias would show as
  // |mean - truth| >> sd/sqrt(40). Measured: mean rho1 -0.004 (factor 1), sd/predicted 0.81-1.26
  // over the eight, |mean - truth| <= 0.21 sd, 302 of 320 inside.
  const Scatter w = scatter(0.0);
  EXPECT_LT(std::fabs(w.rho1), 0.05);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_GT(w.sd_over_predicted[i], 0.7) << "theta " << i;
    EXPECT_LT(w.sd_over_predicted[i], 1.4) << "theta " << i;
    EXPECT_LT(std::fabs(w.bias_over_sd[i]), 4.0 / std::sqrt(40.0)) << "theta " << i;
  }
  EXPECT_GE(w.inside, static_cast<int>(0.88 * w.intervals)) << w.inside << " of " << w.intervals;
}

TEST(OutputError, ACorrelatedResidualWidensTheIntervals) {
  // AR(1) noise with rho = 0.9: sigma^2 (J'J)^-1 alone would be about sqrt((1 + rho)/(1 - rho)) =
  // 4.4 times too narrow; the residual's lag-1 autocorrelation widens it by that factor.
  // Measured: mean rho1 0.898, sd/predicted 0.83-1.22, 307 of 320 inside.
  const Scatter c = scatter(0.9);
  EXPECT_NEAR(c.rho1, 0.9, 0.03);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_GT(c.sd_over_predicted[i], 0.5) << "theta " << i;
    EXPECT_LT(c.sd_over_predicted[i], 1.4) << "theta " << i;
  }
  EXPECT_GE(c.inside, static_cast<int>(0.85 * c.intervals)) << c.inside << " of " << c.intervals;
}

TEST(OutputError, WithDHeldTheInputDeadzonePlantIsFittedOnItsSixParameters) {
  // the plant without its deadband (lash's deadzone and first-order blocks): input-deadzone's
  // model; fit_d = false holds d_r = d_l = 0 and fits a1, b1, c of each side
  const auto v = multisine();
  Deadzone dz({kTruth[6], kTruth[2]});
  FirstOrder g(PerSide<FirstOrderParams>::both({kTruth[0], kTruth[1]}));
  std::vector<double> y(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) y[k] = g.step(dz.step(v[k]));
  OutputErrorParams start = scaled(kTruth, kOff);
  start[3] = start[7] = 0.0;
  OutputErrorOptions o = by_sign();
  o.fit_d = false;
  const OutputErrorFit f = fit_output_error(RecordColumns::of(v, y), start, o);
  ASSERT_TRUE(f.ok);
  EXPECT_TRUE(f.converged);
  EXPECT_LT(f.rms, 1e-6);
  for (std::size_t i : {0u, 1u, 2u, 4u, 5u, 6u}) {
    EXPECT_NEAR(f.theta[i], kTruth[i], 1e-6 * std::fabs(kTruth[i])) << "theta " << i;
    EXPECT_TRUE(std::isfinite(f.half95[i])) << "theta " << i;
  }
  EXPECT_EQ(f.theta[3], 0.0);
  EXPECT_EQ(f.theta[7], 0.0);
  EXPECT_TRUE(std::isnan(f.half95[3]) && std::isnan(f.half95[7]));
}

TEST(OutputError, EditedRowsAreReadInsteadOfTheRecordsY) {
  const auto v = multisine();
  const auto y = plant_output(v);
  OutputErrorParams start = kTruth;
  start[1] *= 1.05;
  start[6] *= 1.05;
  auto spoiled = y;
  const std::vector<std::size_t> rows{3000, 7000};
  const std::vector<double> values{y[3000], y[7000]};
  for (std::size_t r : rows) spoiled[r] += 5000.0;
  OutputErrorOptions o = by_sign();
  o.edit_rows = rows;
  o.edit_values = values;
  const OutputErrorFit edited = fit_output_error(RecordColumns::of(v, spoiled), start, o);
  const OutputErrorFit clean = fit_output_error(RecordColumns::of(v, y), start, by_sign());
  ASSERT_TRUE(edited.ok && clean.ok);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(edited.theta[i], clean.theta[i]) << "theta " << i;
  EXPECT_EQ(edited.rms, clean.rms);
  EXPECT_GT(edited.rms_given, 50.0);  // against y as given the two outliers count: 5000 * sqrt(2 / n)
  const OutputErrorFit pulled = fit_output_error(RecordColumns::of(v, spoiled), start, by_sign());
  ASSERT_TRUE(pulled.ok);
  EXPECT_GT(pulled.rms, 50.0);
}

TEST(OutputError, OnlyTheWindowsRowsAreSummedAndTooFewAreRefused) {
  const auto v = multisine();
  const auto y = plant_output(v);
  OutputErrorOptions o = by_sign();
  o.begin = 2000;
  o.end = 9000;
  const OutputErrorFit f = fit_output_error(RecordColumns::of(v, y), kTruth, o);
  ASSERT_TRUE(f.ok);
  EXPECT_EQ(f.n, 7000u);
  o.begin = 100;
  o.end = 116;  // 16 rows: no more residuals than twice the parameters
  EXPECT_FALSE(fit_output_error(RecordColumns::of(v, y), kTruth, o).ok);
  OutputErrorParams bad = kTruth;
  bad[0] = -1.2;  // a1 outside (-1, 1): not a start
  EXPECT_FALSE(fit_output_error(RecordColumns::of(v, y), bad, by_sign()).ok);
}

}  // namespace
}  // namespace lash
