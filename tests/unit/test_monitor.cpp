// The monitor's pieces against hand computations: the Page–Hinkley detector (metrics), the
// signal expressions and the frame checks against a DBC written here.
#include <gtest/gtest.h>

#include <cmath>

#include "lash/can/dbc.hpp"
#include "lash/io/error.hpp"
#include "lash/metrics/page_hinkley.hpp"
#include "lash/monitor/events.hpp"
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
  s.thresholds.push_back({"d_r", -1e9, 40.0});
  monitor::EventDetector d(s);
  std::vector<monitor::Event> ev;
  const auto period = [&](double t, double x) {
    d.update(t, {monitor::ParamValue{"d_r", x, NAN, NAN, true}}, ev);
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

}  // namespace
}  // namespace lash
