// Identification (docs/method.md §A3–§A5): RLS, the switching estimators, E1.
// Reference numbers come from the plant parameters that generated the data (the estimator
// never sees them) and from hand-checked identities; statsmodels agreement is a script test.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <numbers>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "lash/blocks.hpp"
#include "lash/identify/any_estimator.hpp"
#include "lash/identify/auto.hpp"
#include "lash/identify/auto_gate.hpp"
#include "lash/identify/preprocess.hpp"
#include "lash/identify/rls.hpp"
#include "lash/plant/plant.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"
#include "lash/signals/rng.hpp"

namespace lash {
namespace {

double rel_err(double est, double truth) { return std::fabs(est - truth) / std::fabs(truth); }

// ------------------------------------------------------------------------------------------ Rls

TEST(Rls, RecoversExactRegressionAndKeepsPSymmetric) {
  // y = 2 x1 − 3 x2 + 0.5, noise-free, random regressors: LS is exact after N ≥ 3 samples.
  RlsConfig<3> c;
  c.lambda = 0.98;
  c.p0 = 1e6;
  Rls<3> r(c);
  Rng rng(7);
  for (int k = 0; k < 200; ++k) {
    const double x1 = rng.gaussian(), x2 = rng.gaussian();
    r.update({x1, x2, 1.0}, 2 * x1 - 3 * x2 + 0.5);
  }
  // the only deviation from exact LS is the prior P0⁻¹ forgotten by λ^200 (≈ 2e-8 relative)
  EXPECT_NEAR(r.eta(0), 2.0, 1e-7);
  EXPECT_NEAR(r.eta(1), -3.0, 1e-7);
  EXPECT_NEAR(r.eta(2), 0.5, 1e-7);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_EQ(r.P()[i][j], r.P()[j][i]);
  EXPECT_EQ(r.updates(), 200u);
}

TEST(Rls, FirstStepMatchesHandComputation) {
  // P0 = 10 I, λ = 0.5, η0 = 0, φ = [1, 2], y = 3:
  // Pφ = [10, 20], φᵀPφ = 50, q = [10, 20]/50.5, η = q·3, P = (P − qφᵀP)/λ.
  RlsConfig<2> c;
  c.lambda = 0.5;
  c.p0 = 10.0;
  Rls<2> r(c);
  const double yhat = r.update({1.0, 2.0}, 3.0);
  EXPECT_EQ(yhat, 0.0);
  EXPECT_NEAR(r.eta(0), 30.0 / 50.5, 1e-15);
  EXPECT_NEAR(r.eta(1), 60.0 / 50.5, 1e-15);
  EXPECT_NEAR(r.P()[0][0], (10.0 - 100.0 / 50.5) / 0.5, 1e-12);
  EXPECT_NEAR(r.P()[0][1], (0.0 - 200.0 / 50.5) / 0.5, 1e-12);
  EXPECT_NEAR(r.P()[1][1], (10.0 - 400.0 / 50.5) / 0.5, 1e-12);
}

/// Recursive IV with λ = 1 solves the normal equations of IV exactly (Söderström & Stoica 1989,
/// §8): with R = P0⁻¹ + Σ z φᵀ and b = P0⁻¹ η0 + Σ z y, P = R⁻¹ and η = R⁻¹ b. Checked without an
/// inverse: R·P = I and R·η = b, with R and b summed in long double from the same samples.
/// With λ = 0.999: P = (λᵏ P0⁻¹ + Σ λ^(k−i) z φᵀ)⁻¹ likewise.
template <std::size_t N>
void iv_solves_normal_equations(double lambda) {
  RlsConfig<N> c;
  c.lambda = lambda;
  c.p0 = 100.0;
  for (std::size_t i = 0; i < N; ++i) c.eta0[i] = 0.5;
  Rls<N> r(c);
  Rng rng(3);
  long double R[N][N] = {}, b[N] = {};
  for (std::size_t i = 0; i < N; ++i) {
    R[i][i] = 1.0L / c.p0;
    b[i] = 0.5L / c.p0;
  }
  double y1 = 0.0, y2 = 0.0, y3 = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const double v = std::sin(0.01 * k) * 50.0 + rng.gaussian();
    const double y = 0.9 * y1 + 0.2 * v + 0.3 + rng.gaussian();
    typename Rls<N>::Vec phi{}, z{};
    const double f[4] = {-y1, v, 1.0, k % 2 ? 1.0 : -1.0}, g[4] = {-y3, v, 1.0, k % 2 ? 1.0 : -1.0};
    for (std::size_t i = 0; i < N; ++i) {
      phi[i] = f[i];
      z[i] = g[i];
    }
    r.update_iv(phi, z, y);
    for (std::size_t i = 0; i < N; ++i) {
      b[i] = lambda * b[i] + static_cast<long double>(z[i]) * y;
      for (std::size_t j = 0; j < N; ++j) R[i][j] = lambda * R[i][j] + static_cast<long double>(z[i]) * phi[j];
    }
    y3 = y2;
    y2 = y1;
    y1 = y;
  }
  double worst_p = 0.0, worst_eta = 0.0;
  for (std::size_t i = 0; i < N; ++i) {
    long double re = 0.0L, bn = 0.0L;
    for (std::size_t j = 0; j < N; ++j) {
      long double rp = 0.0L;
      for (std::size_t m = 0; m < N; ++m) rp += R[i][m] * r.P()[m][j];
      worst_p = std::max(worst_p, static_cast<double>(std::fabs(rp - (i == j ? 1.0L : 0.0L))));
      re += R[i][j] * r.eta(j);
    }
    bn = std::fabs(b[i]) + 1.0L;
    worst_eta = std::max(worst_eta, static_cast<double>(std::fabs(re - b[i]) / bn));
  }
  EXPECT_LT(worst_p, 1e-9) << "N = " << N;
  EXPECT_LT(worst_eta, 1e-9) << "N = " << N;
  EXPECT_EQ(r.updates(), 3000u);
}

TEST(Rls, IvSolvesTheNormalEquations) {
  iv_solves_normal_equations<3>(1.0);
  iv_solves_normal_equations<4>(1.0);  // the pooled deadzone-deadband regression (its own code path)
  iv_solves_normal_equations<3>(0.999);
  iv_solves_normal_equations<4>(0.999);
}

TEST(Rls, NonFiniteSampleIsSkippedAndCounted) {
  Rls<3> r(RlsConfig<3>{});
  r.update({1.0, 2.0, 1.0}, 4.0);
  const auto eta = r.eta();
  const auto P = r.P();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(r.update({nan, 1.0, 1.0}, 1.0)));
  r.update({1.0, 1.0, 1.0}, std::numeric_limits<double>::infinity());
  EXPECT_EQ(r.skipped(), 2u);
  EXPECT_EQ(r.updates(), 1u);
  EXPECT_EQ(r.eta(), eta);
  EXPECT_EQ(r.P(), P);
}

TEST(Rls, BoundsProjectTheEstimate) {
  RlsConfig<2> c;
  c.lower = {-1.0, 0.0001};
  c.upper = {0.0, 2.0};
  c.eta0 = {0.5, 5.0};  // projected at reset
  Rls<2> r(c);
  EXPECT_EQ(r.eta(0), 0.0);
  EXPECT_EQ(r.eta(1), 2.0);
  for (int k = 0; k < 50; ++k) r.update({1.0, static_cast<double>(k % 3)}, 10.0 + 7.0 * (k % 3));  // wants b1 = 7
  EXPECT_LE(r.eta(1), 2.0);
  EXPECT_GE(r.eta(0), -1.0);
  EXPECT_LE(r.eta(0), 0.0);
}

TEST(Rls, InvalidConfigThrows) {
  RlsConfig<2> c;
  c.lambda = 1.5;
  EXPECT_THROW(Rls<2>{c}, std::invalid_argument);
  c.lambda = 0.99;
  c.p0 = -1;
  EXPECT_THROW(Rls<2>{c}, std::invalid_argument);
}

// Zero excitation for 10⁶ samples: P stays finite and bounded, the estimate does not move.
void zero_excitation(Forgetting f, bool constant_phi) {
  RlsConfig<3> c;
  c.lambda = 0.99;
  c.p0 = 1000.0;
  c.forgetting = f;
  c.trace_max = 1e8;
  Rls<3> r(c);
  // learn y = −0.96·y1 + 0.1·v + 5 first
  Rng rng(3);
  for (int k = 0; k < 500; ++k) {
    const double a = rng.gaussian() * 100, b = rng.gaussian() * 100;
    r.update({a, b, 1.0}, -0.96 * a + 0.1 * b + 5.0);
  }
  const auto eta = r.eta();
  // parked: the regressor is constant (y at steady state, v fixed) or zero; y consistent with the model
  const std::array<double, 3> phi = constant_phi ? std::array<double, 3>{-250.0, 400.0, 1.0}
                                                 : std::array<double, 3>{0.0, 0.0, 0.0};
  const double y = r.predict(phi);
  double max_trace = 0;
  for (int k = 0; k < 1000000; ++k) {
    r.update(phi, y);
    max_trace = std::max(max_trace, r.trace());
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(r.eta(i), eta[i], 1e-9 * (1 + std::fabs(eta[i])));
    for (int j = 0; j < 3; ++j) EXPECT_TRUE(std::isfinite(r.P()[i][j]));
  }
  EXPECT_TRUE(std::isfinite(max_trace));
  EXPECT_LE(max_trace, 1e8 + 1.0);
  // P stays positive semi-definite on its diagonal
  for (int i = 0; i < 3; ++i) EXPECT_GE(r.P()[i][i], 0.0);
}

TEST(Rls, ZeroExcitationExponentialTraceBound) { zero_excitation(Forgetting::exponential, false); }
TEST(Rls, ConstantRegressorExponentialTraceBound) { zero_excitation(Forgetting::exponential, true); }
TEST(Rls, ZeroExcitationDirectional) { zero_excitation(Forgetting::directional, false); }
TEST(Rls, ConstantRegressorDirectional) { zero_excitation(Forgetting::directional, true); }

TEST(Rls, DirectionalWithLambdaOneIsPlainRls) {
  RlsConfig<3> a, b;
  a.lambda = b.lambda = 1.0;
  b.forgetting = Forgetting::directional;
  Rls<3> ra(a), rb(b);
  Rng rng(11);
  for (int k = 0; k < 100; ++k) {
    const std::array<double, 3> phi{rng.gaussian(), rng.gaussian(), 1.0};
    const double y = rng.gaussian();
    ra.update(phi, y);
    rb.update(phi, y);
  }
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(ra.eta(i), rb.eta(i), 1e-10);
}

TEST(Rls, DirectionalForgettingTracksAChange) {
  RlsConfig<2> c;
  c.lambda = 0.95;
  c.forgetting = Forgetting::directional;
  Rls<2> r(c);
  Rng rng(5);
  for (int k = 0; k < 6000; ++k) {
    const double x = rng.gaussian();
    const double gain = k < 1000 ? 2.0 : 3.0;
    r.update({x, 1.0}, gain * x + 1.0);
    if (k == 999) {
      EXPECT_NEAR(r.eta(0), 2.0, 1e-6);
    }
  }
  // the information along each direction saturates at (1 − λ)/λ, so old data is forgotten
  EXPECT_NEAR(r.eta(0), 3.0, 1e-4);
  EXPECT_NEAR(r.eta(1), 1.0, 1e-4);
}

// ------------------------------------------------------------------------------------------ E1

EstimatorConfig thesis_config() {
  EstimatorConfig c = EstimatorConfig::thesis(ModelKind::deadzone_deadband, 0.005);
  c.guess_left = -350;
  c.guess_right = 350;
  c.rls.lambda = 0.99;
  c.rls.p0 = 1000;
  c.rls.eta0 = {1, 1, 1};
  return c;
}

struct Truth {
  double a1r, b1r, cr, dr, a1l, b1l, cl, dl;
};

void expect_dzdb(const AnyEstimator& e, const Truth& t, double tol, const std::string& when) {
  const SideParams r = e.params(Side::right), l = e.params(Side::left);
  ASSERT_TRUE(r.identified && l.identified) << when;
  EXPECT_LE(rel_err(r.a1, t.a1r), tol) << when << " a1_r " << r.a1;
  EXPECT_LE(rel_err(r.b1, t.b1r), tol) << when << " b1_r " << r.b1;
  EXPECT_LE(rel_err(r.c, t.cr), tol) << when << " c_r " << r.c;
  EXPECT_LE(rel_err(r.d, t.dr), tol) << when << " d_r " << r.d;
  EXPECT_LE(rel_err(l.a1, t.a1l), tol) << when << " a1_l " << l.a1;
  EXPECT_LE(rel_err(l.b1, t.b1l), tol) << when << " b1_l " << l.b1;
  EXPECT_LE(rel_err(l.c, t.cl), tol) << when << " c_l " << l.c;
  EXPECT_LE(rel_err(l.d, t.dl), tol) << when << " d_l " << l.d;
}

/// The eq-34 plant (E1/E2) driven by 600 sin(t) for `duration_s`, noise of `noise_variance` on y.
SimulationTrace eq34_sine(double duration_s, double noise_variance = 0.0, std::uint64_t seed = 1) {
  Plant plant = load_plant(std::string(LASH_SOURCE_DIR) + "/config/plants/thesis_eq34.toml");
  SimulationSpec spec;
  spec.input.kind = Waveform::sine;
  spec.input.amplitude = 600;
  spec.input.frequency_rad_s = 1;
  spec.duration_s = duration_s;
  spec.noise_variance = noise_variance;
  spec.seed = seed;
  return simulate(plant, spec);
}

TEST(Preprocessor, MatchesDirectWindowMeansAndDerivative) {
  // lash's deadzone-deadband filters (MA40 on v and y, MA20 on the backward difference of
  // y_f, both regression signals delayed 10): every output against sums over the stored raw
  // samples (history 0 before the first), on 2·10^5 samples of a noisy sine.
  NoiseSettings ns;
  ns.filter_length = 40;
  ns.filter_input = true;
  ns.derivative_filter_length = 20;
  ns.align_delay = 10;
  const double dt = 0.005;
  Preprocessor pre(ns, dt);
  Rng rng(5);
  std::vector<double> v, y;
  auto at = [](const std::vector<double>& x, long k) { return k < 0 ? 0.0 : x[static_cast<std::size_t>(k)]; };
  auto mean = [&](const std::vector<double>& x, long k, long m) {
    long double s = 0.0L;
    for (long j = 0; j < m; ++j) s += at(x, k - j);
    return static_cast<double>(s / m);
  };
  double worst = 0.0;
  for (long k = 0; k < 200'000; ++k) {
    v.push_back(600.0 * std::sin(0.005 * static_cast<double>(k)) + 10.0 * rng.gaussian());
    y.push_back(300.0 * std::sin(0.005 * static_cast<double>(k) - 0.3) + 14.0 * rng.gaussian());
    const Conditioned c = pre.step(v.back(), y.back());
    if (k % 997 != 0 && k > 100) continue;
    const double vf = mean(v, k - 10, 40), yf = mean(y, k - 10, 40);
    long double ds = 0.0L;
    for (long j = 0; j < 20; ++j) ds += (mean(y, k - j, 40) - mean(y, k - j - 1, 40)) / dt;
    const double ydot = static_cast<double>(ds / 20);
    worst = std::max({worst, std::fabs(c.v - vf) / 600.0, std::fabs(c.y - yf) / 300.0, std::fabs(c.ydot - ydot) / 300.0});
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_EQ(pre.memory_samples(), 61u);  // the derivative path: 40 (MA) + 1 (difference) + 20 (MA of ẏ)
}

TEST(Estimators, E1NoiseFreeThesisEq34) {
  const SimulationTrace tr = eq34_sine(200);
  AnyEstimator e(thesis_config());
  const Truth truth{-0.96, 0.1, 200, 30, -0.94, 0.15, -300, 50};
  const auto& v = tr.col("v");
  const auto& y = tr.col("y");
  for (std::size_t k = 0; k < tr.samples(); ++k) {
    e.step(v[k], y[k]);
    if (k + 1 == 10000) expect_dzdb(e, truth, 0.005, "at 50 s");
  }
  expect_dzdb(e, truth, 1e-4, "at 200 s");
  EXPECT_TRUE(e.identified());
  // the free-run model reproduces the plant output after convergence
  EXPECT_NEAR(e.simulated(), y.back(), 1e-3 * 1000);
}

// ---------------------------------------------- each estimator recovers its own model exactly
// Plants other than the thesis's: different parameters, sample times and inputs; noise-free.

struct Record {
  std::vector<double> v, y;
};

Record run_plant(std::vector<Block> blocks, double dt, SignalSpec in, double duration) {
  Plant plant(std::move(blocks), dt);
  SimulationSpec spec;
  spec.input = in;
  spec.duration_s = duration;
  spec.seed = in.seed;
  const SimulationTrace tr = simulate(plant, spec);
  return {tr.col("v"), tr.col("y")};
}

AnyEstimator estimate(const EstimatorConfig& c, const Record& r) {
  AnyEstimator e(c);
  for (std::size_t k = 0; k < r.v.size(); ++k) e.step(r.v[k], r.y[k]);
  return e;
}

EstimatorConfig base(ModelKind m, double dt) {
  EstimatorConfig c = EstimatorConfig::thesis(m, dt);
  c.accel_limit = std::numeric_limits<double>::infinity();  // coupled carts: no acceleration gate
  c.rls.lambda = 1.0;
  c.rls.p0 = 1e8;
  c.rls.eta0 = {0, 0, 0};
  return c;
}

TEST(Estimators, LinearRecoversItsModel) {
  // G = 0.5/(z − 0.9) both sides, T = 0.01, randomized input
  std::vector<Block> b;
  b.emplace_back(FirstOrder(PerSide<FirstOrderParams>::both({-0.9, 0.5})));
  SignalSpec in;
  in.kind = Waveform::randomized;
  in.seed = 4;
  const Record r = run_plant(std::move(b), 0.01, in, 30);
  const AnyEstimator e = estimate(base(ModelKind::linear, 0.01), r);
  const SideParams p = e.params(Side::right);
  ASSERT_TRUE(p.identified);
  EXPECT_NEAR(p.a1, -0.9, 1e-8);
  EXPECT_NEAR(p.b1, 0.5, 1e-8);
  EXPECT_NEAR(e.simulated(), r.y.back(), 1e-6 * (1 + std::fabs(r.y.back())));
}

/// Delay(n) → DZ(−1.5, 0.8) → G_r = 0.3/(z − 0.8), G_l = 0.45/(z − 0.7); T = 0.001; triangle 5 at
/// 3 rad/s for 10 s; and the input-deadzone settings that identify it (guesses ±2).
Record input_deadzone_record(std::size_t delay) {
  std::vector<Block> b;
  if (delay > 0) b.emplace_back(Delay(delay));
  b.emplace_back(Deadzone({-1.5, 0.8}));
  b.emplace_back(FirstOrder({{-0.8, 0.3}, {-0.7, 0.45}}));
  SignalSpec in;
  in.kind = Waveform::triangle;
  in.amplitude = 5;
  in.frequency_rad_s = 3;
  return run_plant(std::move(b), 0.001, in, 10);
}

EstimatorConfig input_deadzone_config(std::size_t dead_time) {
  EstimatorConfig c = base(ModelKind::input_deadzone, 0.001);
  c.guess_left = -2;
  c.guess_right = 2;
  c.noise.dead_time = dead_time;
  return c;
}

void expect_input_deadzone_plant(const AnyEstimator& e) {
  const SideParams pr = e.params(Side::right), pl = e.params(Side::left);
  ASSERT_TRUE(pr.identified && pl.identified);
  EXPECT_NEAR(pr.a1, -0.8, 1e-8);
  EXPECT_NEAR(pr.b1, 0.3, 1e-8);
  EXPECT_NEAR(pr.c, 0.8, 1e-7);
  EXPECT_NEAR(pl.a1, -0.7, 1e-8);
  EXPECT_NEAR(pl.b1, 0.45, 1e-8);
  EXPECT_NEAR(pl.c, -1.5, 1e-7);
}

TEST(Estimators, InputDeadzoneRecoversItsModel) {
  expect_input_deadzone_plant(estimate(input_deadzone_config(0), input_deadzone_record(0)));
}

TEST(Estimators, DeadTimeDelaysTheRegressionAndTheFreeRun) {
  // The plant of InputDeadzoneRecoversItsModel behind a pure delay of 2 samples: y(k) responds
  // to v(k−3). dead_time = 2 recovers it exactly and its free run reproduces y (NRMSE ~ 0);
  // input_delay = 2 (a filter alignment, not part of the model) gives the same estimates but a
  // free run 2 samples ahead; no delay at all leaves the estimates off.
  const Record r = input_deadzone_record(2);
  EstimatorConfig c = input_deadzone_config(2);
  const AnyEstimator dead = estimate(c, r);
  expect_input_deadzone_plant(dead);
  const double fit_dead = dead.report().fit_nrmse;
  EXPECT_LT(fit_dead, 1e-6);
  EXPECT_NEAR(dead.simulated(), r.y.back(), 1e-6);

  c.noise.dead_time = 0;
  c.noise.input_delay = 2;
  const AnyEstimator aligned = estimate(c, r);
  EXPECT_EQ(aligned.params(Side::right).a1, dead.params(Side::right).a1);  // the same regression, bit for bit
  EXPECT_EQ(aligned.params(Side::left).c, dead.params(Side::left).c);
  EXPECT_GT(aligned.report().fit_nrmse, 100 * fit_dead + 1e-3);  // its free run leads y by 2 samples

  c.noise.input_delay = 0;
  const SideParams nr = estimate(c, r).params(Side::right);
  EXPECT_FALSE(nr.identified && std::fabs(nr.b1 - 0.3) < 1e-3 && std::fabs(nr.c - 0.8) < 1e-3);

  c.noise.dead_time = 100001;
  EXPECT_THROW(AnyEstimator{c}, std::invalid_argument);
}

TEST(Estimators, OutputDeadzoneRecoversItsModel) {
  // G = 0.2/(z − 0.95) → DZ(−0.5, 0.3); T = 0.002; sine 6 at 4 rad/s
  std::vector<Block> b;
  b.emplace_back(FirstOrder(PerSide<FirstOrderParams>::both({-0.95, 0.2})));
  b.emplace_back(Deadzone({-0.5, 0.3}));
  SignalSpec in;
  in.amplitude = 6;
  in.frequency_rad_s = 4;
  const Record r = run_plant(std::move(b), 0.002, in, 10);
  const AnyEstimator e = estimate(base(ModelKind::output_deadzone, 0.002), r);
  const SideParams pr = e.params(Side::right), pl = e.params(Side::left);
  ASSERT_TRUE(pr.identified && pl.identified);
  EXPECT_NEAR(pr.a1, -0.95, 1e-8);
  EXPECT_NEAR(pr.b1, 0.2, 1e-8);
  EXPECT_NEAR(pr.c, 0.3, 1e-6);
  EXPECT_NEAR(pl.a1, -0.95, 1e-8);
  EXPECT_NEAR(pl.b1, 0.2, 1e-8);
  EXPECT_NEAR(pl.c, -0.5, 1e-6);
  EXPECT_NEAR(e.simulated(), r.y.back(), 1e-6);
}

TEST(Estimators, HeldLevelShareCountedByHand) {
  // ValueRange (verdict check 2): the updates at the running largest / smallest value.
  verdict_rules::ValueRange r;
  for (double x : {5.0, 5.0, 5.0, 1.0, 2.0}) r.add(x);
  EXPECT_EQ(r.n, 5U);
  EXPECT_EQ(r.n_hi, 3U);  // three 5s
  EXPECT_EQ(r.n_lo, 1U);  // one 1
  EXPECT_DOUBLE_EQ(r.held_share(), 0.6);
  EXPECT_TRUE(r.varied());
  r.add(5.0 + 1e-12);  // within rounding of 5: still the same level
  EXPECT_EQ(r.n_hi, 4U);
  r.add(7.0);  // a new largest value: its count starts again
  EXPECT_EQ(r.n_hi, 1U);
  EXPECT_DOUBLE_EQ(r.held_share(), 1.0 / 7.0);
  // 19 of 20 at one level: 0.95 > 0.9, several values but not varied
  verdict_rules::ValueRange sq;
  for (int k = 0; k < 19; ++k) sq.add(-6.0);
  sq.add(6.0);
  EXPECT_TRUE(sq.several());
  EXPECT_DOUBLE_EQ(sq.held_share(), 0.95);
  EXPECT_FALSE(sq.varied());
  // exactly 9 of 10: at the threshold, still varied
  verdict_rules::ValueRange nine;
  for (int k = 0; k < 9; ++k) nine.add(3.0);
  nine.add(2.0);
  EXPECT_DOUBLE_EQ(nine.held_share(), 0.9);
  EXPECT_TRUE(nine.varied());
  EXPECT_DOUBLE_EQ(verdict_rules::ValueRange{}.held_share(), 0.0);
}

TEST(Estimators, SquareWaveSidesAreNotExcitedStaircaseSidesAre) {
  // The plant of OutputDeadzoneRecoversItsModel under a square wave of 6 at 4 rad/s: each side
  // sees its own level ±6 in steady state and the other only while the output decays after a
  // switch, i.e. far more than 90 % of its updates at one level: not_excited (verdict check 2),
  // although the noise-free data fit the model exactly (the free run still reproduces them).
  auto blocks = [] {
    std::vector<Block> b;
    b.emplace_back(FirstOrder(PerSide<FirstOrderParams>::both({-0.95, 0.2})));
    b.emplace_back(Deadzone({-0.5, 0.3}));
    return b;
  };
  SignalSpec sq;
  sq.kind = Waveform::square;
  sq.amplitude = 6;
  sq.frequency_rad_s = 4;
  const Record r = run_plant(blocks(), 0.002, sq, 10);
  const AnyEstimator e = estimate(base(ModelKind::output_deadzone, 0.002), r);
  for (Side s : {Side::right, Side::left}) {
    EXPECT_FALSE(e.params(s).identified);
    EXPECT_EQ(e.params(s).reason, Reason::not_excited);
  }
  EXPECT_NEAR(e.simulated(), r.y.back(), 1e-6);
  // A staircase 0, 2, 4, 2, 0, −2, −4, −2 (1 s each, twice): each side holds two levels beyond
  // its edge, the outer one on about half of its updates — identified exactly.
  SignalSpec st;
  st.kind = Waveform::steps;
  st.amplitude = 1;
  const double lv[] = {0, 2, 4, 2, 0, -2, -4, -2};
  for (int k = 0; k < 16; ++k) st.steps.push_back({static_cast<double>(k), lv[k % 8]});
  const Record r2 = run_plant(blocks(), 0.002, st, 16);
  const AnyEstimator e2 = estimate(base(ModelKind::output_deadzone, 0.002), r2);
  const SideParams pr = e2.params(Side::right), pl = e2.params(Side::left);
  ASSERT_TRUE(pr.identified && pl.identified) << to_string(pr.reason) << " " << to_string(pl.reason);
  EXPECT_NEAR(pr.b1, 0.2, 1e-8);
  EXPECT_NEAR(pr.c, 0.3, 1e-6);
  EXPECT_NEAR(pl.b1, 0.2, 1e-8);
  EXPECT_NEAR(pl.c, -0.5, 1e-6);
}

TEST(Estimators, UnstableOrUnphysicalSidesNeverDriveTheFreeRun) {
  // Data of y(k) = 1.002·y(k−1) + 0.001·v(k−1) (a pole outside the unit circle) for v > 0, and
  // nothing for v ≤ 0: the right side's RLS finds a1 = −1.002 exactly, which is neither
  // identified nor used by the free run; the left side never updates. So the free-run output is
  // exactly 0 on every sample while the one-step prediction follows the data.
  for (ModelKind m : {ModelKind::output_deadzone, ModelKind::input_deadzone}) {
    EstimatorConfig c = base(m, 0.01);
    c.guess_left = -0.5;
    c.guess_right = 0.5;
    AnyEstimator e(c);
    double y = 0.0, v1 = 0.0;
    for (int k = 0; k < 400; ++k) {
      const double v = 2.0 + std::sin(0.05 * k);  // 1..3 > guess: the right side updates
      y = 1.002 * y + 0.001 * v1;
      v1 = v;
      e.step(v, y);
      ASSERT_EQ(e.simulated(), 0.0) << "model " << static_cast<int>(m) << " k " << k;
    }
    EXPECT_FALSE(e.params(Side::right).identified);
    EXPECT_FALSE(e.params(Side::left).identified);
  }
  // A stable fit with the right edge below zero (data y = 0.9·y(k−1) + 0.1·v(k−1) + 0.05, i.e.
  // c_r = −0.5 on an output deadzone) is simulated but not presented as identified.
  EstimatorConfig c = base(ModelKind::output_deadzone, 0.01);
  AnyEstimator e(c);
  double y = 0.0, v1 = 0.0;
  for (int k = 0; k < 400; ++k) {
    const double v = 2.0 + std::sin(0.05 * k);
    y = 0.9 * y + 0.1 * v1 + 0.05;
    v1 = v;
    e.step(v, y);
  }
  EXPECT_FALSE(e.params(Side::right).identified);
  EXPECT_NE(e.simulated(), 0.0);
}

Record dzdb_other_plant() {
  // DZ(−100, 50) → G_r = 0.2/(z − 0.9), G_l = 0.3/(z − 0.85) → DB(d_r = 5, d_l = 8); T = 0.01; triangle 400 at 2 rad/s
  std::vector<Block> b;
  b.emplace_back(Deadzone({-100, 50}));
  b.emplace_back(FirstOrder({{-0.9, 0.2}, {-0.85, 0.3}}));
  b.emplace_back(Deadband({5, 8}));
  SignalSpec in;
  in.kind = Waveform::triangle;
  in.amplitude = 400;
  in.frequency_rad_s = 2;
  return run_plant(std::move(b), 0.01, in, 60);
}

void expect_dzdb_other(const AnyEstimator& e, double tol) {
  const SideParams pr = e.params(Side::right), pl = e.params(Side::left);
  ASSERT_TRUE(pr.identified && pl.identified);
  EXPECT_NEAR(pr.a1, -0.9, tol);
  EXPECT_NEAR(pr.b1, 0.2, tol);
  EXPECT_NEAR(pr.c, 50, 1e3 * tol);
  EXPECT_NEAR(pr.d, 5, 1e3 * tol);
  EXPECT_NEAR(pl.a1, -0.85, tol);
  EXPECT_NEAR(pl.b1, 0.3, tol);
  EXPECT_NEAR(pl.c, -100, 1e3 * tol);
  EXPECT_NEAR(pl.d, 8, 1e3 * tol);
}

TEST(Estimators, DeadzoneDeadbandRecoversItsModel) {
  const Record r = dzdb_other_plant();
  EstimatorConfig c = base(ModelKind::deadzone_deadband, 0.01);
  c.guess_left = -150;
  c.guess_right = 150;
  c.sim_side_by_sign = true;  // the plant's rule (eq. 34), so the free run is exact too
  const AnyEstimator e = estimate(c, r);
  expect_dzdb_other(e, 1e-8);
  const auto* d = e.get<DeadzoneDeadbandEstimator>();
  ASSERT_NE(d, nullptr);
  EXPECT_GT(d->updates(Side::right, true), 100u);
  EXPECT_GT(d->updates(Side::left, false), 100u);
  EXPECT_NEAR(e.simulated(), r.y.back(), 1e-5);
}

TEST(Estimators, DeadzoneDeadbandPooledAndIvRecoverItsModel) {
  const Record r = dzdb_other_plant();
  EstimatorConfig c = base(ModelKind::deadzone_deadband, 0.01);
  c.guess_left = -150;
  c.guess_right = 150;
  c.pooled = true;
  expect_dzdb_other(estimate(c, r), 1e-8);
  c.method = EstimationMethod::iv;
  expect_dzdb_other(estimate(c, r), 1e-6);
  c.pooled = false;
  expect_dzdb_other(estimate(c, r), 1e-6);
}

// ------------------------------------------------------- a gap in the record (issue 12 item 6)
// The plant runs on through 10 s that are not recorded: the output jumps across the gap. The
// regressions must never take a sample across it (restart at the gap row).

/// `r` without rows [from, to): the unrecorded stretch.
/// The first row `from` ≥ k0 where a gap of `len` rows makes the worst case: the output rises
/// (y_true) at both ends and jumps up by more than `jump` across it, the input beyond `v_min` at both
/// (for the last three samples before it: the side's direction hold is running).
std::size_t rising_gap(const std::vector<double>& v, const std::vector<double>& y_true, std::size_t k0,
                       std::size_t len, double jump, double v_min) {
  for (std::size_t k = k0; k + len + 1 < y_true.size(); ++k) {
    const std::size_t e = k + len;
    if (y_true[k - 1] > y_true[k - 2] && y_true[e + 1] > y_true[e] && y_true[e] - y_true[k - 1] > jump &&
        v[k - 3] > v_min && v[e] > v_min)
      return k;
  }
  return 0;
}

Record cut(const Record& r, std::size_t from, std::size_t to) {
  Record o;
  for (std::size_t k = 0; k < r.v.size(); ++k)
    if (k < from || k >= to) {
      o.v.push_back(r.v[k]);
      o.y.push_back(r.y[k]);
    }
  return o;
}

TEST(Estimators, GapRestartKeepsNoiseFreeEstimatesExact) {
  // dzdb_other_plant (T = 0.01 s) for 60 s with 9.6 s after t = 25 s unrecorded
  Record full = dzdb_other_plant();
  // 9.6 s missing: three periods of the triangle and 0.17 rad more, so the output moves the same way
  // at both ends of the gap and jumps up across it
  const std::size_t from = rising_gap(full.v, full.y, 2500, 960, 20.0, 150.0), to = from + 960;
  ASSERT_GT(from, 0u);
  const Record r = cut(full, from, to);
  const std::vector<std::size_t> gaps{from};
  EstimatorConfig c = base(ModelKind::deadzone_deadband, 0.01);
  c.guess_left = -150;
  c.guess_right = 150;
  c.pooled = true;
  for (const bool iv : {false, true}) {
    c.method = iv ? EstimationMethod::iv : EstimationMethod::ls;
    const double tol = iv ? 1e-6 : 1e-8;
    // with the restart: exact (every regression sample is a true sample of the plant)
    std::optional<AnyEstimator> with, without;
    run_estimator(c, r.v, r.y, false, [&](const AnyEstimator& e) { with.emplace(e); }, gaps);
    expect_dzdb_other(*with, tol);
    // without it: the samples across the jump enter the regression and bias it
    run_estimator(c, r.v, r.y, false, [&](const AnyEstimator& e) { without.emplace(e); });
    double worst = 0.0;
    for (Side s : {Side::right, Side::left}) {
      const auto& ew = with->get<DeadzoneDeadbandEstimator>()->pooled_rls(s).eta();
      const auto& eo = without->get<DeadzoneDeadbandEstimator>()->pooled_rls(s).eta();
      for (std::size_t i = 0; i < 4; ++i) worst = std::max(worst, std::fabs(eo[i] - ew[i]) / std::fabs(ew[i]));
    }
    EXPECT_GT(worst, 1e3 * tol) << (iv ? "iv" : "ls") << ": the gap must matter without the restart";
  }
}

TEST(Estimators, GapRestartOnE2DataMatchesARestartByHand) {
  // E2-like: the eq-34 plant, noise variance 200, 1 rad/s sine of 600, lash's settings for the
  // model; 7 s unrecorded after t = 100 s. The run loop's restart equals the one done by hand, and
  // the estimates keep E2's bounds (a1 1 %, b1 3 %, c 3 %, d 10 %).
  const SimulationTrace tr = eq34_sine(210, 200, 3);
  // 7 s missing (one period and 0.72 rad): the output rises at both ends and jumps up across it
  const std::size_t from = rising_gap(tr.col("v"), tr.col("y_true"), 20000, 1400, 100.0, 350.0), to = from + 1400;
  ASSERT_GT(from, 0u);
  const Record r = cut({tr.col("v"), tr.col("y")}, from, to);
  const std::vector<std::size_t> gaps{from};
  EstimatorConfig c = preset_config(ModelKind::deadzone_deadband, Preset::lash, 0.005);
  tune_to_data(c, analyse_record(r.v, r.y, 0.005));
  c.guess_left = -350;
  c.guess_right = 350;
  const EstimationRun run = run_estimator(c, r.v, r.y, false, {}, gaps);
  DeadzoneDeadbandEstimator hand(c);
  for (std::size_t k = 0; k < r.v.size(); ++k) {
    if (k == from) hand.restart();
    hand.step(r.v[k], r.y[k]);
  }
  const Truth truth{-0.96, 0.1, 200, 30, -0.94, 0.15, -300, 50};
  const SideParams* got[2] = {&run.report.right.params, &run.report.left.params};
  for (int i = 0; i < 2; ++i) {
    const Side s = i == 0 ? Side::right : Side::left;
    const SideParams h = hand.params(s), &p = *got[i];
    EXPECT_EQ(p.a1, h.a1);
    EXPECT_EQ(p.b1, h.b1);
    EXPECT_EQ(p.c, h.c);
    EXPECT_EQ(p.d, h.d);
    ASSERT_TRUE(p.identified) << to_string(p.reason);
    EXPECT_LE(rel_err(p.a1, i == 0 ? truth.a1r : truth.a1l), 0.01) << p.a1;
    EXPECT_LE(rel_err(p.b1, i == 0 ? truth.b1r : truth.b1l), 0.03) << p.b1;
    EXPECT_LE(rel_err(p.c, i == 0 ? truth.cr : truth.cl), 0.03) << p.c;
    EXPECT_LE(rel_err(p.d, i == 0 ? truth.dr : truth.dl), 0.10) << p.d;
  }
  // without the restart the run differs: the samples across the jump entered the regression (on
  // noisy data their harm is not measurable against the noise; the noise-free test above shows it)
  const EstimationRun plain = run_estimator(c, r.v, r.y);
  EXPECT_NE(plain.report.right.params.c, run.report.right.params.c);
}

TEST(Estimators, DeadzoneDeadbandNotIdentifiedBeforeEnoughData) {
  const Record r = dzdb_other_plant();
  EstimatorConfig c = base(ModelKind::deadzone_deadband, 0.01);
  c.guess_left = -150;
  c.guess_right = 150;
  c.min_updates = 10;
  AnyEstimator e(c);
  // the first 0.5 s: the input has not left the right guess long enough in both directions
  for (std::size_t k = 0; k < 50; ++k) e.step(r.v[k], r.y[k]);
  const SideParams pl = e.params(Side::left);
  EXPECT_FALSE(pl.identified);
  EXPECT_TRUE(std::isnan(pl.c));
  EXPECT_TRUE(std::isnan(pl.d));
  EXPECT_FALSE(e.identified());
}

TEST(Estimators, NonFiniteSampleSkipped) {
  const Record r = dzdb_other_plant();
  EstimatorConfig c = base(ModelKind::deadzone_deadband, 0.01);
  c.guess_left = -150;
  c.guess_right = 150;
  AnyEstimator e(c);
  for (std::size_t k = 0; k < 1000; ++k) e.step(r.v[k], r.y[k]);
  const SideParams before = e.params(Side::right);
  EXPECT_TRUE(std::isnan(e.step(std::numeric_limits<double>::quiet_NaN(), 1.0)));
  const SideParams after = e.params(Side::right);
  EXPECT_EQ(before.a1, after.a1);
  EXPECT_EQ(e.report().skipped, 1u);
}

TEST(Estimators, GuessesInsideOutRejected) {
  EstimatorConfig c = base(ModelKind::deadzone_deadband, 0.01);
  c.guess_left = 100;
  c.guess_right = -100;
  EXPECT_THROW(AnyEstimator{c}, std::invalid_argument);
  c.guess_left = c.guess_right = 0;
  EXPECT_THROW(AnyEstimator{c}, std::invalid_argument);
}

TEST(Estimators, CoupledCartsRecoversItsModel) {
  // Motor cart velocity: x = G(u), G = 0.05/(z − 0.98); ẇ = DZ(x; −0.04, 0.03) [m/s];
  // w(k) = w(k−1) + T·ẇ(k) (eq. 39–40); free cart y = DB(w; d = 0.02 m). T = 0.001, u = 6 sin(2t) V.
  const double dt = 0.001, a1 = -0.98, b1 = 0.05, cl = -0.04, cr = 0.03, d = 0.02;
  Deadband db({d, d});
  std::vector<double> v, y;
  double x = 0, w = 0, u1 = 0;
  for (int k = 0; k < 30000; ++k) {
    const double u = 6.0 * std::sin(2.0 * k * dt);
    x = -a1 * x + b1 * u1;
    const double wdot = x > cr ? x - cr : (x < cl ? x - cl : 0.0);
    w += dt * wdot;
    v.push_back(u);
    y.push_back(db.step(w));
    u1 = u;
  }
  EstimatorConfig c = base(ModelKind::coupled_carts, dt);
  c.stage2_start_s = 7.5;
  AnyEstimator e(c);
  for (std::size_t k = 0; k < v.size(); ++k) e.step(v[k], y[k]);
  const SideParams pr = e.params(Side::right), pl = e.params(Side::left);
  ASSERT_TRUE(e.identified());
  EXPECT_NEAR(pr.a1, a1, 1e-6);
  EXPECT_NEAR(pr.b1, b1, 1e-6);
  EXPECT_NEAR(pr.c, cr, 1e-5);
  EXPECT_NEAR(pl.a1, a1, 1e-6);
  EXPECT_NEAR(pl.b1, b1, 1e-6);
  EXPECT_NEAR(pl.c, cl, 1e-5);
  EXPECT_NEAR(pr.d, d, 1e-5);
  EXPECT_NEAR(e.simulated(), y.back(), 1e-4);
}

TEST(Estimators, CoupledCartsSquareWaveIsNotIdentified) {
  // The model of CoupledCartsRecoversItsModel driven by a 6 V square wave, with the thesis's
  // 1 m/s² acceleration gate: each side only ever updates with one input value (+6 V on r, −6 V
  // on l; the transients are gated out), so b1 and e are not separable (only b1·v + e is). Such a
  // side must be reported not identified — before, it was "identified" with whatever split the
  // RLS landed on, and its free run overflowed in the E5 sweep.
  const double dt = 0.001, a1 = -0.98, b1 = 0.05, cl = -0.04, cr = 0.03, d = 0.02;
  Deadband db({d, d});
  EstimatorConfig c = base(ModelKind::coupled_carts, dt);
  c.accel_limit = 1.0;
  CoupledCartsEstimator e(c);
  double x = 0, w = 0, u1 = 0, sim_max = 0;
  for (int k = 0; k < 30000; ++k) {
    const double u = std::sin(2.0 * k * dt) >= 0.0 ? 6.0 : -6.0;
    x = -a1 * x + b1 * u1;
    const double wdot = x > cr ? x - cr : (x < cl ? x - cl : 0.0);
    w += dt * wdot;
    e.step(u, db.step(w));
    ASSERT_TRUE(std::isfinite(e.simulated())) << k;
    sim_max = std::max(sim_max, std::fabs(e.simulated()));
    u1 = u;
  }
  for (Side s : {Side::right, Side::left}) {
    const SideParams p = e.params(s);
    EXPECT_GT(e.updates(s), 1000u);
    EXPECT_FALSE(p.identified);
    EXPECT_TRUE(std::isnan(p.a1) && std::isnan(p.b1) && std::isnan(p.c));
  }
  EXPECT_FALSE(e.identified());
  EXPECT_EQ(sim_max, 0.0);  // nothing identified: the free run (position) predicts no motion
}

}  // namespace
}  // namespace lash

namespace lash {
namespace {

// analyse_record's quantiles are selected in one pass from a bracket placed by a sample
// (auto.cpp); the reference here copies every sequence and takes std::nth_element's value at rank
// ⌊q·(n − 1)⌋ (the rule analyse_record documents). Equal to the bit on records that exercise the
// bracket (n ≥ 16384): noise, a sine input whose period could alias a strided sample, a quantised
// output (ties at the bracket's ends), non-finite rows and an output that does not move.
DataTraits analyse_reference(const std::vector<double>& v, const std::vector<double>& y, double dt) {
  const auto quantile = [](std::vector<double> x, double q) {
    if (x.empty()) return 0.0;
    const auto k = static_cast<std::size_t>(q * static_cast<double>(x.size() - 1));
    std::nth_element(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(k), x.end());
    return x[k];
  };
  DataTraits d;
  d.dt_s = dt;
  std::vector<double> vf, yf, d2, rates, acc, steps;
  for (std::size_t k = 0; k < v.size(); ++k)
    if (std::isfinite(v[k]) && std::isfinite(y[k])) {
      vf.push_back(v[k]);
      yf.push_back(y[k]);
    }
  d.samples = vf.size();
  if (vf.size() < 3) return d;
  d.v_lo = quantile(vf, 0.001);
  d.v_hi = quantile(vf, 0.999);
  d.y_span = quantile(yf, 0.999) - quantile(yf, 0.001);
  for (std::size_t k = 2; k < yf.size(); ++k) d2.push_back(std::fabs(yf[k] - 2.0 * yf[k - 1] + yf[k - 2]));
  d.noise_sigma = quantile(d2, 0.5) / (0.6745 * std::sqrt(6.0));
  for (std::size_t k = 40; k < yf.size(); ++k) rates.push_back(std::fabs(yf[k] - yf[k - 40]) / (40.0 * dt));
  d.ydot_p90 = quantile(rates, 0.9);
  for (std::size_t k = 2; k < yf.size(); ++k) {
    const double d1 = yf[k] - yf[k - 1], d0 = yf[k - 1] - yf[k - 2];
    if (d1 * d0 > 0.0) acc.push_back(std::fabs(d1 - d0) / (dt * dt));
  }
  d.yddot_p90 = quantile(acc, 0.9);
  // a step below 1e-9 of the largest |y| so far is rounding (auto.hpp quantum_step), written out here
  double scale = std::fabs(yf[0]);
  for (std::size_t k = 1; k < yf.size(); ++k) {
    scale = std::max(scale, std::fabs(yf[k]));
    if (const double s = std::fabs(yf[k] - yf[k - 1]); s > 1e-9 * scale) steps.push_back(s);
  }
  if (steps.size() > 10) {
    const double q = *std::min_element(steps.begin(), steps.end());
    std::size_t on = 0;
    for (double s : steps) on += std::fabs(s / q - std::round(s / q)) < 1e-3 ? 1u : 0u;
    if (on >= steps.size() * 99 / 100) d.quantum = q;
  }
  return d;
}

void expect_same_traits(const DataTraits& a, const DataTraits& b, const char* what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.samples, b.samples);
  for (auto [x, r] : {std::pair{a.v_lo, b.v_lo}, {a.v_hi, b.v_hi}, {a.y_span, b.y_span}, {a.noise_sigma, b.noise_sigma},
                      {a.ydot_p90, b.ydot_p90}, {a.yddot_p90, b.yddot_p90}, {a.quantum, b.quantum}})
    EXPECT_EQ(std::bit_cast<std::uint64_t>(x), std::bit_cast<std::uint64_t>(r)) << x << " vs " << r;
}

TEST(AnalyseRecord, QuantilesEqualFullCopiesToTheBit) {
  Rng rng(42);
  const std::size_t n = 200'000;
  std::vector<double> v(n), y(n), yq(n), yflat(n, 1.5);
  double w = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    v[k] = 600.0 * std::sin(2.0 * std::numbers::pi * static_cast<double>(k) / 1000.0);  // period 1000 rows
    w = 0.96 * w + 0.1 * v[k];
    y[k] = w + 0.5 * rng.gaussian();
    yq[k] = std::round(w / 0.25) * 0.25;  // an encoder: steps of 0.25, many ties
  }
  expect_same_traits(analyse_record(v, y, 0.005), analyse_reference(v, y, 0.005), "sine and noise");
  expect_same_traits(analyse_record(v, yq, 0.001), analyse_reference(v, yq, 0.001), "quantised");
  expect_same_traits(analyse_record(v, yflat, 0.005), analyse_reference(v, yflat, 0.005), "flat output");
  std::vector<double> vn = v, yn = y;
  for (std::size_t k = 7; k < n; k += 997) vn[k] = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 11; k < n; k += 1301) yn[k] = std::numeric_limits<double>::infinity();
  expect_same_traits(analyse_record(vn, yn, 0.005), analyse_reference(vn, yn, 0.005), "non-finite rows");
  std::vector<double> vr(n);
  for (auto& x : vr) x = rng.gaussian() * 100.0;
  expect_same_traits(analyse_record(vr, y, 0.002), analyse_reference(vr, y, 0.002), "white input");
  EXPECT_GT(analyse_record(v, yq, 0.001).quantum, 0.0);  // the encoder step is found
  // An encoder velocity as a rig computes it, (counts(k) − counts(k−1))·q/T: the same count
  // difference gives values a few ulps apart (here: the position's rounding), steps of ~1e-17
  // that are not motion. The quantum is still the encoder's velocity step q/T.
  const double q = 1e-5, T = 0.001;
  std::vector<double> yv(n);
  double prev = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double pos = std::round(50.0 * std::sin(static_cast<double>(k) / 700.0) / q) * q + 1.0;  // [m]
    yv[k] = (pos - prev) / T;
    prev = pos;
  }
  std::size_t tiny = 0;
  for (std::size_t k = 1; k < n; ++k) tiny += yv[k] != yv[k - 1] && std::fabs(yv[k] - yv[k - 1]) < 1e-9 ? 1u : 0u;
  ASSERT_GT(tiny, n / 100);  // more than 1 % of the steps: the grid rule would fail on them
  const DataTraits tv = analyse_record(v, yv, T);
  expect_same_traits(tv, analyse_reference(v, yv, T), "encoder velocity");
  EXPECT_NEAR(tv.quantum, q / T, 1e-9 * q / T);
}

// Past OrderStatistic's cap (2^18 kept values a quantile): at 5·10⁶ rows the median of |Δ²y| keeps
// ≈ 6.6 % of them inside its first bracket, too many; further passes (shared by the quantiles that
// need one) find the same values as full copies.
TEST(AnalyseRecord, QuantilesPastTheCapEqualFullCopies) {
  Rng rng(43);
  const std::size_t n = 5'000'000;
  std::vector<double> v(n), y(n);
  double w = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    v[k] = 600.0 * std::sin(2.0 * std::numbers::pi * static_cast<double>(k) / 1000.0) + 20.0 * rng.gaussian();
    w = 0.96 * w + 0.1 * v[k];
    y[k] = w + 0.5 * rng.gaussian();
  }
  expect_same_traits(analyse_record(v, y, 0.005), analyse_reference(v, y, 0.005), "5e6 rows");
}

// The outlier gate's replacements are kept apart from y (YEdits, no copy of the record): the run
// must be the one on a gated copy made by hand with the rule auto.hpp documents (gate; a flagged
// sample stays when the next one lies nearer it than the replacement), and analyse_record with the
// edits must equal the reference on that copy; the NRMSE score reads the record's own y.
TEST(EstimateAuto, OutlierEditsEqualAGatedCopy) {
  const SimulationTrace tr = eq34_sine(120, 4, 5);  // 24000 rows: the quantiles use their bracket
  std::vector<double> v = tr.col("v"), y = tr.col("y");
  for (std::size_t k = 700; k < y.size(); k += 1777) y[k] += (k % 2 ? 400.0 : -400.0);  // isolated spikes
  for (std::size_t k = 0; k < v.size(); k += 100) v[k] = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> yc(y);
  OutlierGate g;
  std::size_t flagged = 0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    const std::uint64_t before = g.rejected();
    yc[k] = g.step(y[k]);
    if (g.rejected() == before) continue;
    const double next = k + 1 < y.size() ? y[k + 1] : yc[k];
    if (std::fabs(next - y[k]) < std::fabs(next - yc[k])) yc[k] = y[k];
    else ++flagged;
  }
  ASSERT_GT(flagged, 5u);
  EstimatorConfig c = preset_config(ModelKind::deadzone_deadband, Preset::lash, 0.005);
  tune_to_data(c, analyse_record(v, y, 0.005));
  AutoOptions o;
  o.score_begin = 1500;
  o.score_end = y.size();
  const AutoRun edited = estimate_auto(c, v, y, o);
  o.gate = 0.0;
  const AutoRun copied = estimate_auto(c, v, yc, o);
  EXPECT_EQ(edited.outliers, flagged);
  EXPECT_EQ(edited.cfg.guess_right, copied.cfg.guess_right);
  EXPECT_EQ(edited.cfg.guess_left, copied.cfg.guess_left);
  ASSERT_EQ(edited.run.ysim.size(), y.size());
  for (std::size_t k = 0; k < y.size(); ++k) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(edited.run.yhat[k]), std::bit_cast<std::uint64_t>(copied.run.yhat[k])) << k;
    ASSERT_EQ(std::bit_cast<std::uint64_t>(edited.run.ysim[k]), std::bit_cast<std::uint64_t>(copied.run.ysim[k])) << k;
  }
  // the score: the record's y (spikes and all) against y_sim over the rows asked for
  NrmseAccumulator acc;
  for (std::size_t k = 1500; k < y.size(); ++k) acc.add(y[k], edited.run.ysim[k]);
  EXPECT_EQ(edited.run.score.value(), acc.value());
  EXPECT_EQ(edited.run.score.value(), nrmse(std::span(y).subspan(1500), std::span(edited.run.ysim).subspan(1500)));
  // analyse_record through the edits is analyse_record of the copy (the search's first pass)
  std::vector<std::size_t> rows;
  std::vector<double> vals;
  for (std::size_t k = 0; k < y.size(); ++k)
    if (std::bit_cast<std::uint64_t>(yc[k]) != std::bit_cast<std::uint64_t>(y[k])) {
      rows.push_back(k);
      vals.push_back(yc[k]);
    }
  EXPECT_EQ(rows.size(), flagged);
  expect_same_traits(analyse_record(v, y, 0.005, YEdits{rows, vals}), analyse_reference(v, yc, 0.005), "edited");
}

}  // namespace
}  // namespace lash

TEST(Verdict, BothSidesReasonIsOneTextTruncatedToFit) {
  char buf[64];
  lash::both_sides_reason(buf, "wrong_guess", "none");
  EXPECT_STREQ(buf, "right: wrong_guess; left: none");
  char small[10];  // 9 characters and the terminator: "right: wr"
  lash::both_sides_reason(small, "wrong_guess", "none");
  EXPECT_STREQ(small, "right: wr");
}

