// CSV/TOML I/O: round-trip number text, error locations, atomic output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <filesystem>
#include <fstream>

#include "lash/io/atomic_file.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/io/line_tail.hpp"
#include "lash/io/numeric.hpp"
#include "lash/io/table.hpp"
#include "lash/plant/plant_file.hpp"

using namespace lash;
namespace fs = std::filesystem;

namespace {
fs::path tmpfile(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("lash_test_io_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST(Csv, RoundTripShortestText) {
  EXPECT_EQ(format_double(0.1), "0.1");
  EXPECT_EQ(format_double(200.0), "200");
  EXPECT_EQ(format_double(-0.96), "-0.96");
  for (double x : {0.1 + 0.2, 1.0 / 3.0, 2.999987500015625, 1e-300, -7.5e17}) {
    double back = 0;
    ASSERT_TRUE(parse_double(format_double(x), back));
    EXPECT_EQ(back, x);
  }
}

TEST(Csv, ReadsAndNamesBadCells) {
  auto ok = tmpfile("ok.csv", "t,v,y\n0,1,2\n0.5,3,4\n");
  auto t = read_csv(ok);
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_EQ(t["y"][1], 4.0);
  try {
    (void)t["nope"];
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "nope");
  }
  auto bad = tmpfile("bad.csv", "t,v,y\n0,1,2\n0.5,abc,4\n");
  try {
    read_csv(bad);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.field(), "v");
  }
  auto nonmono = tmpfile("nm.csv", "t,v\n0,1\n1,1\n1,2\n");
  try {
    require_increasing(read_csv(nonmono), "t");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 4);
  }
  EXPECT_THROW(read_csv(tmpfile("empty.csv", "")), InputError);
  EXPECT_THROW(read_csv(tmpfile("nan.csv", "t\nnan\n")), InputError);
  for (auto p : {ok, bad, nonmono}) fs::remove(p);
}

TEST(Error, OneBaseForEveryErrorAPersonSees) {
  // main's catch-all maps InputError to exit 2 and every other lash::Error to exit 1:
  // the kinds must be told apart by type, and all be caught as lash::Error.
  const InputError in("f.csv", 3, "v", "not a finite number");
  const SystemError sys("fork failed");
  const RunError run("the slave did not start");
  const Error* all[] = {&in, &sys, &run};
  for (const Error* e : all) EXPECT_NE(dynamic_cast<const std::runtime_error*>(e), nullptr);
  EXPECT_EQ(dynamic_cast<const InputError*>(static_cast<const Error*>(&sys)), nullptr);
  EXPECT_EQ(dynamic_cast<const InputError*>(static_cast<const Error*>(&run)), nullptr);
  EXPECT_STREQ(in.what(), "f.csv:3: 'v': not a finite number");
  try {
    throw InputError("f.csv", 3, "v", "bad");
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "f.csv:3: 'v': bad");
  }
}

TEST(Error, BoundedQuotesAtMost200BytesAndCountsTheRest) {
  EXPECT_EQ(lash::bounded("short"), "short");
  EXPECT_EQ(lash::bounded(std::string(200, 'x')), std::string(200, 'x'));  // exactly the bound: unchanged
  // 300 bytes: the first 200, an ellipsis (U+2026, 3 bytes in UTF-8) and the whole count
  EXPECT_EQ(lash::bounded(std::string(300, 'x')), std::string(200, 'x') + "\xE2\x80\xA6 (300 bytes)");
  // never cut inside a character: 199 ASCII bytes then "é" (2 bytes) straddling the bound
  const std::string s = std::string(199, 'a') + "\xC3\xA9" + std::string(50, 'b');
  EXPECT_EQ(lash::bounded(s), std::string(199, 'a') + "\xE2\x80\xA6 (251 bytes)");
}

TEST(Table, StreamGapsIsTheRecordRuleWithTheNominalPeriod) {
  // period 0.25 s (exact in binary): a step of exactly 5 periods (1.25 s) is not a gap, 1.5 s is;
  // the same steps in a record whose median step is 0.25 s give the same gap rows
  const std::vector<double> t{0.0, 0.25, 0.5, 1.75, 2.0, 3.5, 3.75};
  lash::StreamGaps g(0.25);
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (g.gap_before(t[i])) rows.push_back(i);
  EXPECT_EQ(rows, (std::vector<std::size_t>{5}));
  EXPECT_EQ(lash::analyse_sampling(t).gap_rows, rows);
  g.reset();  // a new stream: its first sample is never a gap
  EXPECT_FALSE(g.gap_before(100.0));
  EXPECT_TRUE(g.gap_before(101.5));
}

TEST(AtomicFile, NothingLeftWithoutCommit) {
  const fs::path target = fs::temp_directory_path() / ("lash_atomic_" + std::to_string(::getpid()) + ".csv");
  {
    AtomicFile f(target);
    f.stream() << "half";
  }
  EXPECT_FALSE(fs::exists(target));
  {
    AtomicFile f(target);
    f.stream() << "whole";
    f.commit();
  }
  EXPECT_TRUE(fs::exists(target));
  fs::remove(target);
}

TEST(PlantFile, ErrorsNameLineAndKey) {
  struct Case {
    std::string text;
    int line;
    std::string field;
  };
  const std::vector<Case> cases{
      {"dt = 0.01\n[[blocks]]\nkind = \"deadzone\"\nleft = 5.0\nright = -5.0\n", 4, "blocks[0].left"},
      {"dt = 0.01\n[[blocks]]\nkind = \"gearbox\"\n", 3, "blocks[0].kind"},
      {"dt = -1\n[[blocks]]\nkind = \"deadzone\"\nleft = 0\nright = 0\n", 1, "dt"},
      {"dt = 0.01\n[[blocks]]\nkind = \"deadband\"\nhalf_width = -3\n", 4, "blocks[0].half_width"},
      {"dt = 0.01\n[[blocks]]\nkind = \"deadzone\"\nleft = nan\nright = 1\n", 4, "blocks[0].left"},
      {"dt = 0.01\n[[blocks]]\nkind = \"deadzone\"\nright = 1\n", 2, "blocks[0].left"},
      {"dt = 0.01\n[[blocks]]\nkind = \"linear\"\na1 = -0.9\nb1 = 1\nc1 = 3\n", 6, "blocks[0].c1"},
      {"dt = 0.01\n[[blocks]\n", 2, ""},
  };
  int i = 0;
  for (const auto& c : cases) {
    auto p = tmpfile("plant" + std::to_string(i++) + ".toml", c.text);
    try {
      load_plant(p);
      ADD_FAILURE() << c.text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.line(), c.line) << c.text << " -> " << e.what();
      EXPECT_EQ(e.field(), c.field) << c.text << " -> " << e.what();
      EXPECT_EQ(e.file(), p.string());
    }
    fs::remove(p);
  }
}

TEST(PlantFile, WidthMeansFullWidthAndKTauForm) {
  auto p = tmpfile("w.toml",
                   "dt = 0.01\n[[blocks]]\nkind = \"linear\"\ngain = 2.0\ntau = 0.1\n"
                   "[[blocks]]\nkind = \"backlash\"\nwidth = 20.0\n");
  Plant plant = load_plant(p);
  const auto& g = std::get<FirstOrder>(plant.blocks()[0]);
  EXPECT_DOUBLE_EQ(g.params().right.a1, -std::exp(-0.1));
  EXPECT_EQ(std::get<Deadband>(plant.blocks()[1]).half_width().left, 10.0);
  fs::remove(p);
}

// ---- read_table: the user's files (issue 12 item 6) --------------------------------------

namespace {
// One record, t/v/y with a spare column, written by hand in each dialect.
const std::vector<double> kT{0, 0.01, 0.02, 0.03}, kV{1.5, -2.25, 300, 4e-3}, kY{0.125, 7, -8.5, 9};
}  // namespace

TEST(Table, EveryDialectGivesTheSameColumns) {
  const std::string dialects[] = {
      "t,v,x,y\n0,1.5,9,0.125\n0.01,-2.25,9,7\n0.02,300,9,-8.5\n0.03,4e-3,9,9\n",
      "t;v;x;y\n0;1,5;9;0,125\n0,01;-2,25;9;7\n0,02;300;9;-8,5\n0,03;4e-3;9;9\n",     // decimal comma
      "t;v;x;y\r\n0;1.5;9;0.125\r\n0.01;-2.25;9;7\r\n0.02;300;9;-8.5\r\n0.03;0.004;9;9\r\n",
      "t\tv\tx\ty\n0\t1.5\t9\t0.125\n0.01\t-2.25\t9\t7\n0.02\t300\t9\t-8.5\n0.03\t4e-3\t9\t9\n",
      "\xEF\xBB\xBF" "t,v,x,y\n0,1.5,9,0.125\n0.01,-2.25,9,7\n0.02,300,9,-8.5\n0.03,4e-3,9,9\n",  // BOM
      "# exported by a logger\n  t   v  x   y\n0 1.5 9 0.125\n\n0.01  -2.25 9 7\n# pause\n0.02 300 9 -8.5\n0.03 4e-3 9 9",
      "\"t\",\"v\",\"x\",\"y\"\n0,1.5,9,0.125\n0.01,-2.25,9,+7\n0.02, 300 ,9,-8.5\n0.03,4e-3,9,9\n",
  };
  int k = 0;
  for (const auto& text : dialects) {
    const auto p = tmpfile("dialect" + std::to_string(k++) + ".csv", text);
    TableOptions o;
    o.columns = {"t", "v", "y"};
    const Table t = read_table(p, o);
    SCOPED_TRACE(text);
    ASSERT_EQ(t.names, (std::vector<std::string>{"t", "v", "y"}));
    EXPECT_EQ(t.cols[0], kT);
    EXPECT_EQ(t.cols[1], kV);
    EXPECT_EQ(t.cols[2], kY);
    o.columns = {"0", "1", "3"};  // the same by 0-based index
    const Table u = read_table(p, o);
    EXPECT_EQ(u.cols, t.cols);
    EXPECT_EQ(t.skipped_rows, 0u);
    fs::remove(p);
  }
}

TEST(Table, HeaderlessFileIsReadByIndex) {
  const auto p = tmpfile("nohead.csv", "0 1.5 0.125\n0.01 -2.25 7\n0.02 300 -8.5\n0.03 4e-3 9\n");
  TableOptions o;
  o.columns = {"0", "1", "2"};
  const Table t = read_table(p, o);
  EXPECT_EQ(t.cols[0], kT);
  EXPECT_EQ(t.cols[2], kY);
  EXPECT_EQ(t.line_of_row.front(), 1);
  fs::remove(p);
}

TEST(Table, ChoicesAreCheckedAndOnlyChosenCellsParsed) {
  const auto p = tmpfile("choose.csv", "t,v,note,y\n0,1,abc,2\n0.1,2,def,3\n");
  TableOptions o;
  o.columns = {"t", "v", "y"};
  EXPECT_EQ(read_table(p, o).rows(), 2u);  // the text column is never parsed
  o.columns = {"t", "0", "y"};             // t twice (by name and by index)
  try {
    read_table(p, o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "--columns");
    EXPECT_NE(std::string(e.what()).find("chosen twice"), std::string::npos);
  }
  o.columns = {"t", "v", "7"};
  EXPECT_THROW(read_table(p, o), InputError);
  o.columns = {"t", "note", "y"};
  try {
    read_table(p, o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.field(), "note");
  }
  fs::remove(p);
}

TEST(Table, LineOfEachRowAcrossCommentsBlankAndSkippedLines) {
  // lines: 1 header, 2-3 rows, 4 comment, 5 blank, 6-7 rows, 8 skipped (nan), 9 row
  const auto p = tmpfile("lines.csv", "t,v,y\n0,1,2\n1,1,2\n# note\n\n2,1,2\n3,1,2\n4,nan,2\n5,1,2\n");
  TableOptions o;
  o.columns = {"t", "v", "y"};
  const Table t = read_table(p, o);
  ASSERT_EQ(t.rows(), 5u);
  EXPECT_EQ(t.line_of_row.to_vector(), (std::vector<int>{2, 3, 6, 7, 9}));
  EXPECT_EQ(t.line_of_row[3], 7);
  EXPECT_EQ(t.line_of_row.size(), 5u);
  EXPECT_EQ(t.line_of_row.runs(), 3u);  // 2-3, 6-7, 9: memory by breaks, not by rows
  RowLines m;
  m.assign_consecutive(1000000, 1);  // a MAT file's element indices
  EXPECT_EQ(m[999999], 1000000);
  EXPECT_EQ(m.runs(), 1u);
  fs::remove(p);
}

TEST(Table, NonFiniteRowsAreSkippedAndCountedUnlessStrict) {
  const auto p = tmpfile("nan.csv", "t,v,y\n0,1,2\n0.1,nan,3\n0.2,2,\n0.3,inf,1\n0.4,5,NaN\n0.5,6,7\n");
  TableOptions o;
  o.columns = {"t", "v", "y"};
  const Table t = read_table(p, o);
  EXPECT_EQ(t.skipped_rows, 4u);
  EXPECT_EQ(t.first_skipped_line, 3);
  EXPECT_EQ(t.cols[0], (std::vector<double>{0, 0.5}));
  EXPECT_EQ(t.line_of_row.to_vector(), (std::vector<int>{2, 7}));
  o.strict = true;
  try {
    read_table(p, o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.field(), "v");
  }
  fs::remove(p);
}

TEST(Table, GapsAreFoundAndNotAveragedIntoDt) {
  // 0, 1, 2, 3, then a gap of 10 (> 5 × the median 1), then 14, 15: dt = (15 − 0 − 10)/(6 − 1) = 1.
  const std::vector<double> t{0, 1, 2, 3, 13, 14, 15};
  const Sampling s = analyse_sampling(t);
  EXPECT_EQ(s.median_dt, 1.0);
  EXPECT_EQ(s.gap_rows, (std::vector<std::size_t>{4}));
  EXPECT_DOUBLE_EQ(s.dt, 1.0);
  // Without a gap dt is exactly the span over the steps.
  const std::vector<double> u{0, 0.1, 0.3, 0.4};
  EXPECT_EQ(analyse_sampling(u).dt, 0.4 / 3);
  EXPECT_TRUE(analyse_sampling(u).gap_rows.empty());
  EXPECT_NEAR(analyse_sampling(u).max_jitter, 1.0, 1e-12);  // the 0.2 step against the median 0.1
}

TEST(Table, MedianStepOfLongRecordsIsTheSortedMiddle) {
  // Long records take the selection path of analyse_sampling (no full sort); the median, gaps and
  // jitter must be those of the definition: the sorted steps' middle (mean of the two middles for an
  // even count), gaps above 5 x it, max |step - median| / median computed step by step.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jit(-0.3, 0.3);
  std::uniform_int_distribution<int> coin(0, 1);
  const auto reference = [](const std::vector<double>& t, double& med, double& jitter, std::size_t& gaps) {
    std::vector<double> d;
    for (std::size_t i = 1; i < t.size(); ++i) d.push_back(t[i] - t[i - 1]);
    std::vector<double> s = d;
    std::sort(s.begin(), s.end());
    med = s.size() % 2 ? s[s.size() / 2] : 0.5 * (s[s.size() / 2] + s[s.size() / 2 - 1]);
    jitter = 0.0;
    gaps = 0;
    for (double x : d) {
      if (x > 5.0 * med) ++gaps;
      else jitter = std::max(jitter, std::abs(x - med) / med);
    }
  };
  for (std::size_t n : {40000, 40001, 300000, 300001}) {
    for (int kind = 0; kind < 5; ++kind) {
      std::vector<double> t(n);
      for (std::size_t k = 0; k < n; ++k) {
        const double base = static_cast<double>(k) * 0.005;
        switch (kind) {
          case 0: t[k] = base; break;                                                  // a few step values
          case 1: t[k] = base + 0.005 * jit(rng); break;                               // all steps differ
          case 2: t[k] = k ? t[k - 1] + (coin(rng) ? 0.004 : 0.006) : 0.0; break;      // two values, median at the edge
          case 3: t[k] = k ? t[k - 1] + 0.001 * static_cast<double>(1 + k % 7) : 0.0; break;  // seven values
          default: t[k] = base + (k > n / 3 ? 1.0 : 0.0) + (k > n / 2 ? 2.0 : 0.0); break;   // two gaps
        }
      }
      double med = 0.0, jitter = 0.0;
      std::size_t gaps = 0;
      reference(t, med, jitter, gaps);
      const Sampling s = analyse_sampling(t);
      EXPECT_EQ(s.median_dt, med) << "n " << n << " kind " << kind;
      EXPECT_EQ(s.max_jitter, jitter) << "n " << n << " kind " << kind;
      EXPECT_EQ(s.gap_rows.size(), gaps) << "n " << n << " kind " << kind;
    }
  }
}

// Range limits by hand: int8 holds -128..127, uint64 below 2^64 = 18446744073709551616, and
// a double next to 2^63 (2^63 - 1024 is the largest double below it).
TEST(Numeric, ConversionsAreRangeCheckedFirst) {
  EXPECT_EQ(lash::round_to<std::int8_t>(127.4), std::int8_t{127});
  EXPECT_FALSE(lash::round_to<std::int8_t>(127.5));  // rounds half away from zero, to 128
  EXPECT_EQ(lash::round_to<std::int8_t>(-128.49), std::int8_t{-128});
  EXPECT_FALSE(lash::round_to<std::int8_t>(-128.5));
  EXPECT_FALSE(lash::round_to<std::uint32_t>(-0.6));
  EXPECT_EQ(lash::round_to<std::uint32_t>(-0.4), 0u);
  EXPECT_FALSE(lash::round_to<int>(std::nan("")));
  EXPECT_FALSE(lash::round_to<long>(std::numeric_limits<double>::infinity()));
  EXPECT_FALSE(lash::round_to<std::uint64_t>(18446744073709551616.0));
  EXPECT_EQ(lash::round_to<std::uint64_t>(18446744073709549568.0), 18446744073709549568ull);  // 2^64 - 2048
  EXPECT_FALSE(lash::round_to<std::int64_t>(9223372036854775808.0));                         // 2^63
  EXPECT_EQ(lash::round_to<std::int64_t>(9223372036854774784.0), 9223372036854774784ll);     // 2^63 - 1024
  EXPECT_EQ(lash::ceil_to<std::size_t>(2.000001), 3u);
  EXPECT_EQ(lash::floor_to<int>(-2.5), -3);
  EXPECT_EQ(lash::round_clamped<std::int64_t>(1e300, 0, 100), 100);
  EXPECT_EQ(lash::round_clamped<std::int64_t>(std::nan(""), 0, 100), 0);
  EXPECT_EQ(lash::round_clamped<std::int64_t>(-7.0, 0, 100), 0);
  EXPECT_EQ(lash::round_clamped<std::int64_t>(41.5, 0, 100), 42);
  EXPECT_EQ(lash::steps_or_throw(1.0, 0.005, "--duration"), 200u);
  EXPECT_THROW(lash::steps_or_throw(1e300, 0.005, "--duration"), std::invalid_argument);
  EXPECT_THROW(lash::steps_or_throw(-1.0, 0.005, "--duration"), std::invalid_argument);
  EXPECT_THROW(lash::steps_or_throw(1.0, 0.0, "--duration"), std::invalid_argument);  // inf steps
  try {
    lash::steps_or_throw(std::nan(""), 0.005, "settle_s");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("settle_s: ", 0), 0u) << e.what();
  }
}

namespace {
std::vector<std::string> poll_all(LineTail& t) {
  std::vector<std::string> out;
  t.poll([&](std::string_view l) { out.emplace_back(l); });
  return out;
}
void append(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::app) << s; }
}  // namespace

TEST(LineTail, AppendedInPiecesHandsOverCompleteLinesOnly) {
  const fs::path p = fs::temp_directory_path() / ("lash_test_io_" + std::to_string(::getpid()) + "_tail.csv");
  fs::remove(p);
  LineTail t(p);
  EXPECT_TRUE(poll_all(t).empty());  // no file yet: nothing, no error
  EXPECT_FALSE(t.opened());
  append(p, "step,x\n0,1.");
  EXPECT_EQ(poll_all(t), (std::vector<std::string>{"step,x"}));
  EXPECT_EQ(t.pending_bytes(), 4u);  // "0,1." waits for its '\n'
  EXPECT_TRUE(poll_all(t).empty());
  append(p, "5");
  EXPECT_TRUE(poll_all(t).empty());
  append(p, "\r\n1,2\n2,");
  EXPECT_EQ(poll_all(t), (std::vector<std::string>{"0,1.5", "1,2"}));
  append(p, "3\n");
  EXPECT_EQ(poll_all(t), (std::vector<std::string>{"2,3"}));
  EXPECT_EQ(t.offset(), fs::file_size(p));
  // Replaced by a shorter file (a new run): read from its start again.
  std::ofstream(p, std::ios::trunc) << "a\n";
  EXPECT_EQ(poll_all(t), (std::vector<std::string>{"a"}));
  EXPECT_EQ(t.restarts(), 1u);
  fs::remove(p);
}

TEST(LineTail, BoundedBufferSkipsOverlongLines) {
  const fs::path p = fs::temp_directory_path() / ("lash_test_io_" + std::to_string(::getpid()) + "_tail2.csv");
  fs::remove(p);
  LineTail t(p, 8);
  append(p, "12345678\n");  // exactly max_line: kept
  EXPECT_EQ(poll_all(t), (std::vector<std::string>{"12345678"}));
  append(p, "123456");
  EXPECT_TRUE(poll_all(t).empty());
  append(p, std::string(5000, 'x'));  // grows past 8 bytes in pieces: never held
  EXPECT_TRUE(poll_all(t).empty());
  EXPECT_LE(t.pending_bytes(), 8u);
  append(p, std::string(100000, 'y') + "\nok\n");  // read in 64 KiB chunks: the tail of it skipped too
  EXPECT_EQ(poll_all(t), (std::vector<std::string>{"ok"}));
  EXPECT_EQ(t.overlong(), 1u);
  EXPECT_EQ(t.pending_bytes(), 0u);
  fs::remove(p);
}
