// OrderStatistic (io/order_statistic.hpp) against std::nth_element on a full copy, the independent
// reference; and the chunked analyse_sampling against the span one, to the bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "lash/io/order_statistic.hpp"
#include "lash/io/table.hpp"

using lash::OrderStatistic;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The reference: the value nth_element puts at rank ⌊q·(n − 1)⌋ of a full copy.
double ref_quantile(std::vector<double> x, double q) {
  if (x.empty()) return 0.0;
  const auto r = static_cast<std::size_t>(q * static_cast<double>(x.size() - 1));
  std::nth_element(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(r), x.end());
  return x[r];
}
/// The reference median: rank n/2, for even n the mean with the largest value of the lower part.
double ref_median(std::vector<double> x) {
  const auto mid = x.begin() + static_cast<std::ptrdiff_t>(x.size() / 2);
  std::nth_element(x.begin(), mid, x.end());
  double m = *mid;
  if (x.size() % 2 == 0) m = 0.5 * (m + *std::max_element(x.begin(), mid));
  return m;
}

struct Outcome {
  double value;
  std::size_t passes, high_water;
};

/// Runs `s` over x in chunks of `chunk` until it needs no more passes.
Outcome run(OrderStatistic s, const std::vector<double>& x, std::size_t chunk = 1000) {
  do {
    for (std::size_t i = 0; i < x.size(); i += chunk) s.add(x.data() + i, std::min(chunk, x.size() - i));
  } while (s.end_pass());
  EXPECT_LE(s.kept_high_water(), s.cap());
  EXPECT_LE(s.passes(), 8u);
  return {s.value(), s.passes(), s.kept_high_water()};
}

/// A bracket from an evenly strided sample of 4096 values (as analyse_record draws one).
void bracket_from(OrderStatistic& s, const std::vector<double>& x) {
  std::vector<double> smp;
  const std::size_t stride = std::max<std::size_t>(1, x.size() / 4096);
  for (std::size_t i = 0; i < x.size(); i += stride) smp.push_back(x[i]);
  s.bracket(smp, x.size());
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
// equal as values (±0 alike) or both NaN
bool same_value(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

const double kQs[] = {0.001, 0.5, 0.9, 0.999};

/// Every q, with and without a sample bracket, caps tiny to large: the reference's value.
void check_all(const std::vector<double>& x, const char* what) {
  for (const std::size_t cap : {std::size_t{16}, std::size_t{100}, std::size_t{5000}, OrderStatistic::kDefaultCap}) {
    for (const double q : kQs) {
      for (const bool with_bracket : {false, true}) {
        OrderStatistic s = OrderStatistic::quantile(q, cap);
        if (with_bracket) bracket_from(s, x);
        const Outcome r = run(s, x, 777);
        const double want = ref_quantile(x, q);
        EXPECT_TRUE(same_value(r.value, want))
            << what << " n=" << x.size() << " q=" << q << " cap=" << cap << " bracket=" << with_bracket
            << ": " << r.value << " vs " << want;
        // within the cap (every value fits): the very bits of the reference
        if (x.size() <= cap && !with_bracket) {
          EXPECT_TRUE(same_bits(r.value, want)) << what;
        }
      }
    }
    OrderStatistic m = OrderStatistic::median(cap);
    bracket_from(m, x);
    const double want = ref_median(x);
    EXPECT_TRUE(same_value(run(m, x, 333).value, want)) << what << " median n=" << x.size() << " cap=" << cap;
    EXPECT_TRUE(same_value(run(OrderStatistic::median(cap), x, 4096).value, want)) << what << " median, no bracket";
  }
}

}  // namespace

TEST(OrderStatistic, RandomSequencesOfManySizes) {
  std::mt19937_64 rng(29);
  std::normal_distribution<double> nd(3.0, 10.0);
  for (const std::size_t n : {1u, 2u, 3u, 15u, 16u, 17u, 255u, 256u, 1000u, 4097u, 20000u, 100003u}) {
    std::vector<double> x(n);
    for (double& v : x) v = nd(rng);
    check_all(x, "normal");
  }
}

TEST(OrderStatistic, HeavyTies) {
  std::mt19937_64 rng(7);
  std::vector<double> all_equal(50000, 2.5);
  check_all(all_equal, "all equal");
  std::vector<double> two(50000);
  for (double& v : two) v = rng() % 3 == 0 ? -1.0 : 4.0;
  check_all(two, "two values");
  std::vector<double> quant(60000);
  std::normal_distribution<double> nd(0.0, 30.0);
  for (double& v : quant) v = 0.25 * std::round(nd(rng));  // an encoder's grid
  check_all(quant, "quantised");
  std::vector<double> zeros(40000);  // ±0 mixed, and tiny values around them
  for (std::size_t i = 0; i < zeros.size(); ++i)
    zeros[i] = i % 3 == 0 ? -0.0 : i % 3 == 1 ? 0.0 : (i % 2 ? 1 : -1) * std::numeric_limits<double>::denorm_min();
  check_all(zeros, "signed zeros");
}

TEST(OrderStatistic, SortedReverseAndInfinities) {
  std::vector<double> up(30000);
  for (std::size_t i = 0; i < up.size(); ++i) up[i] = static_cast<double>(i) * 0.5 - 100.0;
  check_all(up, "sorted");
  std::vector<double> down(up.rbegin(), up.rend());
  check_all(down, "reverse");
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> ud(-1e300, 1e300);
  std::vector<double> inf(30000);
  for (std::size_t i = 0; i < inf.size(); ++i) inf[i] = i % 7 == 0 ? kInf : i % 11 == 0 ? -kInf : ud(rng);
  check_all(inf, "with infinities");
  std::vector<double> mostly_inf(30000, kInf);
  for (std::size_t i = 0; i < 40; ++i) mostly_inf[i * 700] = -kInf;
  check_all(mostly_inf, "mostly +inf");
}

TEST(OrderStatistic, BracketMisses) {
  // an adversarial bracket far below the values, then far above, then around the wrong quantile
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> ud(0.0, 1.0);
  std::vector<double> x(50000);
  for (double& v : x) v = ud(rng);
  for (const std::size_t cap : {std::size_t{64}, OrderStatistic::kDefaultCap}) {
    for (const double q : kQs) {
      for (const auto& [lo, hi] : {std::pair{-3.0, -2.0}, std::pair{2.0, 3.0}, std::pair{0.20, 0.21}, std::pair{0.95, 0.96}}) {
        OrderStatistic s = OrderStatistic::quantile(q, cap);
        s.bracket(lo, hi);
        const Outcome r = run(s, x);
        EXPECT_EQ(r.value, ref_quantile(x, q)) << "q=" << q << " [" << lo << ", " << hi << "] cap=" << cap;
        EXPECT_GE(r.passes, 2u);
      }
      OrderStatistic m = OrderStatistic::median(cap);
      m.bracket(0.7, 0.8);
      EXPECT_EQ(run(m, x).value, ref_median(x));
    }
  }
}

TEST(OrderStatistic, KeptValuesNeverExceedTheCap) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<double> x(200000);
  for (double& v : x) v = nd(rng);
  for (const std::size_t cap : {std::size_t{16}, std::size_t{1000}, std::size_t{65536}}) {
    for (const double q : kQs) {
      OrderStatistic s = OrderStatistic::quantile(q, cap);  // no bracket: every value kept until the cap
      const Outcome r = run(s, x, 4096);
      EXPECT_EQ(r.value, ref_quantile(x, q));
      EXPECT_LE(r.high_water, cap);
      EXPECT_EQ(r.high_water, cap);  // it did fill up
      EXPECT_LE(r.passes, 6u);       // the first pass, ≤ 4 of 16 key bits, one that keeps
    }
  }
  // within the cap: one pass (the bracket holds the rank), kept = the values inside
  OrderStatistic s = OrderStatistic::quantile(0.5);
  bracket_from(s, x);
  const Outcome r = run(s, x);
  EXPECT_EQ(r.passes, 1u);
  EXPECT_GT(r.high_water, 0u);
  EXPECT_LT(r.high_water, x.size() / 10);
}

TEST(OrderStatistic, NaN) {
  std::vector<double> x(3000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(static_cast<double>(i));
  x[1234] = std::numeric_limits<double>::quiet_NaN();
  // within the cap: the reference rule on every value, bit for bit (whatever nth_element makes of the NaN)
  for (const double q : kQs) {
    OrderStatistic s = OrderStatistic::quantile(q);
    bracket_from(s, x);  // the sample holds no NaN: a bracket; the NaN shows in the counts
    const double want = ref_quantile(x, q);
    EXPECT_TRUE(same_bits(run(s, x).value, want)) << q;
    // over the cap: NaN
    OrderStatistic t = OrderStatistic::quantile(q, 100);
    bracket_from(t, x);
    EXPECT_TRUE(std::isnan(run(t, x).value));
    EXPECT_TRUE(std::isnan(run(OrderStatistic::quantile(q, 100), x).value));
  }
  EXPECT_TRUE(same_bits(run(OrderStatistic::median(), x).value, ref_median(x)));
  EXPECT_TRUE(std::isnan(run(OrderStatistic::median(100), x).value));
}

TEST(OrderStatistic, EmptySequence) {
  OrderStatistic s = OrderStatistic::quantile(0.5);
  EXPECT_FALSE(s.end_pass());
  EXPECT_EQ(s.value(), 0.0);
  EXPECT_EQ(s.count(), 0u);
}

namespace {

/// A time column handed out in pieces of at most `piece` rows copied into the caller's buffer (a
/// record read from a file in blocks), never the source's own memory; counts the rows read.
class PieceSource final : public lash::TimeSource {
 public:
  PieceSource(const std::vector<double>& t, std::size_t piece) : t_(t), piece_(piece) {}
  std::size_t rows() const override { return t_.size(); }
  const double* read(std::size_t begin, std::size_t count, double* buf) const override {
    EXPECT_LE(begin + count, t_.size());
    for (std::size_t i = 0; i < count; i += piece_)
      std::memcpy(buf + i, t_.data() + begin + i, std::min(piece_, count - i) * sizeof(double));
    rows_read += count;
    return buf;
  }
  mutable std::size_t rows_read = 0;

 private:
  const std::vector<double>& t_;
  std::size_t piece_;
};

/// Jittery sampling with a few gaps: period `dt`, each step ± `jitter`·dt uniform, a gap of 7–40
/// periods every ~`gap_every` rows; steps drawn on a grid of 1e-9·dt when `grid` (ties).
std::vector<double> jittery(std::size_t n, double dt, double jitter, std::size_t gap_every, bool grid, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> t(n);
  double now = 12.5;
  for (std::size_t i = 0; i < n; ++i) {
    t[i] = now;
    double step = dt * (1.0 + jitter * u(rng));
    if (grid) step = std::round(step / (1e-3 * dt)) * (1e-3 * dt);
    if (gap_every && rng() % gap_every == 0) step = dt * (7.0 + 33.0 * (0.5 + 0.5 * u(rng)));
    now += step;
  }
  return t;
}

bool same(const lash::Sampling& a, const lash::Sampling& b) {
  return std::memcmp(&a.median_dt, &b.median_dt, sizeof(double)) == 0 && std::memcmp(&a.dt, &b.dt, sizeof(double)) == 0 &&
         std::memcmp(&a.max_jitter, &b.max_jitter, sizeof(double)) == 0 && a.gap_rows == b.gap_rows;
}

}  // namespace

TEST(AnalyseSamplingChunks, SameBitsAsTheSpanVersionAndTheReference) {
  struct Case {
    std::size_t n;
    double jitter;
    std::size_t gap_every;
    bool grid;
  };
  // short (every step kept), long (sample bracket), ties on a grid, and long enough that the
  // steps inside the median's bracket pass OrderStatistic's cap (≈ 9.4 % of 3.5·10⁶ > 2^18)
  for (const Case c : {Case{2, 0.0, 0, false}, Case{3, 0.1, 0, false}, Case{1000, 0.05, 50, false},
                       Case{40000, 0.02, 3000, false}, Case{40001, 0.3, 500, true}, Case{3500000, 0.1, 20000, false}}) {
    const std::vector<double> t = jittery(c.n, 0.005, c.jitter, c.gap_every, c.grid, static_cast<unsigned>(c.n));
    const lash::Sampling s = lash::analyse_sampling(t);
    // the independent reference: the median of a full copy of the steps, the gaps by their definition
    std::vector<double> d(t.size() - 1);
    for (std::size_t i = 1; i < t.size(); ++i) d[i - 1] = t[i] - t[i - 1];
    const double med = ref_median(d);
    EXPECT_EQ(s.median_dt, med) << c.n;
    std::vector<std::size_t> gaps;
    double max_dev = 0.0, gap_sum = 0.0;
    for (std::size_t i = 1; i < t.size(); ++i) {
      const double step = t[i] - t[i - 1];
      if (step > lash::kGapFactor * med) {
        gaps.push_back(i);
        gap_sum += step;
      } else {
        max_dev = std::max(max_dev, std::abs(step - med));
      }
    }
    EXPECT_EQ(s.gap_rows, gaps) << c.n;
    EXPECT_EQ(s.max_jitter, med > 0 ? max_dev / med : 0.0) << c.n;
    const std::size_t n_ok = t.size() - 1 - gaps.size();
    EXPECT_EQ(s.dt, n_ok ? (t.back() - t.front() - gap_sum) / static_cast<double>(n_ok) : med) << c.n;
    for (const std::size_t piece : {std::size_t{1}, std::size_t{7}, std::size_t{4096}}) {
      PieceSource src(t, piece);
      EXPECT_TRUE(same(lash::analyse_sampling(src), s)) << c.n << " piece " << piece;
      // a few passes over t, not one per value
      EXPECT_LE(src.rows_read, 8 * t.size() + 8192) << c.n;
      if (c.n < 1000) break;  // the short ones once
    }
  }
}
