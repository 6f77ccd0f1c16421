// The plant chain: timing, side selection, plant files, and the thesis's
// §1.3.3.3 observations on the six orders of DZ, G and DB.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "lash/io/error.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"

using namespace lash;

namespace {
std::string cfg(const std::string& name) { return std::string(LASH_SOURCE_DIR) + "/config/plants/" + name; }
}  // namespace

TEST(Plant, OnlyTheLinearPartDelays) {
  std::vector<Block> b;
  b.emplace_back(Deadzone({-100.0, 200.0}));
  b.emplace_back(FirstOrder(PerSide<FirstOrderParams>::both({0.0, 1.0})));
  b.emplace_back(Deadband(PerSide<double>::both(10.0)));
  Plant p(std::move(b), 0.01);
  // v = 300: u = 100 at once; w(k) = u(k−1) → 0 then 100; deadband acts the same sample: 100 − 10 = 90.
  EXPECT_EQ(p.step(300.0), 0.0);
  EXPECT_EQ(p.signals()[0], 100.0);
  EXPECT_EQ(p.step(300.0), 90.0);
  EXPECT_EQ(p.signals()[1], 100.0);
}

TEST(Plant, SideFromSignOfPreviousPlantInput) {
  // Right b1 = 1, left b1 = 2, a1 = 0, behind a deadzone: the side follows v(k−1), not u.
  std::vector<Block> b;
  b.emplace_back(Deadzone({-1.0, 1.0}));
  b.emplace_back(FirstOrder({{0.0, 1.0}, {0.0, 2.0}}));
  Plant p(std::move(b), 1.0);
  EXPECT_EQ(p.step(5.0), 0.0);    // k=0: v(−1) = 0 → right; u(−1) = 0
  EXPECT_EQ(p.step(-5.0), 4.0);   // v(0) = 5 ≥ 0 → right: 1 · u(0) = 1 · 4
  EXPECT_EQ(p.step(-0.5), -8.0);  // v(1) = −5 → left: 2 · u(1) = 2 · (−4)
  EXPECT_EQ(p.step(0.0), 0.0);    // v(2) = −0.5 → left: 2 · u(2) = 2 · 0
  EXPECT_EQ(p.step(0.0), 0.0);    // v(3) = 0 → right
}

TEST(Plant, ResetReturnsToZeroState) {
  Plant p = load_plant(cfg("thesis_eq34.toml"));
  std::vector<double> a, b;
  for (int k = 0; k < 500; ++k) a.push_back(p.step(600.0 * std::sin(0.005 * k)));
  p.reset();
  for (int k = 0; k < 500; ++k) b.push_back(p.step(600.0 * std::sin(0.005 * k)));
  EXPECT_EQ(a, b);
}

TEST(PlantFile, Eq34FileMatchesHandBuiltChain) {
  Plant file = load_plant(cfg("thesis_eq34.toml"));
  std::vector<Block> b;
  b.emplace_back(Deadzone({-300.0, 200.0}));
  b.emplace_back(FirstOrder({{-0.96, 0.1}, {-0.94, 0.15}}));
  b.emplace_back(Deadband({30.0, 50.0}));
  Plant hand(std::move(b), 0.005);
  EXPECT_EQ(file.dt_s(), 0.005);
  for (int k = 0; k < 4000; ++k) {
    const double v = 600.0 * std::sin(0.005 * k);
    ASSERT_EQ(file.step(v), hand.step(v)) << "k = " << k;
  }
}

TEST(Simulate, SampleCountAndTime) {
  Plant p = load_plant(cfg("thesis_eq34.toml"));
  SimulationSpec s;
  s.duration_s = 200.0;
  s.input.amplitude = 600.0;
  auto tr = simulate(p, s);
  EXPECT_EQ(tr.samples(), 40000u);
  EXPECT_EQ(tr.col("t")[39999], 39999 * 0.005);  // t_k = k·T computed, not accumulated
  EXPECT_EQ(tr.col("y"), tr.col("y_true"));     // no noise requested
}

TEST(Simulate, NoiseHasRequestedVariance) {
  Plant p = load_plant(cfg("thesis_eq34.toml"));
  SimulationSpec s;
  s.duration_s = 200.0;
  s.input.amplitude = 600.0;
  s.noise_variance = 200.0;
  s.seed = 3;
  auto tr = simulate(p, s);
  double s1 = 0, s2 = 0;
  const std::size_t n = tr.samples();
  const double nd = static_cast<double>(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double e = tr.col("y")[k] - tr.col("y_true")[k];
    s1 += e;
    s2 += e * e;
  }
  EXPECT_NEAR(s2 / nd - (s1 / nd) * (s1 / nd), 200.0, 200.0 * 0.03);  // ±3 % with 40000 samples
}

// §1.3.3.3: level the output settles to while v = 600 sin(t) passes through the
// nonlinearities (descending through the deadzone [−300, 200]), and how it gets there.
struct OrderCase {
  const char* file;
  double level;      // hand-derived: DB after DZ holds d = 100 (×K = 2.5 if G follows); DB before DZ → 0
  bool asymptotic;   // DZ before G → approached asymptotically; G before DZ → reached in one step
  double v_exit;     // input level at which the settled phase ends (hand-derived per order)
};

class SixOrders : public ::testing::TestWithParam<OrderCase> {};

TEST_P(SixOrders, SettleLevelAndApproach) {
  const auto c = GetParam();
  Plant p = load_plant(cfg(c.file));
  SimulationSpec s;
  s.input.amplitude = 600.0;
  s.input.frequency_rad_s = 1.0;
  s.duration_s = 4.0;
  auto tr = simulate(p, s);
  const auto& t = tr.col("t");
  const auto& y = tr.col("y");
  // Window: from the moment v falls below c_r = 200 (t = π − asin(1/3)) until it falls below
  // v_exit: c_l = −300, or −400 for DB→DZ→G where the deadband output v + d must first pass c_l.
  const double t0 = std::numbers::pi - std::asin(1.0 / 3.0);
  const double t1 = std::numbers::pi + std::asin(-c.v_exit / 600.0);
  std::size_t k0 = 0, k1 = 0;
  for (std::size_t k = 0; k < tr.samples(); ++k) {
    if (t[k] <= t0) k0 = k;
    if (t[k] <= t1) k1 = k;
  }
  const double y_end = y[k1];
  if (c.asymptotic) {
    // Strictly monotone approach, never reached exactly, within 0.5 % of the level at the end.
    for (std::size_t k = k0 + 2; k <= k1; ++k) {
      ASSERT_LT(y[k], y[k - 1]) << c.file << " k = " << k;
      ASSERT_NE(y[k], c.level);
    }
    EXPECT_NEAR(y_end, c.level, 0.5 + 0.005 * std::abs(c.level)) << c.file;
  } else {
    // Reached exactly in one step from more than 1 away, then held exactly.
    std::size_t hit = 0;
    for (std::size_t k = k0; k <= k1; ++k)
      if (y[k] == c.level) {
        hit = k;
        break;
      }
    ASSERT_GT(hit, k0) << c.file << ": level never reached exactly";
    EXPECT_GT(std::abs(y[hit - 1] - c.level), 1.0) << c.file;
    EXPECT_GT(hit + 50, hit);
    for (std::size_t k = hit; k < hit + 50; ++k) EXPECT_EQ(y[k], c.level) << c.file << " k = " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(Thesis13333, SixOrders,
                         ::testing::Values(OrderCase{"fig1_12_dz_g_db.toml", 100.0, true, -300.0},
                                           OrderCase{"fig1_14_dz_db_g.toml", 250.0, true, -300.0},
                                           OrderCase{"fig1_16_g_dz_db.toml", 100.0, false, -300.0},
                                           OrderCase{"fig1_18_g_db_dz.toml", 0.0, false, -300.0},
                                           OrderCase{"fig1_20_db_g_dz.toml", 0.0, false, -300.0},
                                           OrderCase{"fig1_22_db_dz_g.toml", 0.0, true, -400.0}),
                         [](const auto& param_info) {
                           std::string n = param_info.param.file;
                           return n.substr(0, n.find('.'));
                         });

// Plant::run against step(): the same bits (memcmp of the doubles), chunk boundaries anywhere.
namespace {

/// Plants of every shape step() compiles (config/plants/*.toml: the six orders of DZ, G, DB and
/// eq. 34) plus chains of one, two and repeated kinds and two generic chains (step per block kind).
std::vector<std::pair<std::string, Plant>> run_plants() {
  std::vector<std::pair<std::string, Plant>> out;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(std::string(LASH_SOURCE_DIR) + "/config/plants"))
    if (e.path().extension() == ".toml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) out.emplace_back(f.filename().string(), load_plant(f.string()));
  const Deadzone dz({-300.0, 200.0});
  const Deadband db({30.0, 50.0});
  const FirstOrder g({{-0.96, 0.1}, {-0.94, 0.15}});
  auto add = [&](const std::string& name, std::vector<Block> b) { out.emplace_back(name, Plant(std::move(b), 0.005)); };
  add("dz", {dz});
  add("db", {db});
  add("g", {g});
  add("g_db", {g, db});
  add("db_db", {db, Deadband({5.0, 10.0})});
  add("g_g_g", {g, FirstOrder({{0.5, 1.0}, {-0.5, 2.0}}), g});
  add("dz_g_db_sat (generic)", {dz, g, db, Saturation(-20.0, 25.0)});
  add("delay_ma_diff (generic)", {Delay(3), MovingAverage(4), BackwardDifference(0.005)});
  return out;
}

/// A random input over both sides and through the deadzone, with exact zeros and held signs.
std::vector<double> random_input(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<double> v(n);
  double held = 0.0;
  for (auto& x : v) {
    const std::uint64_t r = rng();
    const double u = static_cast<double>(r >> 11) * 0x1.0p-53;  // [0, 1)
    switch (r & 7) {
      case 0: x = 0.0; break;
      case 1: x = held; break;
      default: x = held = 1600.0 * u - 800.0;
    }
  }
  return v;
}

bool same_bits(std::span<const double> a, std::span<const double> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace

TEST(PlantRun, SameBitsAsStepInAnyChunks) {
  const std::size_t n = 10000;
  const std::vector<double> v = random_input(n, 28);
  for (auto& [name, proto] : run_plants()) {
    SCOPED_TRACE(name);
    const std::size_t nb = proto.blocks().size();
    // the reference: step() sample by sample, the blocks' outputs after each
    Plant ref = proto;
    ref.reset();
    std::vector<double> y_ref(n), x_ref(n * nb);
    for (std::size_t k = 0; k < n; ++k) {
      y_ref[k] = ref.step(v[k]);
      std::copy(ref.signals().begin(), ref.signals().end(), x_ref.begin() + static_cast<std::ptrdiff_t>(k * nb));
    }
    // run() in chunks of different sizes (an empty one too), keeping the blocks' outputs
    Plant p = proto;
    p.reset();
    std::vector<double> y(n), x(n * nb);
    const std::size_t sizes[] = {1, 2, 3, 0, 7, 4096, 1000, 1};
    std::size_t k0 = 0;
    for (std::size_t c = 0; k0 < n; ++c) {
      const std::size_t m = std::min(c < std::size(sizes) ? sizes[c] : std::size_t{4096}, n - k0);
      p.run(std::span(v).subspan(k0, m), std::span(y).subspan(k0, m), std::span(x).subspan(k0 * nb, m * nb));
      k0 += m;
      if (k0 > 0) {  // signals() after a run: the last sample's, as after step()
        ASSERT_TRUE(same_bits(p.signals(), std::span(x_ref).subspan((k0 - 1) * nb, nb))) << "after sample " << k0 - 1;
      }
    }
    EXPECT_TRUE(same_bits(y, y_ref));
    EXPECT_TRUE(same_bits(x, x_ref));
    // one run() over the record without the blocks' outputs, in place (y = v)
    Plant q = proto;
    q.reset();
    std::vector<double> w = v;
    q.run(w, w);
    EXPECT_TRUE(same_bits(w, y_ref));
    EXPECT_TRUE(same_bits(q.signals(), std::span(x_ref).subspan((n - 1) * nb, nb)));
    // the state after run() is step()'s: both go on alike
    for (std::size_t k = 0; k < 300; ++k) {
      const double vk = 700.0 * std::sin(0.01 * static_cast<double>(k));
      const double a = ref.step(vk), b = q.step(vk), c = p.step(vk);
      ASSERT_TRUE(same_bits(std::span(&a, 1), std::span(&b, 1)) && same_bits(std::span(&a, 1), std::span(&c, 1)))
          << "k = " << k;
    }
  }
}

TEST(PlantRun, RefusesMismatchedSpans) {
  Plant p = load_plant(cfg("thesis_eq34.toml"));
  std::vector<double> v(10), y(9), x(29);
  EXPECT_THROW(p.run(v, y), std::invalid_argument);
  y.resize(10);
  EXPECT_THROW(p.run(v, y, x), std::invalid_argument);
  // nothing was stepped: the plant is still at its zero state
  Plant fresh = load_plant(cfg("thesis_eq34.toml"));
  for (int k = 0; k < 50; ++k) ASSERT_EQ(p.step(600.0), fresh.step(600.0));
}

TEST(Simulate, RecordInChunksSameBitsAsStep) {
  // simulate() runs the plant chunk by chunk (Plant::run); its columns against step() per sample
  // over a record of several chunks (10000 samples = 2 chunks of 4096 + 1808).
  const std::vector<double> v = random_input(10000, 34);
  for (auto& [name, proto] : run_plants()) {
    SCOPED_TRACE(name);
    Plant p = proto, ref = proto;
    ref.reset();
    const SimulationTrace tr = simulate(p, v, 0.0, 1);
    const std::size_t nb = proto.blocks().size();
    std::vector<double> y(v.size());
    std::vector<std::vector<double>> x(nb, std::vector<double>(v.size()));
    for (std::size_t k = 0; k < v.size(); ++k) {
      y[k] = ref.step(v[k]);
      for (std::size_t i = 0; i < nb; ++i) x[i][k] = ref.signals()[i];
    }
    EXPECT_TRUE(same_bits(tr.col("y_true"), y));
    for (std::size_t i = 0; i < nb; ++i) EXPECT_TRUE(same_bits(tr.cols[4 + i], x[i])) << tr.names[4 + i];
  }
}
