// Records spilled to a temporary file (io/column_store.hpp) and estimated from it in chunks
// (estimate_record): the spill keeps every bit, leaves no name anywhere, and an estimate from it
// is the estimate from memory, to the bit (issue 29: `lash estimate` in memory that does not grow
// with the record).
#include <dirent.h>
#include <stdlib.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lash/identify/config_sources.hpp"
#include "lash/identify/data.hpp"
#include "lash/identify/estimate.hpp"
#include "lash/io/column_store.hpp"
#include "lash/io/error.hpp"
#include "lash/io/table.hpp"

namespace lash {
namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// A fresh private directory, removed at the end; TMPDIR points there meanwhile.
class TmpdirScope {
 public:
  TmpdirScope() {
    char tmpl[] = "/tmp/lash-spill-test.XXXXXX";
    dir_ = ::mkdtemp(tmpl);
    const char* old = std::getenv("TMPDIR");
    had_ = old != nullptr;
    if (had_) old_ = old;
    ::setenv("TMPDIR", dir_.c_str(), 1);
  }
  ~TmpdirScope() {
    if (had_) ::setenv("TMPDIR", old_.c_str(), 1);
    else ::unsetenv("TMPDIR");
    std::filesystem::remove_all(dir_);
  }
  const std::string& dir() const { return dir_; }
  std::size_t entries() const {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir_)) ++n;
    return n;
  }

 private:
  std::string dir_, old_;
  bool had_ = false;
};

TEST(SpillStore, KeepsEveryBitAcrossBlockBoundaries) {
  TmpdirScope tmp;
  constexpr std::size_t B = SpillWriter::kBlockRows;
  std::mt19937_64 rng(5);
  for (const std::size_t n : {std::size_t{1}, B - 1, B, B + 1, 3 * B + 5}) {
    std::vector<std::vector<double>> cols(3, std::vector<double>(n));
    for (std::size_t i = 0; i < n; ++i)
      for (auto& c : cols) {
        const std::uint64_t u = rng();
        double x;
        std::memcpy(&x, &u, sizeof x);  // any bit pattern: NaN payloads, ±inf, −0, subnormals
        c[i] = x;
      }
    SpillWriter w(3);
    for (std::size_t i = 0; i < n; ++i) {
      const double row[3] = {cols[0][i], cols[1][i], cols[2][i]};
      w.push(row);
    }
    const ColumnStore s = w.finish();
    ASSERT_EQ(s.rows(), n);
    ASSERT_EQ(s.columns(), 3u);
    EXPECT_FALSE(s.in_memory());
    EXPECT_THROW((void)s.column(0), std::logic_error);
    EXPECT_THROW(s.read(0, n, 1, nullptr), std::out_of_range);
    EXPECT_THROW(s.read(3, 0, 1, nullptr), std::out_of_range);
    // every column through the chunked pass, and random ranges read directly
    std::size_t seen = 0;
    bool all_same = true;
    for_chunks(s, std::array<std::size_t, 3>{2, 0, 1}, 0, n, [&](std::size_t base, const auto& c) {
      EXPECT_EQ(base, seen);
      EXPECT_LE(c[0].size(), ColumnStore::kChunkRows);
      for (std::size_t j = 0; j < c[0].size(); ++j)
        all_same = all_same && same_bits(c[0][j], cols[2][base + j]) && same_bits(c[1][j], cols[0][base + j]) &&
                   same_bits(c[2][j], cols[1][base + j]);
      seen += c[0].size();
    });
    EXPECT_EQ(seen, n);
    EXPECT_TRUE(all_same) << n;
    for (int r = 0; r < 20; ++r) {
      const std::size_t b = rng() % n, m = 1 + rng() % (n - b);
      std::vector<double> got(m);
      s.read(1, b, m, got.data());
      for (std::size_t j = 0; j < m; ++j) ASSERT_TRUE(same_bits(got[j], cols[1][b + j])) << n << " " << b + j;
    }
    EXPECT_TRUE(same_bits(s.back(2), cols[2][n - 1]));
  }
  EXPECT_EQ(tmp.entries(), 0u);  // the spill file never had a name there
}

TEST(SpillStore, LeavesNoNameAndNamesTmpdirWhenItCannot) {
  {
    TmpdirScope tmp;
    SpillWriter w(2);
    const double row[2] = {1.0, 2.0};
    for (int i = 0; i < 1000; ++i) w.push(row);
    EXPECT_EQ(tmp.entries(), 0u);
    const ColumnStore s = w.finish();
    EXPECT_EQ(tmp.entries(), 0u);
    EXPECT_EQ(s.at(1, 999), 2.0);
  }
  TmpdirScope tmp;
  ::setenv("TMPDIR", (tmp.dir() + "/missing").c_str(), 1);
  try {
    SpillWriter w(2);
    FAIL() << "a spill file in a missing directory";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "TMPDIR");
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
}

/// A t,v,y CSV: the deadzone-deadband plant of SPEC (deadzone −150/+220, first-order lag, backlash
/// 20/35) under a 0.4 Hz sine of ±500, noise, with comments, a skipped row, two gaps and outliers.
std::string write_record(const std::string& dir, std::size_t n) {
  const std::string path = dir + "/rec.csv";
  std::ofstream f(path);
  f.precision(17);
  f << "# a comment line\n" << "t,v,y\n";
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 2.0);
  double x = 0.0, yb = 0.0, t = 0.0, v_prev = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double v = 500.0 * std::sin(2.0 * M_PI * 0.4 * t);
    const double u = v_prev > 220.0 ? v_prev - 220.0 : v_prev < -150.0 ? v_prev + 150.0 : 0.0;
    x = 0.97 * x + 0.05 * u;
    if (x - yb > 35.0) yb = x - 35.0;
    if (yb - x > 20.0) yb = x + 20.0;
    double y = yb + noise(rng);
    if (k % 4999 == 17) y += 300.0;  // an outlier
    if (k == n / 3) f << "# a comment in the middle\n";
    if (k % 7919 == 3) f << t << ",nan," << y << "\n";  // skipped
    else f << t << "," << v << "," << y << "\n";
    v_prev = v;
    t += 0.005;
    if (k == n / 2 || k == 2 * n / 3) t += 1.0;  // gaps
  }
  return path;
}

TEST(SpillStore, TableReadIntoASpillEqualsTheTableInMemory) {
  TmpdirScope tmp;
  const std::string path = write_record(tmp.dir(), 20000);
  TableOptions o;
  o.columns = {"t", "v", "y"};
  const Table mem = read_table(path, o);
  o.spill_after_rows = 777;
  const Table sp = read_table(path, o);
  ASSERT_EQ(sp.rows(), mem.rows());
  EXPECT_TRUE(sp.cols[0].empty());  // freed: the rows are in the file
  EXPECT_EQ(sp.skipped_rows, mem.skipped_rows);
  EXPECT_GT(mem.skipped_rows, 0u);
  EXPECT_EQ(sp.first_skipped_line, mem.first_skipped_line);
  EXPECT_EQ(sp.line_of_row.to_vector(), mem.line_of_row.to_vector());
  const ColumnStore s = sp.store();
  for (std::size_t c = 0; c < 3; ++c) {
    std::vector<double> got(s.rows());
    s.read(c, 0, got.size(), got.data());
    EXPECT_EQ(std::memcmp(got.data(), mem.cols[c].data(), got.size() * sizeof(double)), 0) << c;
  }
  EXPECT_EQ(tmp.entries(), 1u);  // rec.csv alone
}

TEST(EstimateRecord, FromASpillIsTheEstimateFromMemoryToTheBit) {
  TmpdirScope tmp;
  const std::string path = write_record(tmp.dir(), 40000);  // > 4·4096 rows: analyse_record samples strata
  const Record mem = load_record(path, {"t", "v", "y"});
  const Record sp = load_record(path, {"t", "v", "y"}, false, 1000);
  ASSERT_FALSE(mem.spilled());
  ASSERT_TRUE(sp.spilled());
  ASSERT_EQ(mem.gap_rows().size(), 2u);
  EXPECT_EQ(sp.gap_rows(), mem.gap_rows());
  EXPECT_TRUE(same_bits(sp.dt_s, mem.dt_s));
  EXPECT_TRUE(same_bits(sp.sampling.median_dt, mem.sampling.median_dt));
  EXPECT_TRUE(same_bits(sp.sampling.max_jitter, mem.sampling.max_jitter));
  for (const ModelKind m : {ModelKind::deadzone_deadband, ModelKind::input_deadzone, ModelKind::linear,
                            ModelKind::output_deadzone, ModelKind::coupled_carts}) {
    SettingsSources src;
    src.model = m;
    std::vector<std::vector<double>> trace_mem, trace_sp;
    const auto run = [&](const Record& r, std::vector<std::vector<double>>& trace) {
      ArrayEstimateOptions o;
      o.sampling = &r.sampling;
      o.outputs = false;
      o.on_step = [&](const TraceRow& row) {
        if (row.k % 97 != 0) return;  // a sample of the trace
        std::vector<double> x{static_cast<double>(row.k), row.y, row.yhat, row.ysim};
        x.insert(x.end(), row.params.begin(), row.params.end());
        trace.push_back(std::move(x));
      };
      return estimate_record(src, r.columns(), o);
    };
    const ArrayEstimate a = run(mem, trace_mem), b = run(sp, trace_sp);
    EXPECT_EQ(a.json, b.json) << to_string(m);
    ASSERT_EQ(trace_mem.size(), trace_sp.size());
    bool same = true;
    for (std::size_t i = 0; i < trace_mem.size(); ++i)
      for (std::size_t j = 0; j < trace_mem[i].size(); ++j) same = same && same_bits(trace_mem[i][j], trace_sp[i][j]);
    EXPECT_TRUE(same) << to_string(m);
    // and from the arrays, as Python's lash.estimate calls it
    ArrayEstimateOptions o;
    o.outputs = false;
    const ArrayEstimate c = estimate_arrays(src, mem.t(), mem.v(), mem.y(), o);
    EXPECT_EQ(c.json, a.json) << to_string(m);
  }
}

}  // namespace
}  // namespace lash
