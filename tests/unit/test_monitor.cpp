// The monitor's pieces against hand computations: the Page–Hinkley detector (metrics), the
// signal expressions and the frame checks against a DBC written here.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "lash/can/dbc.hpp"
#include "lash/io/error.hpp"
#include "lash/metrics/page_hinkley.hpp"
#include "lash/identify/any_estimator.hpp"
#include "lash/identify/config_sources.hpp"
#include "lash/io/table.hpp"
#include "lash/monitor/events.hpp"
#include "lash/monitor/online.hpp"
#include "lash/monitor/signal_map.hpp"

namespace lash {
namespace {

// δ = 0.5, h = 2, x = 0, 0, 0, 4 (by hand, Basseville & Nikiforov Eq. 2.2.31 with the running mean):
//   k=1..3: x̄ = 0, U = −0.5, −1.0, −1.5 (each a new minimum m), L = 0.5, 1.0, 1.5 (each a new maximum M)
//   k=4:    x̄ = 1, U = −1.5 + (4 − 1 − 0.5) = 1.0, U − m = 2.5 > 2: increase at sample 4,
//           change time after sample 3, mean before = (0 + 0 + 0)/3 = 0; L = 1.5 + 3.5 = 5 (M − L = 0).
TEST(PageHinkley, IncreaseByHand) {
  PageHinkley ph({0.5, 2.0});
  EXPECT_EQ(ph.update(0), PageHinkley::Change::none);
  EXPECT_EQ(ph.update(0), PageHinkley::Change::none);
  EXPECT_EQ(ph.update(0), PageHinkley::Change::none);
  EXPECT_DOUBLE_EQ(ph.up_statistic(), 0.0);
  EXPECT_EQ(ph.update(4), PageHinkley::Change::up);
  EXPECT_DOUBLE_EQ(ph.up_statistic(), 2.5);
  EXPECT_DOUBLE_EQ(ph.down_statistic(), 0.0);
  EXPECT_DOUBLE_EQ(ph.mean(), 1.0);
  EXPECT_DOUBLE_EQ(ph.mean_before(PageHinkley::Change::up), 0.0);
  EXPECT_DOUBLE_EQ(ph.mean_after(PageHinkley::Change::up), 4.0);  // the one sample after the change time
}

// h = 3: at k=4 U − m = 2.5 (no alarm); k=5: x̄ = 8/5 = 1.6, U = 1.0 + (4 − 1.6 − 0.5) = 2.9,
// U − m = 2.9 + 1.5 = 4.4 > 3: increase at sample 5.
TEST(PageHinkley, ThresholdByHand) {
  PageHinkley ph({0.5, 3.0});
  for (double x : {0.0, 0.0, 0.0, 4.0}) EXPECT_EQ(ph.update(x), PageHinkley::Change::none);
  EXPECT_EQ(ph.update(4), PageHinkley::Change::up);
  EXPECT_NEAR(ph.up_statistic(), 4.4, 1e-12);
  EXPECT_DOUBLE_EQ(ph.mean_after(PageHinkley::Change::up), 4.0);  // (4 + 4)/2, samples 4 and 5
}

// x = 0, 0, 0, −4: the mirror image: L = 0.5, 1.0, 1.5, then x̄ = −1, L = 1.5 + (−4 + 1 + 0.5) = −1,
// M − L = 2.5 > 2: decrease; a NaN sample is skipped (count unchanged).
TEST(PageHinkley, DecreaseAndNaN) {
  PageHinkley ph({0.5, 2.0});
  for (double x : {0.0, 0.0, 0.0}) ph.update(x);
  EXPECT_EQ(ph.update(std::nan("")), PageHinkley::Change::none);
  EXPECT_EQ(ph.count(), 3u);
  EXPECT_EQ(ph.update(-4), PageHinkley::Change::down);
  EXPECT_DOUBLE_EQ(ph.down_statistic(), 2.5);
  EXPECT_DOUBLE_EQ(ph.mean_before(PageHinkley::Change::down), 0.0);
  EXPECT_DOUBLE_EQ(ph.mean_after(PageHinkley::Change::down), -4.0);
  ph.reset();
  EXPECT_TRUE(std::isnan(ph.mean_after(PageHinkley::Change::down)));
  EXPECT_EQ(ph.count(), 0u);
  EXPECT_THROW(PageHinkley({-1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(PageHinkley({0.0, 0.0}), std::invalid_argument);
}

// A constant sequence never alarms (U decreases by δ per sample, L increases by δ).
TEST(PageHinkley, ConstantNeverAlarms) {
  PageHinkley ph({0.01, 0.1});
  for (int k = 0; k < 10000; ++k) ASSERT_EQ(ph.update(3.0), PageHinkley::Change::none);
}

constexpr const char* kDbc = R"(VERSION ""
BU_: A B
BO_ 256 Cmd: 8 A
 SG_ CurA : 0|16@1+ (0.1,0) [0|2000] "mA" B
 SG_ CurB : 16|16@1+ (0.1,0) [0|2000] "mA" B
 SG_ Cmd_Counter : 48|8@1+ (1,0) [0|255] "" B
BO_ 512 Sens: 8 B
 SG_ Mux M : 0|8@1+ (1,0) [0|0] "" A
 SG_ P m1 : 8|16@1- (0.5,-10) [0|0] "kPa" A
 SG_ Q m2 : 8|16@1+ (1,0) [0|100] "" A
)";

can::Frame frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes, double t) {
  can::Frame f;
  f.id = id;
  f.len = static_cast<std::uint8_t>(bytes.size());
  std::size_t i = 0;
  for (auto b : bytes) f.data[i++] = b;
  f.timestamp_s = t;
  return f;
}

TEST(MonitorSignals, DifferenceMultiplexAndChecks) {
  const auto db = can::dbc::parse_dbc(kDbc);
  monitor::SignalMap m(db, monitor::parse_signal_expr("Cmd.CurA-Cmd.CurB", "--v"),
                       monitor::parse_signal_expr("Sens.P", "--y"), "x.dbc");
  bool is_y = false, jump = false;
  // CurA raw 3000 (0x0BB8) → 300 mA, CurB raw 1000 (0x03E8) → 100 mA: v = 200 mA by hand
  EXPECT_EQ(m.decode(frame(256, {0xB8, 0x0B, 0xE8, 0x03, 0, 0, 7, 0}, 0.0), is_y, jump), monitor::FrameCheck::ok);
  EXPECT_FALSE(is_y);
  EXPECT_DOUBLE_EQ(m.v(), 200.0);
  EXPECT_TRUE(std::isnan(m.y()));
  // mux 1 selects P: raw 0xFFFE = −2 → −2·0.5 − 10 = −11 kPa
  EXPECT_EQ(m.decode(frame(512, {1, 0xFE, 0xFF, 0, 0, 0, 0, 0}, 0.005), is_y, jump), monitor::FrameCheck::ok);
  EXPECT_TRUE(is_y);
  EXPECT_DOUBLE_EQ(m.y(), -11.0);
  // mux 2 (Q): not y's signal, not a sample
  EXPECT_EQ(m.decode(frame(512, {2, 5, 0, 0, 0, 0, 0, 0}, 0.01), is_y, jump), monitor::FrameCheck::ok);
  EXPECT_FALSE(is_y);
  EXPECT_DOUBLE_EQ(m.y(), -11.0);
  // wrong DLC; CurA raw 20010 (2001 mA > 2000): out of range; neither changes v
  EXPECT_EQ(m.decode(frame(256, {0xB8, 0x0B, 0xE8}, 0.02), is_y, jump), monitor::FrameCheck::bad_dlc);
  EXPECT_EQ(m.decode(frame(256, {0x2A, 0x4E, 0, 0, 0, 0, 8, 0}, 0.02), is_y, jump), monitor::FrameCheck::out_of_range);
  EXPECT_DOUBLE_EQ(m.v(), 200.0);
  // counter 7 → 8 is no jump, 8 → 10 is one
  EXPECT_EQ(m.decode(frame(256, {0, 0, 0, 0, 0, 0, 8, 0}, 0.03), is_y, jump), monitor::FrameCheck::ok);
  EXPECT_FALSE(jump);
  EXPECT_EQ(m.decode(frame(256, {0, 0, 0, 0, 0, 0, 10, 0}, 0.04), is_y, jump), monitor::FrameCheck::ok);
  EXPECT_TRUE(jump);
  EXPECT_EQ(m.decode(frame(0x123, {1}, 0.05), is_y, jump), monitor::FrameCheck::other);
}

TEST(MonitorSignals, UnknownSignalNamesIt) {
  const auto db = can::dbc::parse_dbc(kDbc);
  try {
    monitor::SignalMap m(db, monitor::parse_signal_expr("Cmd.CurC", "--v"), monitor::parse_signal_expr("Sens.P", "--y"),
                         "x.dbc");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("CurC"), std::string::npos);
    EXPECT_EQ(e.field(), "--v");
  }
  EXPECT_THROW(monitor::parse_signal_expr("Cmd", "--v"), InputError);
  EXPECT_THROW(monitor::parse_signal_expr("A.b-C.d-E.f", "--v"), InputError);
}

// Thresholds are edge-triggered: one event on leaving the band, none while outside.
TEST(MonitorEvents, ThresholdOnce) {
  monitor::AlarmSettings s;
  s.drift.enabled = false;
  s.warmup_s = 0.0;
  s.thresholds.push_back({"d_r", -1e9, 40.0});
  monitor::EventDetector d(s);
  std::vector<monitor::Event> ev;
  const auto period = [&](double t, double x) {
    d.update(t, {monitor::ParamValue{"d_r", x, NAN, NAN, true, true}}, ev);
  };
  period(1, 30);
  period(2, 45);
  period(3, 46);
  period(4, 30);
  period(5, 41);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].kind, "threshold");
  EXPECT_DOUBLE_EQ(ev[0].t, 2);
  EXPECT_DOUBLE_EQ(ev[0].before, 30);
  EXPECT_DOUBLE_EQ(ev[0].after, 45);
  EXPECT_DOUBLE_EQ(ev[1].t, 5);
}

// Thresholds are armed warmup_s (8 s, the default) after the first estimate (t0 = 1 here): the
// excursions at 4 and 8 (t - t0 = 3, 7) fire nothing; a value still outside at 9 (t - t0 = 8)
// fires then, with `before` the period before; after that, edge-triggered as above.
TEST(MonitorEvents, ThresholdArmedAfterTheWarmUp) {
  monitor::AlarmSettings s;
  s.drift.enabled = false;
  ASSERT_DOUBLE_EQ(s.warmup_s, 8.0);
  s.thresholds.push_back({"c_r", -1e9, 350.0});
  monitor::EventDetector d(s);
  std::vector<monitor::Event> ev;
  for (const auto& [t, x] : {std::pair{1.0, 280.0}, {4.0, 406.0}, {5.0, 280.0}, {8.0, 400.0}, {9.0, 401.0},
                             {10.0, 402.0}, {11.0, 290.0}, {12.0, 360.0}})
    d.update(t, {monitor::ParamValue{"c_r", x, NAN, NAN, true, true}}, ev);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_DOUBLE_EQ(ev[0].t, 9);
  EXPECT_DOUBLE_EQ(ev[0].before, 400);
  EXPECT_DOUBLE_EQ(ev[0].after, 401);
  EXPECT_DOUBLE_EQ(ev[1].t, 12);
  EXPECT_DOUBLE_EQ(ev[1].before, 290);
}

// A step of c_r from 100 to 132 after 10 periods, δ = 0.03, h = 0.3, warm-up 0 (x = c/100, by hand):
//   periods 1-10: x = 1, x̄ = 1, U = −0.03·k, m = U = −0.3 after period 10.
//   median 1: period 11: x̄ = 11.32/11 = 1.02909, U − m = 1.32 − 1.02909 − 0.03 = 0.26091 (< h);
//             period 12: x̄ = 12.64/12 = 1.05333, U − m = 0.26091 + 0.23667 = 0.49758 > h: alarm at 12.
//   median 3: period 11 sees median(100, 100, 132) = 100 (U − m = 0 at m = −0.33), then 132 from
//             period 12: the same two steps one period later: alarm at 13. median 5: at 14.
TEST(MonitorEvents, DriftMedianDelaysByHand) {
  for (const auto& [median, alarm_t] : {std::pair{std::size_t{1}, 12.0}, {std::size_t{3}, 13.0}, {std::size_t{5}, 14.0}}) {
    monitor::AlarmSettings s;
    s.drift.warmup_s = 0.0;
    s.drift.median = median;
    s.drift.parameters = {"c_r"};
    monitor::EventDetector d(s);
    std::vector<monitor::Event> ev;
    for (int k = 1; k <= 16 && ev.empty(); ++k)
      d.update(k, {monitor::ParamValue{"c_r", k <= 10 ? 100.0 : 132.0, NAN, NAN, true, true}}, ev);
    ASSERT_EQ(ev.size(), 1u) << median;
    EXPECT_EQ(ev[0].kind, "drift");
    EXPECT_DOUBLE_EQ(ev[0].t, alarm_t) << median;
    EXPECT_DOUBLE_EQ(ev[0].before, 100.0) << median;
    EXPECT_DOUBLE_EQ(ev[0].after, 132.0) << median;
  }
}

// The persistent estimator is the estimator `lash estimate` runs, stepped once per sample: with the
// guesses given, no gate and no re-guessing, its state after a record equals an AnyEstimator with the
// settings resolved from the first init_s seconds stepped over the same samples (all but the last,
// held for the gate's look-ahead), bit for bit; with re-guessing on and guesses far inside the
// deadzone, the guesses move out and the edges come within 5 % of the plant's.
struct DeadzoneRecord {
  std::vector<double> t, v, y;
};
DeadzoneRecord deadzone_record(std::size_t n, double c_r, double c_l) {
  DeadzoneRecord r;
  std::uint64_t rng = 12345;
  const auto uniform = [&] {  // a fixed LCG: the same bits on every standard library
    rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(rng >> 11) * 0x1p-53;
  };
  double level = 0.0, y = 0.0, v1 = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (k % 37 == 0) level = -700.0 + 1400.0 * uniform();
    const double dz = v1 > c_r ? v1 - c_r : (v1 < c_l ? v1 - c_l : 0.0);
    y = 0.9 * y + 0.2 * dz + 0.2 * (uniform() - 0.5);
    r.t.push_back(0.005 * static_cast<double>(k));
    r.v.push_back(level);
    r.y.push_back(y);
    v1 = level;
  }
  return r;
}

TEST(MonitorOnline, EqualsTheEstimatorSteppedOnce) {
  const DeadzoneRecord r = deadzone_record(6000, 300.0, -250.0);
  SettingsSources src;
  src.model = ModelKind::input_deadzone;
  src.options = {{"guess-right", "400"}, {"guess-left", "-350"}};
  monitor::OnlineSettings os;
  os.init_s = 5.0;
  os.outlier_gate = 0.0;
  os.reguess.enabled = false;
  monitor::OnlineEstimator on(src, os);
  for (std::size_t k = 0; k < r.t.size(); ++k) on.add(r.t[k], r.v[k], r.y[k], false);
  ASSERT_TRUE(on.ready());
  // the first stretch: t - t0 >= 5 s at sample 1000 (5.000 s), samples 0..1000
  const std::size_t m = 1001;
  const std::span<const double> ts(r.t.data(), m), vs(r.v.data(), m), ys(r.y.data(), m);
  const EstimatorConfig cfg = resolve_settings(src, analyse_sampling(ts).dt, vs, ys).cfg;
  AnyEstimator ref(cfg);
  for (std::size_t k = 0; k + 1 < r.t.size(); ++k) ref.step(r.v[k], r.y[k]);
  const auto snap = on.snapshot(0.0, r.t.back());
  ASSERT_TRUE(snap.has_value());
  EXPECT_EQ(on.samples(), r.t.size() - 1);
  for (const Side s : {Side::right, Side::left}) {
    const SideParams a = (s == Side::right ? snap->report.right : snap->report.left).params, b = ref.params(s);
    EXPECT_EQ(a.a1, b.a1);
    EXPECT_EQ(a.b1, b.b1);
    EXPECT_EQ(a.c, b.c);
    EXPECT_EQ(on.reguesses(s), 0u);
  }
  EXPECT_NEAR(ref.params(Side::right).c, 300.0, 15.0);  // the plant's edges (the estimator converged)
  EXPECT_NEAR(ref.params(Side::left).c, -250.0, 12.5);
}

TEST(MonitorOnline, RefusesModelSwitchingAtConstruction) {
  // model switching needs a whole record (a switching model iterated over it); the online
  // estimator refuses it when made, naming the option, rather than at every stretch it tries
  SettingsSources src;
  src.model = ModelKind::deadzone_deadband;
  src.options = {{"model-switching", "true"}};
  try {
    monitor::OnlineEstimator on(src, monitor::OnlineSettings{});
    ADD_FAILURE() << "model switching was accepted online";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "model-switching");
  }
  src.options.clear();
  EXPECT_NO_THROW(monitor::OnlineEstimator(src, monitor::OnlineSettings{}));
}

TEST(MonitorOnline, ReguessesAGuessInsideTheDeadzone) {
  const DeadzoneRecord r = deadzone_record(12000, 300.0, -250.0);
  SettingsSources src;
  src.model = ModelKind::input_deadzone;
  src.options = {{"guess-right", "100"}, {"guess-left", "-100"}};  // inside [-250, 300]
  monitor::OnlineSettings os;
  os.init_s = 5.0;
  monitor::OnlineEstimator on(src, os);
  for (std::size_t k = 0; k < r.t.size(); ++k) on.add(r.t[k], r.v[k], r.y[k], false);
  const auto snap = on.snapshot(0.0, r.t.back());
  ASSERT_TRUE(snap.has_value());
  EXPECT_GE(on.reguesses(Side::right), 1u);
  EXPECT_GE(on.reguesses(Side::left), 1u);
  EXPECT_GT(on.config()->guess_right, 300.0);
  EXPECT_LT(on.config()->guess_left, -250.0);
  EXPECT_TRUE(snap->report.right.params.identified);
  EXPECT_TRUE(snap->report.left.params.identified);
  EXPECT_NEAR(snap->report.right.params.c, 300.0, 15.0);
  EXPECT_NEAR(snap->report.left.params.c, -250.0, 12.5);
}

}  // namespace
}  // namespace lash
