// Each block against sequences computed by hand (values in the comments).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "lash/blocks.hpp"
#include "lash/signals/rng.hpp"

using namespace lash;

namespace {
template <class F>
std::vector<double> run(F&& f, const std::vector<double>& in) {
  std::vector<double> out;
  for (double x : in) out.push_back(f(x));
  return out;
}
}  // namespace

TEST(Deadzone, Eq1HandSequence) {
  Deadzone dz({-300.0, 200.0});
  // in − c_l below, 0 inside (edges included), in − c_r above.
  EXPECT_EQ(run([&](double x) { return dz.step(x); }, {-500, -300, -100, 0, 200, 250, 1000}),
            (std::vector<double>{-200, 0, 0, 0, 0, 50, 800}));
}

TEST(Deadzone, RejectsInsideOutAndNonFinite) {
  EXPECT_THROW(Deadzone({10.0, -10.0}), std::invalid_argument);
  EXPECT_THROW(Deadzone({NAN, 1.0}), std::invalid_argument);
  EXPECT_NO_THROW(Deadzone({5.0, 5.0}));
}

TEST(Deadband, Eq5And6HandSequence) {
  Deadband db(PerSide<double>::both(30.0));
  // out_prev = 0: 0,10 inside; 40 > 0+30 → 10; 100 → 70; 80, 60 inside [40,100];
  // 40 is not < 70−30 → hold 70; 20 < 40 → 50; −30 → 0.
  EXPECT_EQ(run([&](double x) { return db.step(x); }, {0, 10, 40, 100, 80, 60, 40, 20, -30}),
            (std::vector<double>{0, 0, 10, 70, 70, 70, 70, 50, 0}));
}

TEST(Deadband, PerSideHalfWidth) {
  Deadband db({/*right*/ 10.0, /*left*/ 40.0});
  EXPECT_EQ(db.step(25.0, Side::right), 15.0);  // 25 > 0 + 10
  EXPECT_EQ(db.step(-20.0, Side::left), 15.0);  // −20 not < 15 − 40 = −25 → hold
  EXPECT_EQ(db.step(-30.0, Side::left), 10.0);  // −30 < −25 → −30 + 40
  EXPECT_THROW(Deadband({-1.0, 1.0}), std::invalid_argument);
}

TEST(FirstOrder, Eq8HandSequence) {
  FirstOrder g(PerSide<FirstOrderParams>::both({-0.5, 2.0}));
  // w(k) = 0.5 w(k−1) + 2 u(k−1): u = 1,1,1,0,0 → w = 0, 2, 3, 3.5, 1.75
  EXPECT_EQ(run([&](double u) { return g.step(u); }, {1, 1, 1, 0, 0}), (std::vector<double>{0, 2, 3, 3.5, 1.75}));
}

TEST(FirstOrder, PiecewiseUsesGivenSide) {
  FirstOrder g({{0.0, 1.0}, {0.0, 3.0}});  // right b1 = 1, left b1 = 3, a1 = 0
  EXPECT_EQ(g.step(2.0, Side::right), 0.0);
  EXPECT_EQ(g.step(2.0, Side::left), 6.0);   // 3 · u(k−1) = 3 · 2
  EXPECT_EQ(g.step(0.0, Side::right), 2.0);  // 1 · 2
}

TEST(FirstOrder, FromContinuousEq9And10) {
  const auto p = FirstOrderParams::from_continuous(2.0, 0.1, 0.01);
  EXPECT_NEAR(p.a1, -0.9048374180359595, 2e-16);  // −e^{−0.1} (scipy/numpy reference value)
  EXPECT_NEAR(p.b1, 0.19032516392808085, 1e-16);  // −2·expm1(−0.1)
  EXPECT_NEAR(p.gain(), 2.0, 1e-14);
  EXPECT_NEAR(p.tau_s(0.01), 0.1, 1e-14);
  // Thesis eq. (2): 0.1/(z − 0.96) has K = 0.1/0.04 = 2.5.
  EXPECT_NEAR((FirstOrderParams{-0.96, 0.1}).gain(), 2.5, 1e-12);
  EXPECT_THROW(FirstOrderParams::from_continuous(1.0, 0.0, 0.01), std::invalid_argument);
}

TEST(MovingAverage, HandSequenceAndDelay) {
  MovingAverage ma(3);
  EXPECT_EQ(run([&](double x) { return ma.step(x); }, {3, 6, 9, 12}), (std::vector<double>{1, 3, 6, 9}));
  EXPECT_EQ(ma.delay_samples(), 1.0);
  EXPECT_THROW(MovingAverage(0), std::invalid_argument);
}

TEST(MovingAverage, NoDriftOverMillionSamples) {
  // After 10^6 samples of wide-range noise, M zeros must give exactly 0 again and
  // every output must equal the direct mean of the window.
  const std::size_t m = 20;
  MovingAverage ma(m);
  Rng rng(7);
  std::vector<double> window(m, 0.0);
  double worst = 0.0;
  for (int k = 0; k < 1'000'000; ++k) {
    const double x = 1e6 * rng.gaussian() + (k % 2 ? 1e-3 : -1e-3);
    window[k % m] = x;
    const double got = ma.step(x);
    if (k % 9973 == 0) {
      double s = 0.0;
      for (double w : window) s += w;
      worst = std::max(worst, std::abs(got - s / m));
    }
  }
  EXPECT_LT(worst, 1e-6);
  double last = 1.0;
  for (std::size_t i = 0; i < m; ++i) last = ma.step(0.0);
  EXPECT_EQ(last, 0.0);
}

TEST(MovingAverage, LongRunMatchesDirectWindowSum) {
  // 2·10^7 samples (5·10^5 windows of 40) of values spanning 12 decades with a large offset:
  // every 99 991st output must equal the direct sum of its window (long double, from the
  // stored inputs) to within M·ε·Σ|x|, whatever the position in the run. A running sum that
  // adds and subtracts would carry the cancellation error of every step so far.
  const std::size_t m = 40;
  MovingAverage ma(m);
  Rng rng(11);
  std::vector<double> window(m, 0.0);
  double scale[13];
  for (int i = 0; i < 13; ++i) scale[i] = std::pow(10.0, i - 6);
  double worst_rel = 0.0;
  for (std::int64_t k = 0; k < 20'000'000; ++k) {
    const double x = 1e7 + 1e6 * rng.gaussian() * scale[k % 13];
    window[static_cast<std::size_t>(k) % m] = x;
    const double got = ma.step(x);
    if (k % 99'991 == 0 || k == 19'999'999) {
      long double s = 0.0L, a = 0.0L;
      for (double w : window) {
        s += w;
        a += std::fabs(w);
      }
      const double want = static_cast<double>(s / m), bound = static_cast<double>(a / m) * 40 * 2.3e-16;
      worst_rel = std::max(worst_rel, std::fabs(got - want) / bound);
    }
  }
  EXPECT_LE(worst_rel, 1.0);  // within the bound everywhere, the last window as well as the first
  for (std::size_t i = 0; i < m; ++i) ma.step(0.0);
  EXPECT_EQ(ma.step(0.0), 0.0);  // a window of zeros is exactly 0 after 2·10^7 samples
}

TEST(MovingAveragePair, HandSequenceAndSameBitsAsTwoMovingAverages) {
  MovingAveragePair pair(3);
  double a = 0.0, b = 0.0;
  const double in_a[] = {3, 6, 9, 12}, in_b[] = {-30, 0, 30, 90};
  const double want_a[] = {1, 3, 6, 9}, want_b[] = {-10, -10, 0, 40};  // (sum of the last 3, 0 before) / 3
  for (int k = 0; k < 4; ++k) {
    pair.step(in_a[k], in_b[k], a, b);
    EXPECT_DOUBLE_EQ(a, want_a[k]) << k;
    EXPECT_DOUBLE_EQ(b, want_b[k]) << k;
  }
  EXPECT_THROW(MovingAveragePair(0), std::invalid_argument);
  // Each channel is the same computation as a MovingAverage of it: equal bit for bit (the
  // preprocessor's regression signals do not change when it filters v and y as a pair), over
  // several blocks and after reset(); and within M·ε·Σ|x| of the direct window sum.
  const std::size_t m = 40;
  MovingAveragePair p2(m);
  MovingAverage ma(m), mb(m);
  Rng rng(5);
  std::vector<double> wa(m, 0.0), wb(m, 0.0);
  for (int round = 0; round < 2; ++round) {
    for (std::size_t k = 0; k < 1000; ++k) {
      const double x = 500.0 * rng.gaussian(), y = 1e4 + rng.gaussian();
      wa[k % m] = x;
      wb[k % m] = y;
      p2.step(x, y, a, b);
      ASSERT_EQ(a, ma.step(x)) << k;
      ASSERT_EQ(b, mb.step(y)) << k;
      long double sa = 0.0L, sb = 0.0L, aa = 0.0L, ab = 0.0L;
      for (std::size_t i = 0; i < m; ++i) {
        sa += wa[i];
        sb += wb[i];
        aa += std::fabs(wa[i]);
        ab += std::fabs(wb[i]);
      }
      ASSERT_LE(std::fabs(a - static_cast<double>(sa / m)), static_cast<double>(aa / m) * 40 * 2.3e-16) << k;
      ASSERT_LE(std::fabs(b - static_cast<double>(sb / m)), static_cast<double>(ab / m) * 40 * 2.3e-16) << k;
    }
    p2.reset();
    ma.reset();
    mb.reset();
    std::fill(wa.begin(), wa.end(), 0.0);
    std::fill(wb.begin(), wb.end(), 0.0);
  }
}

TEST(BackwardDifference, Eq26HandSequence) {
  BackwardDifference d(0.5);
  EXPECT_EQ(run([&](double x) { return d.step(x); }, {1, 2, 4}), (std::vector<double>{2, 2, 4}));
  EXPECT_THROW(BackwardDifference(0.0), std::invalid_argument);
}

TEST(BackwardDifference, Eq33VarianceOfDerivative) {
  // var(ẏ) = 2 var(y) / T² for white noise (thesis eq. 33).
  const double T = 0.005, var = 200.0;
  BackwardDifference d(T);
  GaussianNoise n(var, 11);
  double s = 0, s2 = 0;
  const int N = 400000;
  for (int k = 0; k < N; ++k) {
    const double x = d.step(n.step());
    if (k == 0) continue;
    s += x;
    s2 += x * x;
  }
  const double mean = s / (N - 1), v = s2 / (N - 1) - mean * mean;
  EXPECT_NEAR(v / (2.0 * var / (T * T)), 1.0, 0.01);
}

TEST(Delay, HandSequence) {
  Delay d(2);
  EXPECT_EQ(run([&](double x) { return d.step(x); }, {1, 2, 3, 4}), (std::vector<double>{0, 0, 1, 2}));
  Delay pass(0);
  EXPECT_EQ(pass.step(5.0), 5.0);
}

TEST(Saturation, Clamps) {
  Saturation s(0.0, 2000.0);
  EXPECT_EQ(run([&](double x) { return s.step(x); }, {-5, 0, 1500, 2000, 2500}),
            (std::vector<double>{0, 0, 1500, 2000, 2000}));
  EXPECT_THROW(Saturation(1.0, 0.0), std::invalid_argument);
}

TEST(Blocks, StepsAreNoexcept) {
  static_assert(noexcept(std::declval<Deadzone&>().step(0.0)));
  static_assert(noexcept(std::declval<Deadband&>().step(0.0, Side::left)));
  static_assert(noexcept(std::declval<FirstOrder&>().step(0.0, Side::left)));
  static_assert(noexcept(std::declval<MovingAverage&>().step(0.0)));
  static_assert(noexcept(std::declval<BackwardDifference&>().step(0.0)));
  static_assert(noexcept(std::declval<Delay&>().step(0.0)));
  static_assert(noexcept(std::declval<Saturation&>().step(0.0)));
  SUCCEED();
}
