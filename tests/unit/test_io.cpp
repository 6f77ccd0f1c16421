// CSV/TOML I/O: round-trip number text, error locations, atomic output.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "lash/io/atomic_file.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
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
