// Unit tests of the HIL nodes: frame layout against hand-packed bytes, sequence-counter
// bookkeeping, the closed-loop simulation against a hand-written discrete loop, faults.
#include <gtest/gtest.h>
#include <algorithm>

#include <cmath>
#include <numbers>

#include "lash/hil/bench_layout.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/hil/schedule.hpp"
#include "recorded_dto.hpp"

using namespace lash;
using namespace lash::hil;

namespace {

using test::recorded_dto;

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
  c.counter = 0xBEEF;          // an 8-bit alive counter on the bus: 0xEF
  const can::Frame f = L.pack_command(c);
  EXPECT_EQ(f.id, 0x100u);
  EXPECT_EQ(f.len, 8);
  // Byte 7: CRC-8 SAE J1850 of 00 01 3A 30 00 00 14 00 EF = 0xB6 (python3-crcmod,
  // mkCrcFun(0x11D, initCrc=0, rev=False, xorOut=0xFF), and a bit-by-bit implementation).
  const std::uint8_t want[8] = {0x3A, 0x30, 0x00, 0x00, 0x14, 0x00, 0xEF, 0xB6};
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(f.data[i], want[i]) << i;
  const CommandMsg back = L.unpack_command(f);
  EXPECT_DOUBLE_EQ(back.solenoid_a_mA, 12346 * 0.1);
  EXPECT_EQ(back.counter, 0xEF);
  EXPECT_FALSE(L.check_command(f).has_value());
  // Clamping: negative → 0, beyond 16 bits → 65535.
  c.solenoid_a_mA = -5.0;
  EXPECT_EQ(L.unpack_command(L.pack_command(c)).solenoid_a_mA, 0.0);
  c.solenoid_a_mA = 1e9;  // clamped to the DBC range [0|2000] mA
  EXPECT_DOUBLE_EQ(L.unpack_command(L.pack_command(c)).solenoid_a_mA, 2000.0);
}

TEST(HilLayout, SensorBytesAndSpecScaling) {
  BenchLayout L;
  // docs/method.md §B1: 1000 kPa → duty 1000/48.82 + 5.98 = 26.46332… % → raw round(26.46332…·655.35) = 17343.
  const std::uint16_t raw = encode_pressure_raw(1000.0);
  EXPECT_EQ(raw, 17343);
  SensorMsg s{raw, 0, 513};
  const can::Frame f = L.pack_sensors(s);
  EXPECT_EQ(f.id, 0x200u);
  EXPECT_EQ(f.len, 8);
  // Byte 6 reserved; byte 7: CRC-8 SAE J1850 of 00 02 BF 43 00 00 01 02 00 = 0x64 (python3-crcmod).
  const std::uint8_t want[8] = {0xBF, 0x43, 0x00, 0x00, 0x01, 0x02, 0x00, 0x64};
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(f.data[i], want[i]) << i;
  EXPECT_EQ(L.unpack_sensors(f).counter, 513);
  EXPECT_FALSE(L.check_sensors(f).has_value());
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
  EXPECT_EQ(d.sensors_len, 8);
  EXPECT_EQ(d.command_counter_bits(), 8u);
  EXPECT_EQ(d.sensor_counter_bits(), 16u);
  // The DBC's ranges: [0|2000] mA at 0.1 mA/bit → raw 0..20000; duty [5|95] % at 100/65535 %/bit
  // → raw ceil(5·655.35 = 3276.75) = 3277 .. floor(95·655.35 = 62258.25) = 62258.
  for (const BenchLayout* l : {&d, &b}) {
    EXPECT_TRUE(l->checks.solenoid_a.in_range(20000));
    EXPECT_FALSE(l->checks.solenoid_a.in_range(20001));
    EXPECT_TRUE(l->checks.pilot.in_range(3277));
    EXPECT_FALSE(l->checks.pilot.in_range(3276));
    EXPECT_TRUE(l->checks.pilot.in_range(62258));
    EXPECT_FALSE(l->checks.pilot.in_range(62259));
    EXPECT_TRUE(l->checks.supply.in_range(0));
    EXPECT_TRUE(l->checks.command_counter.in_range(255));
  }
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

TEST(HilSeq, LateLostRepeatedWrongSequenceResync) {
  SeqTracker t;  // 16 bit, window 1..10, resync after 2 consecutive counters
  EXPECT_TRUE(t.on_counter(10));
  t.end_step();
  t.end_step();                   // a step without a frame
  EXPECT_TRUE(t.on_counter(11));
  EXPECT_TRUE(t.on_counter(12));  // two frames in one step: 11 was late
  t.end_step();
  EXPECT_TRUE(t.on_counter(15));  // 13, 14 lost
  EXPECT_FALSE(t.on_counter(15)); // repeated
  t.end_step();
  EXPECT_FALSE(t.on_counter(26)); // 15 + 11: outside the window
  EXPECT_FALSE(t.on_counter(300));
  EXPECT_TRUE(t.on_counter(16));  // the real sequence goes on
  EXPECT_FALSE(t.on_counter(4000));
  EXPECT_TRUE(t.on_counter(4001)); // second consecutive counter of a new sequence: resync
  t.end_step();
  EXPECT_TRUE(t.on_counter(4002));
  t.end_step();
  EXPECT_EQ(t.received, 0u);  // counted by the node for every frame with the identifier
  EXPECT_EQ(t.accepted, 7u);
  EXPECT_EQ(t.late, 2u);  // 11 (before 12); 16 (before 4001 in the same step)
  EXPECT_EQ(t.lost, 2u);
  EXPECT_EQ(t.drops[Drop::repeated], 1u);
  EXPECT_EQ(t.drops[Drop::sequence], 3u);
  EXPECT_EQ(t.resyncs, 1u);
  EXPECT_EQ(t.extended, 4002u);
}

TEST(HilSeq, EightBitWrapAndExtendedCounter) {
  SeqTracker t;
  t.bits = 8;
  EXPECT_TRUE(t.on_counter(250));
  for (std::uint16_t c = 251; c < 262; ++c) EXPECT_TRUE(t.on_counter(static_cast<std::uint16_t>(c & 0xFF)));
  EXPECT_EQ(t.last, 5);
  EXPECT_EQ(t.extended, 261u);  // unwrapped across 255 → 0
  EXPECT_FALSE(t.on_counter(5 + 200));  // 200 ahead: wrong sequence
  EXPECT_TRUE(t.on_counter(5 + 3));     // 6, 7 lost
  EXPECT_EQ(t.lost, 2u);
  EXPECT_EQ(t.extended, 264u);
  // A receiver stalled for 115 frames (frames 265..379 never seen): 380 = 124 mod 256 is a wrong
  // sequence (dropped), 381 = 125 re-synchronises. The unwrapped counter goes on numbering the
  // sender's frames (381), not the wire's 8-bit value (125).
  EXPECT_FALSE(t.on_counter(380 & 0xFF));
  EXPECT_TRUE(t.on_counter(381 & 0xFF));
  EXPECT_EQ(t.resyncs, 1u);
  EXPECT_EQ(t.extended, 381u);
  EXPECT_TRUE(t.on_counter(382 & 0xFF));
  EXPECT_EQ(t.extended, 382u);
}

// The simulation through the nodes and the bus equals a discrete loop written out by hand
// with the same blocks: y(k) = measure(); i(k) = C(r(k), y(k)); apply(q(i(k))), q = the
// bus's 0.1 mA current quantisation. Bit for bit.
TEST(HilSimulate, EqualsHandWrittenDiscreteLoop) {
  const double T = 0.005;
  const std::size_t N = 1000;
  BenchLayout L;
  const SimulationResult sim = simulate_bench(L, master_config(T), slave_config(T), ideal_schedule(N));
  ASSERT_EQ(sim.master.size(), N + 1);
  EXPECT_EQ(sim.master[0].state, MasterState::startup);

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

// --scenario nodes against a hand-written loop: the E4 rig with a drift at control step 200, the
// PID + feedforward + adaptive deadzone compensator, the bus by hand (negative currents on
// solenoid B, 0.1 mA steps; the pressure difference + 2000 kPa as the sensor code).
TEST(HilSimulate, ScenarioEqualsHandWrittenLoopWithDriftAndBothSolenoids) {
  const double T = 0.005;
  const std::size_t N = 1200;
  BenchLayout L;
  RigPlant plant;
  plant.seed = 7;
  rigs::PilotValveRigParams drifted = plant.params;
  drifted.deadzone_right_mA = 380.0;
  plant.drift.push_back({200, 0, plant.params, drifted});
  CompensatedLaw law;
  law.pid.dt_s = T;
  law.pid.gains.kp = 0.5;
  law.pid.gains.ki_per_s = 10.0;
  law.pid.anti_windup = AntiWindup::clamp;
  law.pid.output_min = -2000.0;
  law.pid.output_max = 2000.0;
  law.feedforward = 0.465;
  law.compensation.mode = CompensationMode::adaptive;
  law.compensation.nominal = DeadzoneInverseParams::from_deadzone(288.0, 1.0);
  law.compensation.estimator.model = ModelKind::input_deadzone;
  law.compensation.estimator.dt_s = T;
  law.compensation.estimator.guess_right = 432.0;
  law.compensation.estimator.guess_left = -444.0;
  MasterConfig mc = master_config(T);
  mc.reference = SignalSpec{};
  mc.reference.kind = Waveform::sine;
  mc.reference.amplitude = 600.0;
  mc.reference.frequency_rad_s = 2.0 * 3.141592653589793;
  mc.law = law;
  SlaveConfig sc = slave_config(T);
  sc.rig = plant;
  const SimulationResult sim = simulate_bench(L, mc, sc, ideal_schedule(N));
  ASSERT_EQ(sim.master.size(), N + 1);

  rigs::PilotValveRig rig(plant.params, T, plant.seed);
  Pid pid(law.pid);
  DeadzoneCompensator comp(law.compensation);
  Signal ref(mc.reference, T);
  double applied = 0.0;  // slave step 0 runs before any command
  bool negative = false;
  for (std::size_t k = 0; k < N; ++k) {
    if (k == 201) rig.set_params(drifted);  // slave step 201 applies control step 200's command
    const std::uint16_t raw = encode_pressure_raw(rig.step(applied) + 2000.0);
    const double y = decode_pressure_raw(raw) - 2000.0;
    const double r = ref.next();
    double i = comp.command(pid.step(r - y) + law.feedforward * r);
    i = std::clamp(i, law.command_min, law.command_max);
    comp.observe(i, y, true);
    negative = negative || i < -300.0;
    applied = i >= 0 ? L.quantize_current(i) : -L.quantize_current(-i);
    const MasterStepLog& m = sim.master[k + 1];
    ASSERT_EQ(m.state, MasterState::running) << k;
    ASSERT_EQ(m.measured_kPa, y) << k;
    ASSERT_EQ(m.current_mA, i) << k;
    ASSERT_EQ(sim.slave[k].pressure_kPa, rig.true_pressure_kPa()) << k;
    ASSERT_EQ(m.inverse_right_mA, comp.inverse().params().offset_right) << k;
  }
  EXPECT_TRUE(negative);  // solenoid B was used
  EXPECT_EQ(sim.compensation.updates, comp.updates());
  EXPECT_TRUE(sim.compensation.on);
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
  // The slave falls silent: two held periods, then the safe state (0 mA) at the third.
  for (int miss = 1; miss <= 3; ++miss) {
    master.step(link.a(), 0);
    const auto& l = master.log().back();
    if (miss < 3) {
      EXPECT_EQ(l.state, MasterState::running);
      EXPECT_GT(l.current_mA, 0.0);
    } else {
      EXPECT_EQ(l.state, MasterState::safe);
      EXPECT_EQ(l.current_mA, 0.0);
    }
  }
  ASSERT_EQ(master.events().back().kind, MasterEventKind::sensor_timeout);
  EXPECT_EQ(master.events().back().from, MasterState::running);
  // In the safe state the master keeps asking for CONNECT; a restarted slave answers. Its
  // counter starts again at 0: the first frame is a wrong sequence (dropped), the second
  // re-synchronises, and recovery_frames = 5 good steps in a row bring control back.
  SlaveNode restarted(L, slave_config(T));
  bool connected = false;
  for (int i = 0; i < 30 && !connected; ++i) {
    master.step(link.a(), 0);
    EXPECT_EQ(master.log().back().current_mA, 0.0);
    connected = restarted.wait_connect(link.b(), std::chrono::nanoseconds(0));
  }
  ASSERT_TRUE(connected);
  const auto resyncs = master.sensors().resyncs;
  for (int i = 1; i <= 6; ++i) {
    restarted.step(link.b(), 0);
    master.step(link.a(), 0);
    const auto& l = master.log().back();
    if (i < 6) {
      EXPECT_EQ(l.state, MasterState::safe) << i;
      EXPECT_EQ(l.current_mA, 0.0) << i;
    } else {
      EXPECT_EQ(l.state, MasterState::running);
    }
  }
  EXPECT_EQ(master.sensors().resyncs, resyncs + 1);
  EXPECT_EQ(master.events().back().kind, MasterEventKind::input_resumed);
  EXPECT_EQ(master.log().back().sensor_counter, 5);
  EXPECT_EQ(master.log().back().integrator_mA, 0.0);  // forward Euler after a reset: I(0) = 0
}

// A slave slow to start: the master waits several steps for the DTO. Those steps are not missed
// sensor periods: at the connection the master is in `connected`, not in the safe state, and a
// replay of its schedule (which starts at the connection) agrees. The timeout then counts 3
// periods from the connection (docs/hil.md).
TEST(HilMaster, SensorTimeoutCountsFromTheConnection) {
  const double T = 0.005;
  BenchLayout L;
  MasterNode master(L, master_config(T));
  SlaveNode slave(L, slave_config(T));
  MemLink link;
  for (int i = 0; i < 5; ++i) master.step(link.a(), 0);  // CRO sent, no answer yet (5 > 3 periods)
  ASSERT_EQ(master.state(), MasterState::startup);
  ASSERT_TRUE(slave.wait_connect(link.b(), std::chrono::nanoseconds(0)));
  master.step(link.a(), 0);  // the DTO: connected, no sensor frame yet
  EXPECT_EQ(master.state(), MasterState::connected);
  for (int miss = 1; miss <= 2; ++miss) {  // periods after the connection without a sensor frame
    master.step(link.a(), 0);
    EXPECT_EQ(master.state(), MasterState::connected) << miss;
  }
  master.step(link.a(), 0);  // the 3rd: the timeout
  EXPECT_EQ(master.state(), MasterState::safe);
  EXPECT_EQ(master.events().back().kind, MasterEventKind::sensor_timeout);
}

namespace {

/// A command frame with the given raw SolenoidA code and counter, CRC right unless told.
can::Frame forged_command(const BenchLayout& L, std::uint64_t raw_a, std::uint8_t counter, bool good_crc = true) {
  can::Frame f;
  f.id = L.command_id;
  f.len = L.command_len;
  L.solenoid_a.put(f, raw_a);
  L.command_counter.put(f, counter);
  L.command_crc.put(f, BenchLayout::e2e_crc(f, L.command_crc) ^ (good_crc ? 0 : 0x5A));
  return f;
}

}  // namespace

TEST(HilE2E, Crc8SaeJ1850CheckValues) {
  auto crc = [](std::initializer_list<std::uint8_t> b) {
    return Crc8SaeJ1850::compute(std::span<const std::uint8_t>(b.begin(), b.size()));
  };
  // The catalogue check value (reveng "CRC-8/SAE-J1850": check=0x4b) ...
  EXPECT_EQ(crc({'1', '2', '3', '4', '5', '6', '7', '8', '9'}), 0x4B);
  // ... and AUTOSAR SWS CRC Library's table for Crc_CalculateCRC8 (also python3-crcmod).
  EXPECT_EQ(crc({0x00, 0x00, 0x00, 0x00}), 0x59);
  EXPECT_EQ(crc({0xF2, 0x01, 0x83}), 0x37);
  EXPECT_EQ(crc({0x0F, 0xAA, 0x00, 0x55}), 0x79);
  EXPECT_EQ(crc({0x00, 0xFF, 0x55, 0x11}), 0xB8);
  EXPECT_EQ(crc({0x33, 0x22, 0x55, 0xAA, 0xBB, 0xCC, 0xDD, 0xEE, 0xFF}), 0xCB);
  EXPECT_EQ(crc({0x92, 0x6B, 0x55}), 0x8C);
  EXPECT_EQ(crc({0xFF, 0xFF, 0xFF, 0xFF}), 0x74);
}

TEST(HilE2E, EachCheckCatchesItsFault) {
  BenchLayout L;
  const can::Frame good = forged_command(L, 12345, 7);
  EXPECT_FALSE(L.check_command(good).has_value());
  can::Frame f = good;
  f.len = 7;
  EXPECT_EQ(L.check_command(f), Drop::dlc);
  f = good;
  f.remote = true;
  EXPECT_EQ(L.check_command(f), Drop::dlc);
  for (std::size_t bit = 0; bit < 64; ++bit) {  // every single-bit error is caught by the CRC
    f = good;
    f.data[bit / 8] = static_cast<std::uint8_t>(f.data[bit / 8] ^ (1u << (bit % 8)));
    EXPECT_EQ(L.check_command(f), Drop::crc) << bit;
  }
  f = good;
  f.id = L.sensors_id;  // the data ID is in the CRC: a frame moved to another identifier fails
  EXPECT_EQ(BenchLayout::e2e_crc(f, L.command_crc) == good.data[7], false);
  EXPECT_EQ(L.check_command(forged_command(L, 20000, 7)), std::nullopt);
  EXPECT_EQ(L.check_command(forged_command(L, 20001, 7)), Drop::range);  // 2000.1 mA
  EXPECT_EQ(L.check_command(forged_command(L, 61430, 7)), Drop::range);  // 6143 mA (issue 15)
  can::Frame s = L.pack_sensors({3276, 0, 1});                           // duty 4.9998 %
  EXPECT_EQ(L.check_sensors(s), Drop::range);
  s = L.pack_sensors({3277, 0, 1});
  EXPECT_EQ(L.check_sensors(s), std::nullopt);
}

// Forged command frames (out of range with a right CRC, wrong CRCs, wrong counters) never
// reach the valve: the slave drops and counts them, ramps the current to 0 mA at 20 mA per
// step (4000 mA/s · 5 ms), sits in the safe state, and takes commands again after 5 good steps.
TEST(HilSlave, ForgedCommandsAreDroppedAndRampToSafe) {
  const double T = 0.005;
  BenchLayout L;
  SlaveNode slave(L, slave_config(T));
  MemLink link;
  link.a().send(L.pack_connect(0));
  ASSERT_TRUE(slave.wait_connect(link.b(), std::chrono::nanoseconds(0)));
  std::uint8_t c = 0;
  for (int k = 0; k < 10; ++k) {
    link.a().send(forged_command(L, 10000, c++));  // 1000 mA
    slave.step(link.b(), k * T);
  }
  ASSERT_EQ(slave.state(), SlaveState::running);
  EXPECT_EQ(slave.log().back().current_mA, 1000.0);
  // Step 10: a 6143 mA command with a right CRC and the next counter, then garbage.
  link.a().send(forged_command(L, 61430, c));
  link.a().send(forged_command(L, 10000, c, false));
  link.a().send(forged_command(L, 10000, static_cast<std::uint8_t>(c + 100)));
  slave.step(link.b(), 10 * T);
  EXPECT_EQ(slave.state(), SlaveState::degraded);
  EXPECT_EQ(slave.log().back().current_mA, 980.0);
  EXPECT_EQ(slave.log().back().dropped, 3);
  const auto& d = slave.commands().drops;
  EXPECT_EQ(d[Drop::range], 1u);
  EXPECT_EQ(d[Drop::crc], 1u);
  EXPECT_EQ(d[Drop::sequence], 1u);
  // Forged frames keep coming (with good ones in between): the ramp goes on to 0 mA.
  double prev = 980.0;
  int k = 11;
  for (; slave.state() == SlaveState::degraded; ++k) {
    link.a().send(forged_command(L, 10000, c++));
    link.a().send(forged_command(L, 65535, c));
    slave.step(link.b(), k * T);
    const double i = slave.log().back().current_mA;
    EXPECT_EQ(i, std::max(0.0, prev - 20.0)) << k;
    prev = i;
  }
  EXPECT_EQ(k, 11 + 49);  // 980 mA / 20 mA per step
  EXPECT_EQ(slave.state(), SlaveState::safe);
  EXPECT_EQ(slave.events().back().kind, NodeEventKind::ramp_done);
  // Good commands only: 4 steps stay at 0 mA, the 5th applies the command.
  for (int g = 1; g <= 5; ++g, ++k) {
    link.a().send(forged_command(L, 15000, c++));
    slave.step(link.b(), k * T);
    EXPECT_EQ(slave.log().back().current_mA, g < 5 ? 0.0 : 1500.0) << g;
  }
  EXPECT_EQ(slave.state(), SlaveState::running);
  EXPECT_EQ(slave.events().back().kind, NodeEventKind::input_resumed);
  for (const auto& l : slave.log()) EXPECT_TRUE(l.current_mA >= 0.0 && l.current_mA <= 2000.0);
  // Stale commands: held for 2 periods, degraded (ramp) at the 3rd.
  for (int miss = 1; miss <= 3; ++miss, ++k) slave.step(link.b(), k * T);
  EXPECT_EQ(slave.state(), SlaveState::degraded);
  EXPECT_EQ(slave.events().back().kind, NodeEventKind::input_stale);
  EXPECT_EQ(slave.log().back().current_mA, 1480.0);
}

// Garbage sensor frames: the master freezes its PID (the integrator holds its value), ramps
// its command to 0 mA at 20 mA per step and enters the safe state; when the garbage stops it
// resumes after 5 good steps with a reset PID and tracks again.
TEST(HilMaster, ImplausibleSensorsFreezeIntegratorRampAndRecover) {
  const double T = 0.005;
  BenchLayout L;
  MasterConfig mc = master_config(T);
  mc.reference.kind = Waveform::constant;
  mc.reference.amplitude = 1000.0;
  mc.reference.offset = 0.0;
  MasterNode master(L, mc);
  SlaveNode slave(L, slave_config(T));
  MemLink link;
  master.step(link.a(), 0.0);
  ASSERT_TRUE(slave.wait_connect(link.b(), std::chrono::nanoseconds(0)));
  for (int k = 0; k < 400; ++k) {
    slave.step(link.b(), 0);
    master.step(link.a(), 0);
  }
  ASSERT_EQ(master.state(), MasterState::running);
  const double i0 = master.log().back().current_mA, integ0 = master.log().back().integrator_mA;
  ASSERT_GT(i0, 300.0);
  ASSERT_NE(integ0, 0.0);
  // Garbage: a wrong DLC and a payload with a bad CRC next to every real frame.
  double prev = i0;
  std::size_t garbage_steps = 0;
  for (; master.state() != MasterState::safe; ++garbage_steps) {
    can::Frame g;
    g.id = L.sensors_id;
    g.len = static_cast<std::uint8_t>(garbage_steps % 2 ? 3 : 8);
    for (std::size_t b = 0; b < 8; ++b) g.data[b] = static_cast<std::uint8_t>(37 * garbage_steps + 11 * b);
    slave.step(link.b(), 0);
    link.b().send(g);
    master.step(link.a(), 0);
    const auto& l = master.log().back();
    EXPECT_EQ(l.integrator_mA, integ0);  // frozen
    EXPECT_EQ(l.current_mA, std::max(0.0, prev - 20.0));
    EXPECT_GE(l.dropped, 1);
    prev = l.current_mA;
    ASSERT_LT(garbage_steps, 200u);
  }
  EXPECT_EQ(garbage_steps, static_cast<std::size_t>(std::ceil(i0 / 20.0)));
  EXPECT_EQ(master.events().back().kind, NodeEventKind::ramp_done);
  EXPECT_EQ(master.sensors().drops.total(), garbage_steps);
  // The garbage stops: 4 more safe steps at 0 mA, control from the 5th good step on.
  for (int g = 1; g <= 5; ++g) {
    slave.step(link.b(), 0);
    master.step(link.a(), 0);
    EXPECT_EQ(master.log().back().state, g < 5 ? MasterState::safe : MasterState::running) << g;
  }
  EXPECT_EQ(master.events().back().kind, NodeEventKind::input_resumed);
  for (int k = 0; k < 200; ++k) {
    slave.step(link.b(), 0);
    master.step(link.a(), 0);
  }
  EXPECT_NEAR(master.log().back().measured_kPa, 1000.0, 50.0);
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

// Random frames with the command's identifier (seeded): random DLCs and payloads, half of
// them with a CRC fixed up so that the range and counter checks are reached, a quarter with
// the next counter. Whatever arrives, the slave drives 0..2000 mA at every step, every
// frame is either accepted or dropped with a reason, and nothing implausible is applied:
// every accepted value is in the DBC range.
TEST(HilSlave, RandomFramesNeverDriveOutsideTheRange) {
  const double T = 0.005;
  BenchLayout L;
  SlaveConfig sc = slave_config(T);
  sc.log_capacity = 20000;
  SlaveNode slave(L, sc);
  MemLink link;
  link.a().send(L.pack_connect(0));
  ASSERT_TRUE(slave.wait_connect(link.b(), std::chrono::nanoseconds(0)));
  std::uint64_t x = 0x9E3779B97F4A7C15ull;  // splitmix64
  auto rnd = [&x]() {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  std::uint8_t next = 0;
  std::uint64_t sent = 0;
  for (int k = 0; k < 20000; ++k) {
    const int n = static_cast<int>(rnd() % 4);
    for (int j = 0; j < n; ++j) {
      can::Frame f;
      f.id = L.command_id;
      const std::uint64_t r = rnd();
      f.len = static_cast<std::uint8_t>(r % 16 < 12 ? 8 : r % 9);
      const std::uint64_t payload = rnd();
      for (std::size_t b = 0; b < 8; ++b) f.data[b] = static_cast<std::uint8_t>(payload >> (8 * b));
      if ((r >> 8) % 4 == 0) L.command_counter.put(f, next);
      if ((r >> 12) % 2 == 0) L.command_crc.put(f, BenchLayout::e2e_crc(f, L.command_crc));
      if ((r >> 16) % 4 == 0)  // a plausible frame: in range, the next counter
        f = L.pack_command({static_cast<double>((r >> 20) % 20001) * 0.1, 0.0, 0.0, next++});
      link.a().send(f);
      ++sent;
    }
    slave.step(link.b(), k * T);
  }
  const auto& c = slave.commands();
  EXPECT_EQ(c.received, sent);
  EXPECT_EQ(c.accepted + c.drops.total(), sent);
  EXPECT_GT(c.accepted, 100u);
  for (std::size_t i = 0; i < kDropReasons; ++i) EXPECT_GT(c.drops.n[i], 0u) << to_string(static_cast<Drop>(i));
  bool ran = false;
  for (const auto& l : slave.log()) {
    ASSERT_TRUE(l.current_mA >= 0.0 && l.current_mA <= 2000.0) << l.step;
    ran = ran || l.state == SlaveState::running;
  }
  EXPECT_TRUE(ran);
}
