// Unit tests of the HIL nodes: frame layout against hand-packed bytes, sequence-counter
// bookkeeping, the closed-loop simulation against a hand-written discrete loop, faults.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lash/hil/bench_layout.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/hil/simulate.hpp"

using namespace lash;
using namespace lash::hil;

namespace {

can::Frame recorded_dto() {
  can::Frame f;
  f.id = 0x7E1;
  f.len = 8;
  const std::uint8_t bytes[8] = {0xFF, 0x00, 0x00, 0x21, 0x07, 0x5A, 0x00, 0x03};
  for (int i = 0; i < 8; ++i) f.data[static_cast<std::size_t>(i)] = bytes[i];
  return f;
}

ControllerConfig controller(double dt_s) {
  ControllerConfig c;
  c.pid.dt_s = dt_s;
  c.pid.gains.kp = 1.2;
  c.pid.gains.ki_per_s = 12.0;
  c.pid.gains.kd_s = 0.004;
  return c;
}

MasterConfig master_config(double dt_s) {
  MasterConfig m;
  m.controller = controller(dt_s);
  m.reference.kind = Waveform::square;
  m.reference.amplitude = 400.0;
  m.reference.offset = 900.0;
  m.reference.frequency_rad_s = std::numbers::pi;
  m.log_capacity = 4096;
  return m;
}

SlaveConfig slave_config(double dt_s) {
  SlaveConfig s;
  s.plant.dt_s = dt_s;
  s.plant.seed = 7;
  s.dto_reply = {recorded_dto()};
  s.log_capacity = 4096;
  return s;
}

}  // namespace

TEST(HilLayout, CommandBytesByHand) {
  BenchLayout L;
  CommandMsg c;
  c.solenoid_a_mA = 1234.56;  // raw round(12345.6) = 12346 = 0x303A
  c.solenoid_b_mA = 0.0;
  c.restrictor_mA = 2.0;      // raw 20 = 0x0014
  c.counter = 0xBEEF;
  const can::Frame f = L.pack_command(c);
  EXPECT_EQ(f.id, 0x100u);
  EXPECT_EQ(f.len, 8);
  const std::uint8_t want[8] = {0x3A, 0x30, 0x00, 0x00, 0x14, 0x00, 0xEF, 0xBE};
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(f.data[i], want[i]) << i;
  const CommandMsg back = L.unpack_command(f);
  EXPECT_DOUBLE_EQ(back.solenoid_a_mA, 12346 * 0.1);
  EXPECT_EQ(back.counter, 0xBEEF);
  // Clamping: negative → 0, beyond 16 bits → 65535.
  c.solenoid_a_mA = -5.0;
  EXPECT_EQ(L.unpack_command(L.pack_command(c)).solenoid_a_mA, 0.0);
  c.solenoid_a_mA = 1e9;  // clamped to the DBC range [0|2000] mA
  EXPECT_DOUBLE_EQ(L.unpack_command(L.pack_command(c)).solenoid_a_mA, 2000.0);
}

TEST(HilLayout, SensorBytesAndSpecScaling) {
  BenchLayout L;
  // SPEC B1: 1000 kPa → duty 1000/48.82 + 5.98 = 26.46332… % → raw round(26.46332…·655.35) = 17343.
  const std::uint16_t raw = encode_pressure_raw(1000.0);
  EXPECT_EQ(raw, 17343);
  SensorMsg s{raw, 0, 513};
  const can::Frame f = L.pack_sensors(s);
  EXPECT_EQ(f.id, 0x200u);
  EXPECT_EQ(f.len, 6);
  const std::uint8_t want[6] = {0xBF, 0x43, 0x00, 0x00, 0x01, 0x02};
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(f.data[i], want[i]) << i;
  EXPECT_EQ(L.unpack_sensors(f).counter, 513);
}

TEST(HilLayout, MotorolaFieldByHand) {
  // 12-bit big-endian field with MSB at bit 7: occupies byte 0 and the high nibble of byte 1.
  BitField b{7, 12, 1.0, 0.0, 0.0, /*intel=*/false};
  can::Frame f;
  f.len = 8;
  b.put(f, 0xABC);
  EXPECT_EQ(f.data[0], 0xAB);
  EXPECT_EQ(f.data[1], 0xC0);
  EXPECT_EQ(b.get(f), 0xABCu);
}

TEST(HilLayout, ShippedDbcMatchesBuiltInLayout) {
  const BenchLayout d = BenchLayout::from_dbc(std::string(LASH_SOURCE_DIR) + "/config/hydraulic_bench.dbc");
  const BenchLayout b;
  EXPECT_EQ(d.command_id, b.command_id);
  EXPECT_EQ(d.sensors_id, b.sensors_id);
  EXPECT_EQ(d.cro_id, b.cro_id);
  EXPECT_EQ(d.dto_id, b.dto_id);
  EXPECT_EQ(d.command_len, 8);
  EXPECT_EQ(d.sensors_len, 6);
  CommandMsg c{1234.5, 0, 0, 77};
  SensorMsg s{17343, 0, 9};
  EXPECT_TRUE(can::same_content(d.pack_command(c), b.pack_command(c)));
  EXPECT_TRUE(can::same_content(d.pack_sensors(s), b.pack_sensors(s)));
  EXPECT_TRUE(can::same_content(d.pack_connect(3), b.pack_connect(3)));
}

TEST(HilLayout, CcpConnect) {
  BenchLayout L;
  const can::Frame cro = L.pack_connect(5);
  EXPECT_EQ(cro.id, 0x7E0u);
  EXPECT_EQ(cro.data[0], 0x01);
  EXPECT_EQ(cro.data[1], 5);
  EXPECT_TRUE(L.is_connect(cro));
  EXPECT_TRUE(L.is_connect_ack(recorded_dto()));
  can::Frame nack = recorded_dto();
  nack.data[1] = 0x30;  // CCP error code "access denied"-like: not a positive reply
  EXPECT_FALSE(L.is_connect_ack(nack));
}

TEST(HilSeq, LateLostDuplicate) {
  SeqTracker t;
  EXPECT_TRUE(t.on_frame(10));
  t.end_step();
  t.end_step();             // a step without a frame
  EXPECT_TRUE(t.on_frame(11));
  EXPECT_TRUE(t.on_frame(12));  // two frames in one step: 11 was late
  t.end_step();
  EXPECT_TRUE(t.on_frame(15));  // 13, 14 lost
  EXPECT_FALSE(t.on_frame(15)); // duplicate
  t.end_step();
  EXPECT_TRUE(t.on_frame(65535 - 0));  // jump backwards: resync (restarted peer)
  t.end_step();
  EXPECT_TRUE(t.on_frame(0));  // wrap-around 65535 → 0 is the next frame
  t.end_step();
  EXPECT_EQ(t.received, 7u);
  EXPECT_EQ(t.late, 2u);  // 11, and the duplicate 15 in the same step
  EXPECT_EQ(t.lost, 2u);
  EXPECT_EQ(t.duplicates, 1u);
  EXPECT_EQ(t.resyncs, 1u);
}

// The simulation through the nodes and the bus equals a discrete loop written out by hand
// with the same blocks: y(k) = measure(); i(k) = C(r(k), y(k)); apply(q(i(k))), q = the
// bus's 0.1 mA current quantisation. Bit for bit.
TEST(HilSimulate, EqualsHandWrittenDiscreteLoop) {
  const double T = 0.005;
  const std::size_t N = 1000;
  BenchLayout L;
  const SimulationResult sim = simulate_bench(L, master_config(T), slave_config(T), N);
  ASSERT_EQ(sim.master.size(), N + 1);
  EXPECT_EQ(sim.master[0].state, MasterState::connecting);

  PilotValveParams pp = slave_config(T).plant;
  PilotValvePlant plant(pp);
  ClosedLoopDiscrete ctl(controller(T));
  Signal ref(master_config(T).reference, T);
  for (std::size_t k = 0; k < N; ++k) {
    const double y = plant.measure();
    const double y_seen = decode_pressure_raw(plant.last_raw());
    const double r = ref.next();
    const double i = ctl.step(r, y_seen);
    plant.apply(L.quantize_current(i));
    const MasterStepLog& m = sim.master[k + 1];
    ASSERT_EQ(m.control_step, static_cast<std::int64_t>(k));
    ASSERT_EQ(m.state, MasterState::running);
    ASSERT_TRUE(m.sensor_fresh);
    ASSERT_EQ(m.measured_kPa, y_seen) << k;
    ASSERT_EQ(m.reference_kPa, r) << k;
    ASSERT_EQ(m.current_mA, i) << k;
    ASSERT_EQ(sim.slave[k].measured_kPa, y) << k;
  }
  // The loop tracks: the last 0.2 s of the high half-period are within 4σ of 1300 kPa.
  double worst = 0.0;
  for (std::size_t k = 0; k < N; ++k) {
    const double t = static_cast<double>(k) * T;
    if (t > 0.8 && t < 1.0) worst = std::max(worst, std::abs(sim.master[k + 1].measured_kPa - 1300.0));
  }
  EXPECT_LT(worst, 4 * 7.28);
}

TEST(HilMaster, SafeStateAfterThreeMissedPeriodsAndResume) {
  const double T = 0.005;
  BenchLayout L;
  MasterConfig mc = master_config(T);
  MasterNode master(L, mc);
  SlaveNode slave(L, slave_config(T));
  MemLink link;
  master.step(link.a(), 0.0);
  ASSERT_TRUE(slave.wait_connect(link.b(), std::chrono::nanoseconds(0)));
  std::uint32_t k = 0;
  for (; k < 200; ++k) {
    slave.step(link.b(), 0);
    master.step(link.a(), 0);
  }
  ASSERT_EQ(master.state(), MasterState::running);
  ASSERT_GT(master.log().back().current_mA, 0.0);
  // The slave falls silent: two held periods, then 0 mA at the third.
  for (int miss = 1; miss <= 3; ++miss) {
    master.step(link.a(), 0);
    const auto& l = master.log().back();
    if (miss < 3) {
      EXPECT_EQ(l.state, MasterState::running);
      EXPECT_GT(l.current_mA, 0.0);
    } else {
      EXPECT_EQ(l.state, MasterState::fault);
      EXPECT_EQ(l.current_mA, 0.0);
    }
  }
  ASSERT_EQ(master.events().back().kind, MasterEventKind::sensor_timeout);
  // In fault the master keeps asking for CONNECT; a restarted slave answers and control resumes.
  SlaveNode restarted(L, slave_config(T));
  bool connected = false;
  for (int i = 0; i < 30 && !connected; ++i) {
    master.step(link.a(), 0);
    EXPECT_EQ(master.log().back().current_mA, 0.0);
    connected = restarted.wait_connect(link.b(), std::chrono::nanoseconds(0));
  }
  ASSERT_TRUE(connected);
  restarted.step(link.b(), 0);
  master.step(link.a(), 0);
  EXPECT_EQ(master.state(), MasterState::running);
  EXPECT_EQ(master.events().back().kind, MasterEventKind::sensor_resumed);
  EXPECT_EQ(master.log().back().sensor_counter, 0);
}

TEST(HilMaster, DtoTimeoutFails) {
  const double T = 0.005;
  BenchLayout L;
  MasterConfig mc = master_config(T);
  mc.dto_timeout_s = 0.05;
  MasterNode master(L, mc);
  MemLink link;
  bool ok = true;
  int steps = 0;
  for (; steps < 100 && ok; ++steps) ok = master.step(link.a(), steps * T);
  EXPECT_FALSE(ok);
  EXPECT_EQ(master.state(), MasterState::failed);
  EXPECT_EQ(steps, 11);  // CRO at t = 0; failed at t = 0.05 s (step 10)
  EXPECT_EQ(master.events().back().kind, MasterEventKind::dto_timeout);
}

#include "lash/control/step_metrics.hpp"
#include "lash/hil/report.hpp"

TEST(HilReport, StepResponseByHand) {
  // Rise: z crosses 0.9 between t=1 (0.5) and t=2 (1.2): 1 + 0.4/0.7. Overshoot 20 %.
  // Settling: last out of band at t=2 (1.2), back in at t=3 (0.95): edge 1.1 crossed at 2 + 0.1/0.25.
  const std::vector<double> t{0, 1, 2, 3, 4}, y{0, 0.5, 1.2, 0.95, 1.0};
  const StepMetrics r = step_metrics(t, y, 0.0, 0.0, 1.0);
  EXPECT_NEAR(r.rise_s, 1.0 + 0.4 / 0.7, 1e-12);
  EXPECT_NEAR(r.overshoot_pct, 20.0, 1e-9);
  EXPECT_NEAR(r.settling_s, 2.4, 1e-12);
  // Downward step 10 -> 0 mirrors it.
  std::vector<double> yd;
  for (double v : y) yd.push_back(10.0 - 10.0 * v);
  const StepMetrics d = step_metrics(t, yd, 0.0, 10.0, 0.0);
  EXPECT_NEAR(d.rise_s, r.rise_s, 1e-12);
  EXPECT_NEAR(d.overshoot_pct, 20.0, 1e-9);
  EXPECT_NEAR(d.settling_s, 2.4, 1e-12);
}

TEST(HilReport, FirstOrderStepIsTauLn10) {
  // y = 1 − exp(−t/τ): 90 % rise = 10 % settling = τ ln 10, no overshoot.
  const double tau = 0.1, dt = 1e-4;
  std::vector<double> t, y;
  for (int k = 0; k <= 10000; ++k) {
    t.push_back(1.0 + k * dt);
    y.push_back(1.0 - std::exp(-k * dt / tau));
  }
  const StepMetrics r = step_metrics(t, y, 1.0, 0.0, 1.0);
  EXPECT_NEAR(r.rise_s, tau * std::log(10.0), 1e-6);
  EXPECT_NEAR(r.settling_s, tau * std::log(10.0), 1e-6);
  EXPECT_EQ(r.overshoot_pct, 0.0);
}

TEST(HilReport, FindStepSkipsShortLevels) {
  // 0.1 s at 0, 1 s at 500, then 1500 for 3 s: the first step held >= 0.5 s is 500 -> 1500 at t = 1.1 s,
  // window capped at 2 s.
  std::vector<double> r;
  for (int k = 0; k < 10; ++k) r.push_back(0);
  for (int k = 0; k < 100; ++k) r.push_back(500);
  for (int k = 0; k < 300; ++k) r.push_back(1500);
  const auto w = find_step(r, 0.01);
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->begin, 110u);
  EXPECT_EQ(w->end, 310u);
  EXPECT_DOUBLE_EQ(w->y0, 500);
  EXPECT_DOUBLE_EQ(w->y1, 1500);
  EXPECT_NEAR(w->t_step_s, 1.1, 1e-12);
  EXPECT_FALSE(find_step(std::vector<double>(50, 3.0), 0.01).has_value());
}
