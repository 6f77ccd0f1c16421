// Signals of docs/method.md §A2 against their formulas and the statistics theory predicts.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <limits>
#include <numbers>

#include "lash/signals/signal.hpp"

using namespace lash;

namespace {
std::vector<double> take(Signal& s, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(s.next());
  return v;
}
}  // namespace

TEST(Signal, SineSquareTriangleAtQuarterPeriods) {
  const double w = 2.0, T = std::numbers::pi / 8.0;  // ωT = π/4
  for (auto kind : {Waveform::sine, Waveform::square, Waveform::triangle}) {
    SignalSpec sp;
    sp.kind = kind;
    sp.amplitude = 10.0;
    sp.frequency_rad_s = w;
    Signal s(sp, T);
    auto v = take(s, 5);  // ωt = 0, π/4, π/2, 3π/4, π
    switch (kind) {
      case Waveform::sine:
        EXPECT_NEAR(v[1], 10.0 * std::sqrt(0.5), 1e-12);
        EXPECT_NEAR(v[2], 10.0, 1e-12);
        break;
      case Waveform::square:
        EXPECT_EQ(v[0], 0.0);  // sign(sin 0) = 0
        EXPECT_EQ(v[1], 10.0);
        EXPECT_EQ(v[3], 10.0);
        break;
      default:  // eq. (37): A (2/π) asin(sin ωt): linear ramp, 5 at π/4, 10 at π/2
        EXPECT_NEAR(v[1], 5.0, 1e-12);
        EXPECT_NEAR(v[2], 10.0, 1e-12);
        EXPECT_NEAR(v[3], 5.0, 1e-12);
        EXPECT_NEAR(v[4], 0.0, 1e-12);
    }
  }
}

TEST(Signal, RandomizedVarianceMatchesLowPassTheory) {
  // x(k) = a x(k−1) + (1−a) g(k), g ~ N(0, σ²): stationary var = σ² (1−a)/(1+a), a = exp(−T/τ).
  SignalSpec sp;
  sp.kind = Waveform::randomized;
  sp.variance = 10000.0;
  sp.tau_s = 0.5;
  sp.seed = 42;
  const double T = 0.01;
  Signal s(sp, T);
  const double a = std::exp(-T / 0.5);
  const double expect = 10000.0 * (1 - a) / (1 + a);
  double s1 = 0, s2 = 0;
  const int skip = 1000, n = 2'000'000;
  for (int k = 0; k < skip; ++k) s.next();
  for (int k = 0; k < n; ++k) {
    const double x = s.next();
    s1 += x;
    s2 += x * x;
  }
  EXPECT_NEAR((s2 / n - (s1 / n) * (s1 / n)) / expect, 1.0, 0.03);
  EXPECT_NEAR(s1 / n, 0.0, 0.05 * std::sqrt(expect));
}

TEST(Signal, SameSeedSameBitsOtherSeedOtherBits) {
  SignalSpec sp;
  sp.kind = Waveform::randomized;
  sp.seed = 9;
  Signal a(sp, 0.001), b(sp, 0.001);
  sp.seed = 10;
  Signal c(sp, 0.001);
  auto va = take(a, 1000), vb = take(b, 1000), vc = take(c, 1000);
  EXPECT_EQ(va, vb);
  EXPECT_NE(va, vc);
}

TEST(Signal, StepSequenceHoldsLevels) {
  SignalSpec sp;
  sp.kind = Waveform::steps;
  sp.steps = {{0.1, 500.0}, {0.3, 800.0}};
  Signal s(sp, 0.1);
  EXPECT_EQ(take(s, 5), (std::vector<double>{0, 500, 500, 800, 800}));
  sp.steps = {{0.3, 1.0}, {0.1, 2.0}};
  EXPECT_THROW(Signal(sp, 0.1), std::invalid_argument);
}

TEST(Signal, ParseWaveform) {
  EXPECT_EQ(parse_waveform("triangle"), Waveform::triangle);
  EXPECT_EQ(parse_waveform("random"), Waveform::randomized);
  EXPECT_THROW(parse_waveform("sawtooth"), std::invalid_argument);
}

TEST(Rng, GaussianMomentsAndKnownFirstValues) {
  Rng r(1);
  const int n = 1'000'000;
  double s1 = 0, s2 = 0, s4 = 0;
  for (int i = 0; i < n; ++i) {
    const double g = r.gaussian();
    s1 += g;
    s2 += g * g;
    s4 += g * g * g * g;
  }
  EXPECT_NEAR(s1 / n, 0.0, 0.005);
  EXPECT_NEAR(s2 / n, 1.0, 0.005);
  EXPECT_NEAR(s4 / n, 3.0, 0.05);  // kurtosis of a normal
  // xoshiro256** reference: state seeded by splitmix64(1) — first output computed by hand
  // from the published algorithms (Vigna): splitmix64 sequence from x = 1.
  Rng q(1);
  std::uint64_t x = 1;
  auto sm = [&x] {
    std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  };
  sm();
  const std::uint64_t s1v = sm();
  const std::uint64_t expect = ((s1v * 5) << 7 | (s1v * 5) >> 57) * 9;
  EXPECT_EQ(q.next(), expect);
}

// --- lash excite (signals/excite.hpp, docs/excite.md) -------------------------------------------
#include "lash/signals/excite.hpp"

TEST(Excite, ChecksNameTheField) {
  ExciteSpec s;
  s.edge_left = -200, s.edge_right = 300, s.dt_s = 0.005, s.duration_s = 60;
  EXPECT_FALSE(check_excite(s));
  const auto field = [](ExciteSpec x) { return check_excite(x) ? check_excite(x)->field : std::string(); };
  ExciteSpec b = s;
  b.edge_left = 10;
  EXPECT_EQ(field(b), "edges");
  b = s, b.edge_right = std::numeric_limits<double>::infinity();
  EXPECT_EQ(field(b), "edges");
  b = s, b.edge_left = -1e308, b.edge_right = 1e308;  // 2x overflows
  EXPECT_EQ(field(b), "edges");
  b = s, b.dt_s = 0;
  EXPECT_EQ(field(b), "dt");
  b = s, b.dt_s = std::nan("");
  EXPECT_EQ(field(b), "dt");
  b = s, b.duration_s = 4 * 2 * std::numbers::pi - 0.01;  // less than 4 default periods
  EXPECT_EQ(field(b), "duration");
  b = s, b.duration_s = 4 * 2 * std::numbers::pi;
  EXPECT_FALSE(check_excite(b));
  b = s, b.duration_s = 0.005 * (kExciteMaxSamples + 1);
  EXPECT_EQ(field(b), "duration");
  b = s, b.period_s = 0.05;  // < 20 dt
  EXPECT_EQ(field(b), "period");
  EXPECT_THROW(excite(b), std::invalid_argument);
  EXPECT_EQ(parse_excite_kind("prbs"), ExciteKind::prbs);
  EXPECT_THROW(parse_excite_kind("chirp"), std::invalid_argument);
  EXPECT_DOUBLE_EQ(excite_period(s), 2 * std::numbers::pi);  // max(2 pi, 1000 dt)
  s.dt_s = 0.01;
  EXPECT_DOUBLE_EQ(excite_period(s), 10.0);
}

// The design rule, for every kind: v within reach x the bounds, beyond each bound by a margin,
// and moving both up and down beyond each bound many times; the same seed gives the same signal.
TEST(Excite, EveryKindReversesBeyondBothBounds) {
  for (const ExciteKind kind : {ExciteKind::sine, ExciteKind::multisine, ExciteKind::prbs}) {
    SCOPED_TRACE(to_string(kind));
    ExciteSpec s;
    s.edge_left = -200, s.edge_right = 300, s.dt_s = 0.005, s.duration_s = 120, s.kind = kind, s.seed = 3;
    const std::vector<double> v = excite(s);
    ASSERT_EQ(v.size(), 24000u);
    EXPECT_EQ(v, excite(s));
    const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
    EXPECT_GE(*mn, -400.0);
    EXPECT_LE(*mx, 600.0);
    EXPECT_LT(*mn, -1.5 * 200);
    EXPECT_GT(*mx, 1.5 * 300);
    // moves (v(k) != v(k-1), both beyond the bound) up and down on each side
    int up_r = 0, down_r = 0, up_l = 0, down_l = 0;
    for (std::size_t k = 1; k < v.size(); ++k) {
      if (v[k] > 300 && v[k - 1] > 300) {
        up_r += v[k] > v[k - 1];
        down_r += v[k] < v[k - 1];
      }
      if (v[k] < -200 && v[k - 1] < -200) {
        up_l += v[k] > v[k - 1];
        down_l += v[k] < v[k - 1];
      }
    }
    const int need = kind == ExciteKind::prbs ? 5 : 500;  // prbs moves at level changes only
    EXPECT_GE(up_r, need);
    EXPECT_GE(down_r, need);
    EXPECT_GE(up_l, need);
    EXPECT_GE(down_l, need);
    // not two levels: the input takes many values beyond each bound (b1 and the offset separate)
    std::vector<double> beyond;
    for (double x : v)
      if (x > 300) beyond.push_back(x);
    std::sort(beyond.begin(), beyond.end());
    EXPECT_GE(std::unique(beyond.begin(), beyond.end()) - beyond.begin(), 5);
    if (kind != ExciteKind::sine) {
      ExciteSpec other = s;
      other.seed = 4;
      EXPECT_NE(v, excite(other));
    }
  }
}
