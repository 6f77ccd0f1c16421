// The console's decimator and running statistics against naive references computed here:
// per pixel column the min/max of the raw samples whose bucket lies in the column, and the
// nearest-rank p99 of the sorted values (docs/console.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "lash/console/decimator.hpp"
#include "lash/console/live_stats.hpp"
#include "lash/console/synthetic.hpp"

namespace {
using namespace lash::console;

TEST(ConsoleDecimator, ViewF32EqualsNaiveMinMaxPerColumn) {
  DecimatorConfig c;
  c.signals = 3;
  c.base_s = 0.001;
  c.levels = 4;
  c.buckets = 512;
  Decimator d(c);
  struct Row { double t; double v[3]; };
  std::vector<Row> rows;
  std::uint64_t x = 7;
  for (std::uint64_t k = 0; k < 3000; ++k) {  // 3 s at 1 kHz; a one-sample spike at k = 1234
    Row r{static_cast<double>(k) * 0.001, {}};
    for (std::size_t i = 0; i < 3; ++i) r.v[i] = synthetic_value(i, k, 1000.0, x);
    if (k == 1234) r.v[1] = 1000.0;
    rows.push_back(r);
    d.add(r.t, r.v);
  }
  for (const double window : {0.3, 1.0, 2.5}) {
    const std::vector<std::size_t> sig{0, 1, 2};
    std::vector<float> out;
    double t0 = 0, col = 0, bucket = 0;
    const std::size_t ncol = d.view_f32(d.last_t(), window, 200, sig, out, t0, col, bucket);
    ASSERT_GT(ncol, 0u);
    ASSERT_EQ(out.size(), 3 * 2 * ncol);
    // the grid: a column is a whole number of buckets, t0 a whole number of columns, the window
    // covered (the last column holds t_end)
    const double k = col / bucket, j0 = t0 / col;
    ASSERT_NEAR(k, std::round(k), 1e-9);
    ASSERT_NEAR(j0, std::round(j0), 1e-6);
    ASSERT_GE(col, window / 200 - 1e-12);
    ASSERT_LE(t0, d.last_t() - window + 1e-9);
    ASSERT_GT(t0 + col, d.last_t() - window);
    ASSERT_GT(t0 + static_cast<double>(ncol) * col, d.last_t());
    // naive: a sample belongs to column c when its bucket lies in [t0 + c col, t0 + (c+1) col)
    for (std::size_t cc = 0; cc < ncol; ++cc) {
      const auto b0 = std::llround(j0 + static_cast<double>(cc)) * std::llround(k);
      const auto b1 = b0 + std::llround(k);
      for (std::size_t s = 0; s < 3; ++s) {
        double lo = NAN, hi = NAN;
        for (const auto& r : rows) {
          const auto b = static_cast<std::int64_t>(std::floor(r.t / bucket));
          if (b < b0 || b >= b1) continue;
          lo = std::isnan(lo) ? r.v[s] : std::min(lo, r.v[s]);
          hi = std::isnan(hi) ? r.v[s] : std::max(hi, r.v[s]);
        }
        const float m = out[(2 * s) * ncol + cc], M = out[(2 * s + 1) * ncol + cc];
        if (std::isnan(lo)) {
          EXPECT_TRUE(std::isnan(m)) << "window " << window << " column " << cc;
        } else {
          EXPECT_EQ(m, static_cast<float>(lo)) << "window " << window << " column " << cc << " signal " << s;
          EXPECT_EQ(M, static_cast<float>(hi)) << "window " << window << " column " << cc << " signal " << s;
        }
      }
    }
    if (window >= 2.0) {  // the spike survives decimation
      float top = -1;
      for (std::size_t cc = 0; cc < ncol; ++cc) top = std::max(top, out[3 * ncol + cc]);
      EXPECT_EQ(top, 1000.0f);
    }
  }
}

// The page's stream: asking from column J gives the columns J.. of the full view, equal to them.
TEST(ConsoleDecimator, FromColumnIsTheTailOfTheWholeWindow) {
  DecimatorConfig c;
  c.signals = 2;
  c.base_s = 0.001;
  Decimator d(c);
  std::uint64_t x = 11;
  for (std::uint64_t k = 0; k < 12000; ++k) {
    const double v[2] = {synthetic_value(0, k, 1000.0, x), synthetic_value(3, k, 1000.0, x)};
    d.add(static_cast<double>(k) * 0.001, v);
  }
  const std::vector<std::size_t> sig{0, 1};
  std::vector<float> all, part;
  double t0 = 0, col = 0, bucket = 0, t0p = 0, colp = 0, bucketp = 0;
  const std::size_t n = d.view_f32(d.last_t(), 10.0, 625, sig, all, t0, col, bucket);
  EXPECT_EQ(bucket, 0.016);  // finest level covering 10 s: 1 ms * 4^2 (2048 buckets)
  EXPECT_EQ(col, 0.016);
  // columns 124 (holds 11.999 - 10 = 1.999 s: 1.999 / 0.016 = 124.9) to 749 (11.999 / 0.016 = 749.9)
  EXPECT_EQ(n, 626u);
  const auto j0 = std::llround(t0 / col);
  EXPECT_EQ(j0, 124);
  for (const std::int64_t back : {0, 1, 5, 625}) {
    const std::int64_t from = j0 + 625 - back;
    const std::size_t m = d.view_f32(d.last_t(), 10.0, 625, sig, part, t0p, colp, bucketp, from);
    ASSERT_EQ(m, static_cast<std::size_t>(back + 1));
    EXPECT_EQ(std::llround(t0p / colp), from);
    for (std::size_t q = 0; q < 4; ++q)  // min, max of both signals
      for (std::size_t cc = 0; cc < m; ++cc) {
        const float a = all[q * n + (n - m) + cc], b = part[q * m + cc];
        EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << "from " << from << " column " << cc;
      }
  }
  // a column after the newest: nothing; before the window: the whole window
  EXPECT_EQ(d.view_f32(d.last_t(), 10.0, 625, sig, part, t0p, colp, bucketp, j0 + 626), 0u);
  EXPECT_EQ(d.view_f32(d.last_t(), 10.0, 625, sig, part, t0p, colp, bucketp, j0 - 100), 626u);
}

TEST(ConsoleDecimator, NothingBeforeTheFirstSampleNorFromNaN) {
  DecimatorConfig c;
  c.signals = 1;
  c.base_s = 0.01;
  Decimator d(c);
  const double nan = NAN;
  d.add(0.0, std::span<const double>(&nan, 1));  // no value yet
  const double five = 5.0;
  d.add(0.001, std::span<const double>(&five, 1));
  std::vector<float> out;
  double t0, col, bucket;
  const std::vector<std::size_t> sig{0};
  const std::size_t n = d.view_f32(1.0, 2.0, 100, sig, out, t0, col, bucket);  // window [-1, 1)
  int finite = 0;
  for (std::size_t cc = 0; cc < n; ++cc)
    if (!std::isnan(out[cc])) {
      ++finite;
      EXPECT_EQ(out[cc], 5.0f);      // never a phantom 0 (t < 0) nor a NaN hiding the 5
      EXPECT_EQ(out[n + cc], 5.0f);
    }
  EXPECT_EQ(finite, 1);
}

TEST(ConsoleLiveStats, MeanMaxAndP99AgainstSortedValues) {
  LiveStats st(0.05, 50000);
  std::vector<double> v;
  std::uint64_t x = 3;
  for (int k = 0; k < 20000; ++k) {
    double a = 5.0 + std::fabs(synthetic_value(0, static_cast<std::uint64_t>(k), 1000.0, x));  // 4..6 us
    if (k % 250 == 0) a = 40.0 + k * 1e-3;  // 80 slow steps (0.4 %)
    v.push_back(a);
    st.add(a);
  }
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (double a : v) sum += a;
  EXPECT_NEAR(st.mean(), sum / static_cast<double>(v.size()), 1e-9);
  EXPECT_EQ(st.max(), v.back());
  const double p99 = v[static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(v.size()))) - 1];
  EXPECT_GE(st.quantile(0.99), p99);
  EXPECT_LE(st.quantile(0.99), p99 + 0.05);  // one bin
}

}  // namespace
