// MAT-file reading (libmatio) against files written by scipy.io.savemat, and the EMPS recipe
// (docs/emps.md) against the benchmark authors' Coulomb forces (+20.14 N / −20.63 N).
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <toml++/toml.h>

#include "lash/identify/data.hpp"
#include "lash/identify/estimators.hpp"
#include "lash/io/error.hpp"
#include "lash/io/mat.hpp"
#include "lash/io/toml_util.hpp"

namespace fs = std::filesystem;

namespace {

/// Writes a MAT file with scipy (the independent writer); returns false if python/scipy is absent.
bool write_with_scipy(const fs::path& file, const std::string& format) {
  const fs::path script = file.string() + ".py";
  std::ofstream(script) << "import numpy as np, scipy.io as sio\n"
                           "t = np.arange(5) * 0.5\n"
                           "sio.savemat(r'" << file.string() << "', {'t': t.reshape(-1, 1), 'v': np.array([[1.0, -2.0, 3.5, 0.25, 8.0]]),\n"
                           "  'k': np.array([[2.5]]), 'm': np.ones((2, 3)), 'u8': np.array([0, 5, 5, 0, 5], dtype=np.uint8)},\n"
                           "  format='" << format << "')\n";
  return std::system(("/usr/bin/python3 " + script.string() + " >/dev/null 2>&1").c_str()) == 0;
}

fs::path temp_dir() {
  fs::path d = fs::temp_directory_path() / ("lash_mat_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                           "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::create_directories(d);
  return d;
}

/// ../shared/data/emps relative to the repository root (LASH_EMPS_DIR overrides, e.g. for a worktree).
fs::path emps_dir() {
  if (const char* d = std::getenv("LASH_EMPS_DIR")) return d;
  return fs::path(LASH_SOURCE_DIR) / ".." / "shared" / "data" / "emps";
}

}  // namespace

TEST(MatReader, ReadsScipyV5AndV4) {
  for (const char* format : {"5", "4"}) {
    const fs::path d = temp_dir();
    const fs::path f = d / (std::string("rec_v") + format + ".mat");
    if (!write_with_scipy(f, format)) GTEST_SKIP() << "SKIPPED: /usr/bin/python3 with scipy not available";
    const lash::Table t = lash::read_mat(f, {"t", "v", "k"});
    ASSERT_EQ(t.rows(), 5u);
    EXPECT_EQ(t.names[1], "v");
    EXPECT_DOUBLE_EQ(t["t"][4], 2.0);
    EXPECT_DOUBLE_EQ(t["v"][2], 3.5);
    EXPECT_DOUBLE_EQ(t["k"][3], 2.5);  // a 1x1 variable is repeated on every row
    if (std::string(format) == "5") {
      const auto u = lash::read_mat(f, {"u8"});
      EXPECT_DOUBLE_EQ(u.cols[0][1], 5.0);
    }
    const auto names = lash::mat_variable_names(f);
    EXPECT_NE(std::find(names.begin(), names.end(), "m"), names.end());
    fs::remove_all(d);
  }
}

TEST(MatReader, ColumnExpressions) {
  const fs::path d = temp_dir();
  const fs::path f = d / "rec.mat";
  if (!write_with_scipy(f, "5")) GTEST_SKIP() << "SKIPPED: /usr/bin/python3 with scipy not available";
  const auto t = lash::read_mat(f, {"k*v", "diff(v)/0.5", "2*k*t"});
  // k*v = 2.5·[1, −2, 3.5, 0.25, 8]; diff(v)/0.5 = [0, −6, 11, −6.5, 15.5]; 2·k·t = 5·t.
  EXPECT_DOUBLE_EQ(t.cols[0][1], -5.0);
  EXPECT_DOUBLE_EQ(t.cols[1][0], 0.0);
  EXPECT_DOUBLE_EQ(t.cols[1][2], 11.0);
  EXPECT_DOUBLE_EQ(t.cols[1][4], 15.5);
  EXPECT_DOUBLE_EQ(t.cols[2][3], 7.5);
  EXPECT_EQ(t.names[0], "k*v");
  fs::remove_all(d);
}

TEST(MatReader, ErrorsNameFileAndVariable) {
  const fs::path d = temp_dir();
  const fs::path f = d / "rec.mat";
  if (!write_with_scipy(f, "5")) GTEST_SKIP() << "SKIPPED: /usr/bin/python3 with scipy not available";
  try {
    lash::read_mat(f, {"t", "force"});
    FAIL() << "no error for a missing variable";
  } catch (const lash::InputError& e) {
    EXPECT_EQ(e.field(), "force");
    EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no variable named 'force'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(lash::read_mat(f, {"m"}), lash::InputError);             // a matrix
  EXPECT_THROW(lash::read_mat(f, {"k"}), lash::InputError);             // only scalars
  EXPECT_THROW(lash::read_mat(f, {"t", "sqrt(v)"}), lash::InputError);  // unknown function
  EXPECT_THROW(lash::read_mat(d / "absent.mat", {"t"}), lash::InputError);
  std::ofstream(d / "junk.mat") << "not a mat file";
  EXPECT_THROW(lash::read_mat(d / "junk.mat", {"t"}), lash::InputError);
  // Through the column loader that `lash estimate` uses (MAT chosen by the extension).
  const lash::ColumnData c = lash::load_columns(f, {"t", "v"});
  EXPECT_EQ(c.rows(), 5u);
  EXPECT_THROW(lash::load_columns(f, {"t", "nope"}), lash::InputError);
  fs::remove_all(d);
}

TEST(Emps, FileMatchesItsReadme) {
  const fs::path f = emps_dir() / "DATA_EMPS.mat";
  if (!fs::exists(f)) GTEST_SKIP() << "SKIPPED: EMPS data not found at " << emps_dir() << " (../shared/data/emps)";
  // README: 24 841 samples, T = 1 ms, gtau = 35.15 N/V, kp = 160.18, kv = 243.45.
  const auto t = lash::read_mat(f, {"t", "qm", "vir"});
  EXPECT_EQ(t.rows(), 24841u);
  EXPECT_NEAR((t["t"].back() - t["t"].front()) / 24840.0, 0.001, 1e-6);
  EXPECT_NEAR(lash::read_mat_scalar(f, "gtau"), 35.15, 0.005);
  EXPECT_NEAR(lash::read_mat_scalar(f, "kp"), 160.18, 0.005);
  EXPECT_NEAR(lash::read_mat_scalar(f, "kv"), 243.45, 0.005);
}

namespace {

/// Runs the recipe of config/emps_friction.toml on one record; returns the Coulomb force per side c/K.
std::pair<double, double> emps_coulomb(const fs::path& mat) {
  const fs::path cfg_file = fs::path(LASH_SOURCE_DIR) / "config" / "emps_friction.toml";
  const toml::table root = lash::parse_toml_file(cfg_file);
  lash::TomlTable t(root, cfg_file.string());
  EXPECT_EQ(t.string("model"), "output-deadzone");
  const auto columns = t.strings("columns");
  auto rls = t.table("rls");
  lash::EstimatorConfig e = lash::EstimatorConfig::thesis(lash::ModelKind::output_deadzone, 0.001);
  e.rls.lambda = rls.number("lambda");
  e.rls.p0 = rls.number("p0");
  const auto eta0 = rls.numbers("eta0");
  for (std::size_t i = 0; i < 3; ++i) e.rls.eta0[i] = eta0.at(i);
  const auto rec = lash::read_mat(mat, columns);
  lash::OutputDeadzoneEstimator est(e);
  for (std::size_t k = 0; k < rec.rows(); ++k) est.step(rec.cols[1][k], rec.cols[2][k]);
  auto force = [&](lash::Side s) {
    const auto p = est.params(s);
    EXPECT_TRUE(p.identified);
    return p.c / (p.b1 / (1.0 + p.a1));
  };
  return {force(lash::Side::right), force(lash::Side::left)};
}

}  // namespace

TEST(Emps, CoulombForceWithinFivePercentOnEstimationRecord) {
  const fs::path f = emps_dir() / "DATA_EMPS.mat";
  if (!fs::exists(f)) GTEST_SKIP() << "SKIPPED: EMPS data not found at " << emps_dir() << " (../shared/data/emps)";
  const auto [right, left] = emps_coulomb(f);
  std::printf("DATA_EMPS.mat: Fc+ = %.3f N (authors 20.14), Fc- = %.3f N (authors -20.63)\n", right, left);
  EXPECT_NEAR(right / 20.14, 1.0, 0.05);
  EXPECT_NEAR(left / -20.63, 1.0, 0.05);
}

TEST(Emps, SameSettingsWithinTenPercentOnPulsesRecord) {
  const fs::path f = emps_dir() / "DATA_EMPS_PULSES.mat";
  if (!fs::exists(f)) GTEST_SKIP() << "SKIPPED: EMPS data not found at " << emps_dir() << " (../shared/data/emps)";
  const auto [right, left] = emps_coulomb(f);
  std::printf("DATA_EMPS_PULSES.mat: Fc+ = %.3f N, Fc- = %.3f N (authors on DATA_EMPS: 20.14 / -20.63)\n", right, left);
  EXPECT_NEAR(right / 20.14, 1.0, 0.10);
  EXPECT_NEAR(left / -20.63, 1.0, 0.10);
}
