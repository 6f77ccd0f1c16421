// The observed-schedule replay (hil/schedule.hpp): a hand-made schedule with a frame used
// twice, a skipped frame, a late command and a dropped frame, against a hand-written discrete
// loop (plant, controller and reference stepped directly, no node code); identities with the
// ideal-schedule simulation; non-causal schedules and bad schedule files refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <unistd.h>

#include "lash/hil/report.hpp"
#include "lash/hil/schedule.hpp"
#include "lash/io/error.hpp"
#include "hil_test_bench.hpp"
#include "recorded_dto.hpp"

using namespace lash;
using namespace lash::hil;

namespace {

using test::recorded_dto;

using test::kT;
using test::master_cfg;
using test::slave_cfg;

/// The bench's closed loop written out over an in-process link (MemLink), independent of the
/// schedule replay: the master's CONNECT step, then each period slave.step(); master.step().
SimulationResult memlink_loop(const BenchLayout& L, std::size_t N) {
  MasterConfig mc = master_cfg();
  mc.log_capacity = N + 1;
  SlaveConfig sc = slave_cfg();
  sc.log_capacity = N;
  MasterNode master(L, mc);
  SlaveNode slave(L, sc);
  MemLink link;
  master.step(link.a(), 0.0);
  EXPECT_TRUE(slave.wait_connect(link.b(), std::chrono::nanoseconds(0)));
  for (std::size_t k = 1; k <= N; ++k) {
    const double t = static_cast<double>(k) * kT;
    slave.step(link.b(), t - 0.5 * kT);
    master.step(link.a(), t);
  }
  SimulationResult r;
  r.master.assign(master.log().begin(), master.log().end());
  r.slave.assign(slave.log().begin(), slave.log().end());
  return r;
}

void expect_same(const SimulationResult& a, const SimulationResult& b) {
  ASSERT_EQ(a.master.size(), b.master.size());
  ASSERT_GE(a.slave.size(), b.slave.size());
  for (std::size_t k = 0; k < a.master.size(); ++k) {
    ASSERT_EQ(a.master[k].control_step, b.master[k].control_step) << k;
    ASSERT_EQ(a.master[k].measured_kPa, b.master[k].measured_kPa) << k;
    ASSERT_EQ(a.master[k].current_mA, b.master[k].current_mA) << k;
    ASSERT_EQ(a.master[k].state, b.master[k].state) << k;
  }
  for (std::size_t s = 0; s < b.slave.size(); ++s) ASSERT_EQ(a.slave[s].pressure_kPa, b.slave[s].pressure_kPa) << s;
}

}  // namespace

TEST(HilSchedule, IdealScheduleEqualsTheLoopOverALink) {
  const std::size_t N = 600;
  BenchLayout L;
  const SimulationResult ideal = simulate_bench(L, master_cfg(), slave_cfg(), ideal_schedule(N));
  const SimulationResult link = memlink_loop(L, N);
  expect_same(ideal, link);
  // The schedule the simulated nodes logged is the ideal one: sensor_seq = control step.
  const FrameSchedule seen = observed_schedule(ideal.master, ideal.slave);
  const FrameSchedule want = ideal_schedule(N);
  ASSERT_EQ(seen.master.size(), N);
  ASSERT_GE(seen.slave.size(), N);
  for (std::size_t k = 0; k < N; ++k) {
    ASSERT_EQ(seen.master[k].seq, want.master[k].seq) << k;
    ASSERT_EQ(seen.slave[k].seq, want.slave[k].seq) << k;
    ASSERT_FALSE(seen.master[k].dropped || seen.slave[k].dropped) << k;
  }
}

// The lazy ideal schedule (O(1) memory) and the streaming form of simulate_bench hand over the
// rows of the loop written out over a link, and the streamed step response equals the one of
// the whole trace (find_step + step_metrics).
TEST(HilSchedule, StreamedSimulationEqualsTheLoopOverALink) {
  const std::size_t N = 600;
  BenchLayout L;
  SimulationResult streamed;
  SimulationSink sink;
  sink.master = [&](const MasterStepLog& l) { streamed.master.push_back(l); };
  sink.slave = [&](const SlaveStepLog& l) { streamed.slave.push_back(l); };
  const SimulationResult r = simulate_bench(L, master_cfg(), slave_cfg(), lazy_ideal_schedule(N), sink);
  EXPECT_TRUE(r.master.empty());
  EXPECT_TRUE(r.slave.empty());
  expect_same(streamed, memlink_loop(L, N));
  std::vector<double> ref, p;
  StepResponseStream stream(kT);
  for (std::size_t m = 0; m < N; ++m) {
    ref.push_back(streamed.master[m + 1].reference_kPa);
    p.push_back(streamed.slave[m].pressure_kPa);
    stream.add(ref.back(), p.back());
  }
  const auto whole = step_response(ref, kT, p);
  const auto part = stream.result();
  ASSERT_TRUE(whole && part);
  EXPECT_EQ(part->window.begin, whole->window.begin);
  EXPECT_EQ(part->window.end, whole->window.end);
  EXPECT_EQ(part->plant.rise_s, whole->plant.rise_s);
  EXPECT_EQ(part->plant.settling_s, whole->plant.settling_s);
  EXPECT_EQ(part->plant.overshoot_pct, whole->plant.overshoot_pct);
}

// A schedule whose slave log ends early (a killed slave) is replayed up to the last control
// step the slave's log can serve.
TEST(HilSchedule, ReplayableStepsEndWhereTheSlaveLogEnds) {
  FrameSchedule s = ideal_schedule(50);
  EXPECT_EQ(replayable_control_steps(s), 50u);
  s.slave.resize(30);  // slave steps 0..29 kept: control step 30 uses the sensor frame of slave step 30
  EXPECT_EQ(replayable_control_steps(s), 30u);
  s.master[29].seq = -1;  // held: still replayable
  EXPECT_EQ(replayable_control_steps(s), 30u);
  BenchLayout L;
  s.master.resize(replayable_control_steps(s));
  EXPECT_NO_THROW(simulate_bench(L, master_cfg(), slave_cfg(), s));
}

TEST(HilSchedule, LateAndSkippedFramesEqualHandWrittenLoop) {
  const std::size_t N = 400;
  FrameSchedule sch = ideal_schedule(N);
  // Master: sensor frame 50 late (the value of frame 49 is used at control steps 49 and 50),
  // then frame 51 at 51: frame 50 skipped. Frame 80 used one step late, at 81; frame 81 skipped.
  sch.master[50].seq = -1;
  sch.master[80].seq = -1;
  sch.master[81].seq = 80;
  // Slave: command 119 late, 120 arrives with it at slave step 121: 119 skipped, 118 held at 120.
  sch.slave[120].seq = -1;
  BenchLayout L;
  const SimulationResult sim = simulate_bench(L, master_cfg(), slave_cfg(), sch);
  ASSERT_EQ(sim.master.size(), N + 1);

  // By hand: slave step k applies the command it used (held if none) and measures; master
  // step k uses the sensor frame of slave step U(k) (holds value and command if none).
  PilotValvePlant plant(slave_cfg().plant);
  ClosedLoopDiscrete ctl(master_cfg().controller);
  Signal ref(master_cfg().reference, kT);
  std::vector<double> y_sent(N), i_sent(N);
  double c = 0.0, y = 0.0, i = 0.0;
  for (std::size_t k = 0; k < N; ++k) {
    if (k > 0) {
      if (sch.slave[k].seq >= 0) c = L.quantize_current(i_sent[static_cast<std::size_t>(sch.slave[k].seq)]);
      plant.apply(c);
    }
    plant.measure();
    y_sent[k] = decode_pressure_raw(plant.last_raw());
    const double r = ref.next();
    if (sch.master[k].seq >= 0) {
      y = y_sent[static_cast<std::size_t>(sch.master[k].seq)];
      i = ctl.step(r, y);
    }
    i_sent[k] = i;
    const MasterStepLog& m = sim.master[k + 1];
    ASSERT_EQ(m.control_step, static_cast<std::int64_t>(k));
    ASSERT_EQ(m.state, MasterState::running) << k;
    ASSERT_EQ(m.measured_kPa, y) << k;
    ASSERT_EQ(m.current_mA, i) << k;
    ASSERT_EQ(m.sensor_seq, sch.master[k].seq) << k;
    ASSERT_EQ(sim.slave[k].current_mA, c) << k;
  }
  // The frame used twice and the skipped ones by value: held at 50 and 80, frame 80 at 81.
  EXPECT_EQ(sim.master[51].measured_kPa, y_sent[49]);
  EXPECT_EQ(sim.master[51].current_mA, sim.master[50].current_mA);
  EXPECT_EQ(sim.master[82].measured_kPa, y_sent[80]);
  EXPECT_EQ(sim.master[83].measured_kPa, y_sent[82]);
  EXPECT_EQ(sim.slave[120].current_mA, sim.slave[119].current_mA);
  EXPECT_EQ(sim.slave[121].current_mA, L.quantize_current(i_sent[120]));
  // And it is not the ideal schedule's trace (the comparison can fail).
  const SimulationResult ideal = simulate_bench(L, master_cfg(), slave_cfg(), ideal_schedule(N));
  const SimulationDiff d = compare_with_simulation(sim.master, ideal.master);
  EXPECT_GT(d.max_abs_diff_kPa, 0.0);
  ASSERT_TRUE(d.first_diff_step.has_value());
  EXPECT_EQ(*d.first_diff_step, 50);
}

TEST(HilSchedule, DroppedFrameDegradesAtItsStep) {
  const std::size_t N = 100;
  FrameSchedule sch = ideal_schedule(N);
  sch.master[60].dropped = true;  // an implausible sensor frame besides frame 60
  BenchLayout L;
  const SimulationResult sim = simulate_bench(L, master_cfg(), slave_cfg(), sch);
  // Control step m is row m + 1: running until 59, degraded at 60 with the integrator frozen,
  // running again after recovery_frames (5) good steps: 61..65.
  EXPECT_EQ(sim.master[60].state, MasterState::running);
  EXPECT_EQ(sim.master[61].state, MasterState::degraded);
  EXPECT_EQ(sim.master[61].integrator_mA, sim.master[60].integrator_mA);
  EXPECT_EQ(sim.master[61].dropped, 1);
  EXPECT_EQ(sim.master[65].state, MasterState::degraded);
  EXPECT_EQ(sim.master[66].state, MasterState::running);
}

TEST(HilSchedule, NonCausalSchedulesAreRefused) {
  BenchLayout L;
  FrameSchedule ahead = ideal_schedule(50);
  ahead.master[10].seq = 11;   // a sensor frame from the slave step after it
  ahead.slave[11].seq = 11;    // …which needs the command of control step 11
  EXPECT_THROW(simulate_bench(L, master_cfg(), slave_cfg(), ahead), std::invalid_argument);
  FrameSchedule back = ideal_schedule(50);
  back.master[20].seq = 19;    // frame 19 again
  EXPECT_THROW(simulate_bench(L, master_cfg(), slave_cfg(), back), std::invalid_argument);
  FrameSchedule short_slave = ideal_schedule(50);
  short_slave.slave.resize(30);  // the master uses frames the slave never sent
  EXPECT_THROW(simulate_bench(L, master_cfg(), slave_cfg(), short_slave), std::invalid_argument);
}

TEST(HilSchedule, ReadScheduleFromLogs) {
  const auto dir = std::filesystem::temp_directory_path() / ("lash_sched_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ofstream m(dir / "master.csv");
    m << "step,control_step,sensor_seq,dropped,measured_kPa,current_mA\n"
         "0,-1,-1,0,0,0\n1,0,0,0,1,2\n2,1,-1,1,1,2\n3,2,2,0,3,4\n";
    std::ofstream s(dir / "slave.csv");
    s << "step,command_counter,command_fresh,dropped\n0,0,0,0\n1,0,1,0\n2,0,1,0\n3,2,1,1\n";
  }
  const FrameSchedule fs = read_schedule(dir / "master.csv", dir / "slave.csv");
  ASSERT_EQ(fs.master.size(), 3u);
  EXPECT_EQ(fs.master[0].seq, 0);
  EXPECT_EQ(fs.master[1].seq, -1);
  EXPECT_TRUE(fs.master[1].dropped);
  EXPECT_EQ(fs.master[2].seq, 2);
  ASSERT_EQ(fs.slave.size(), 4u);
  EXPECT_EQ(fs.slave[0].seq, -1);
  EXPECT_EQ(fs.slave[1].seq, 0);
  EXPECT_EQ(fs.slave[3].seq, 2);
  EXPECT_TRUE(fs.slave[3].dropped);
  const auto trace = read_master_trace(dir / "master.csv");
  ASSERT_EQ(trace.size(), 3u);
  EXPECT_EQ(trace[2].measured_kPa, 3.0);
  {
    std::ofstream m(dir / "master.csv");
    m << "step,control_step,sensor_seq,dropped\n0,0,0,0\n1,1,0.5,0\n";
  }
  try {
    read_schedule(dir / "master.csv", dir / "slave.csv");
    ADD_FAILURE() << "a fractional sensor_seq was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.field(), "sensor_seq");
  }
  std::filesystem::remove_all(dir);
}

// XCP calibration (hil/calibration.hpp): a page handed over through the XcpLink before step k is
// in force from step k on (the step boundary), each changed object is one event with its old and
// new value, the reference offset moves the square reference by exactly that much, and the
// replay of the logged schedule (which carries the pages) equals the run bit for bit.
TEST(HilSchedule, CalibrationPageAtTheStepBoundaryAndItsReplay) {
  const BenchLayout L;
  constexpr std::size_t N = 400, K = 200;
  MasterConfig mc = master_cfg();
  mc.log_capacity = N + 1;
  SlaveConfig sc = slave_cfg();
  sc.log_capacity = N;
  MasterNode master(L, mc);
  SlaveNode slave(L, sc);
  auto xl = std::make_unique<XcpLink>();
  master.attach(xl.get());
  MemLink link;
  master.step(link.a(), 0.0);
  ASSERT_TRUE(slave.wait_connect(link.b(), std::chrono::nanoseconds(0)));
  for (std::size_t k = 1; k <= N; ++k) {
    const double t = static_cast<double>(k) * kT;
    if (k == K) {
      CalibrationPage p = master.calibration();
      p.kp = 0.7;
      p.reference_offset_kPa = 50.0;
      ASSERT_TRUE(xl->pages.push(p));
    }
    slave.step(link.b(), t - 0.5 * kT);
    master.step(link.a(), t);
  }
  const std::vector<MasterStepLog> log(master.log().begin(), master.log().end());
  for (std::size_t k = 1; k <= N; ++k) {
    const bool after = k >= K;
    ASSERT_EQ(log[k].calibration.kp, after ? 0.7 : 1.2) << k;
    ASSERT_EQ(log[k].calibration.ki_per_s, 12.0) << k;
    // The square reference of master_cfg() is 900 ± 400 kPa (900 where the sine crosses 0).
    const double r = log[k].reference_kPa - (after ? 50.0 : 0.0);
    ASSERT_TRUE(r == 500.0 || r == 900.0 || r == 1300.0) << k << " " << log[k].reference_kPa;
  }
  const auto ev = master.calibration_events();
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(std::string(calibration_fields()[ev[0].field].name), "kp");
  EXPECT_EQ(ev[0].old_value, 1.2);
  EXPECT_EQ(ev[0].new_value, 0.7);
  EXPECT_EQ(ev[0].step, K);
  EXPECT_EQ(std::string(calibration_fields()[ev[1].field].name), "reference_offset_kPa");
  EXPECT_EQ(ev[1].new_value, 50.0);
  // Every step pushed its measurements (one per step, nothing lost).
  MeasurementSample smp;
  std::size_t n = 0;
  while (xl->samples.pop(smp)) ++n;
  EXPECT_EQ(n, N + 1);
  EXPECT_EQ(xl->samples_lost.load(), 0u);

  SimulationResult run;
  run.master = log;
  run.slave.assign(slave.log().begin(), slave.log().end());
  const FrameSchedule fs = observed_schedule(run.master, run.slave);
  ASSERT_EQ(fs.calibration.size(), 2u);  // the first control step's page, and the change
  EXPECT_EQ(fs.calibration[1].control_step, log[K].control_step);
  expect_same(run, simulate_bench(L, mc, sc, fs));
  // Without the pages the replay departs from the run after step K (the write mattered).
  FrameSchedule without = fs;
  without.calibration.clear();
  const SimulationResult other = simulate_bench(L, mc, sc, without);
  EXPECT_NE(other.master[N].current_mA, run.master[N].current_mA);
}

// XCP calibration of the scenario law (--scenario): the compensation mode, the nominal edges and
// the dither switched mid-run through the XcpLink. With Kp = Ki = 0 (written in the first page)
// the PID's output is its frozen integrator I, so u = I + 0.465·r from the logged columns, and
// the current follows from the inverse's definition by hand (slopes 1, no smoothing):
//   none:     i = u
//   fixed:    i = u + 300 (u > 0), u − 310 (u < 0)       (the new nominal edges of the second page)
//   adaptive: i = fixed(u + d), d = +10 for 10 samples, −10 for 10 (dither 10 mA, period 0.1 s,
//             restarted by the mode change), edges still 300/310 (settle 0.5 s = 100 samples)
// and the replay of the logged schedule equals the run bit for bit.
TEST(HilSchedule, CompensationModeSwitchUnderAScenarioAndItsReplay) {
  const BenchLayout L;
  constexpr std::size_t N = 1000, K1 = 400, K2 = 600, K3 = 800;
  constexpr double ff = 0.465;
  MasterConfig mc = master_cfg();
  mc.log_capacity = N + 1;
  mc.reference = SignalSpec{};
  mc.reference.kind = Waveform::sine;
  mc.reference.amplitude = 600.0;
  mc.reference.frequency_rad_s = 2.0 * std::numbers::pi;
  CompensatedLaw law;
  law.pid.dt_s = kT;
  law.pid.gains.kp = 0.5;
  law.pid.gains.ki_per_s = 10.0;
  law.pid.anti_windup = AntiWindup::clamp;
  law.pid.output_min = -2000.0;
  law.pid.output_max = 2000.0;
  law.feedforward = ff;
  law.compensation.mode = CompensationMode::adaptive;
  law.compensation.nominal.offset_right = 288.0;
  law.compensation.nominal.offset_left = 296.0;
  law.compensation.estimator.model = ModelKind::input_deadzone;
  law.compensation.estimator.dt_s = kT;
  law.compensation.estimator.guess_right = 432.0;
  law.compensation.estimator.guess_left = -444.0;
  mc.law = law;
  SlaveConfig sc = slave_cfg();
  sc.log_capacity = N;
  sc.rig = RigPlant{};
  sc.rig->seed = 7;
  MasterNode master(L, mc);
  SlaveNode slave(L, sc);
  auto xl = std::make_unique<XcpLink>();
  master.attach(xl.get());
  ASSERT_EQ(master.calibration().compensation, 2.0);  // the scenario's mode, edges and settings
  ASSERT_EQ(master.calibration().dz_right_mA, 288.0);
  ASSERT_EQ(master.calibration().adapt_settle_s, 0.5);
  MemLink link;
  master.step(link.a(), 0.0);
  ASSERT_TRUE(slave.wait_connect(link.b(), std::chrono::nanoseconds(0)));
  for (std::size_t k = 1; k <= N; ++k) {
    CalibrationPage p = master.calibration();
    if (k == K1) {
      p.kp = p.ki_per_s = 0.0;
      p.compensation = 0.0;
    } else if (k == K2) {
      p.compensation = 1.0;
      p.dz_right_mA = 300.0;
      p.dz_left_mA = 310.0;
    } else if (k == K3) {
      p.compensation = 2.0;
      p.dither_mA = 10.0;
    }
    if (k == K1 || k == K2 || k == K3) {
      ASSERT_TRUE(xl->pages.push(p));
    }
    const double t = static_cast<double>(k) * kT;
    slave.step(link.b(), t - 0.5 * kT);
    master.step(link.a(), t);
  }
  const std::vector<MasterStepLog> log(master.log().begin(), master.log().end());
  auto fixed = [](double u) { return u > 0.0 ? u + 300.0 : (u < 0.0 ? u - 310.0 : 0.0); };
  const double I = log[K1].integrator_mA;
  for (std::size_t k = K1; k <= N; ++k) {
    const MasterStepLog& m = log[k];
    ASSERT_EQ(m.state, MasterState::running) << k;
    ASSERT_EQ(m.integrator_mA, I) << k;
    const double u = I + ff * m.reference_kPa;
    if (k < K2) {
      ASSERT_EQ(m.calibration.compensation, 0.0) << k;
      ASSERT_NEAR(m.current_mA, u, 1e-9) << k;
      ASSERT_EQ(m.inverse_right_mA, 0.0) << k;
    } else if (k < K3) {
      ASSERT_EQ(m.calibration.compensation, 1.0) << k;
      ASSERT_NEAR(m.current_mA, fixed(u), 1e-9) << k;
      ASSERT_EQ(m.inverse_right_mA, 300.0) << k;
      ASSERT_EQ(m.inverse_left_mA, -310.0) << k;
    } else if (k < K3 + 100) {
      ASSERT_EQ(m.calibration.compensation, 2.0) << k;
      const double d = (k - K3) % 20 < 10 ? 10.0 : -10.0;
      ASSERT_NEAR(m.current_mA, fixed(u + d), 1e-9) << k;
      ASSERT_EQ(m.inverse_right_mA, 300.0) << k;
    }
  }
  // One event per changed object, in table order within a page.
  const auto ev = master.calibration_events();
  std::vector<std::string> names;
  for (const auto& e : ev) names.emplace_back(calibration_fields()[e.field].name);
  const std::vector<std::string> want{"kp", "ki_per_s", "compensation", "dz_right_mA", "dz_left_mA",
                                      "compensation", "compensation", "dither_mA"};
  ASSERT_EQ(names, want);
  EXPECT_EQ(ev[2].old_value, 2.0);
  EXPECT_EQ(ev[2].new_value, 0.0);
  EXPECT_EQ(ev[2].step, K1);
  EXPECT_EQ(ev[5].old_value, 0.0);
  EXPECT_EQ(ev[5].new_value, 1.0);
  EXPECT_EQ(ev[6].new_value, 2.0);
  EXPECT_EQ(ev[6].step, K3);
  EXPECT_EQ(master.compensation().mode, CompensationMode::adaptive);

  SimulationResult run;
  run.master = log;
  run.slave.assign(slave.log().begin(), slave.log().end());
  const FrameSchedule fs = observed_schedule(run.master, run.slave);
  ASSERT_EQ(fs.calibration.size(), 4u);  // the first control step's page, and the three changes
  expect_same(run, simulate_bench(L, mc, sc, fs));
  FrameSchedule without = fs;  // without the pages the replay departs from the run
  without.calibration.resize(1);
  const SimulationResult other = simulate_bench(L, mc, sc, without);
  EXPECT_NE(other.master[K1 + 1].current_mA, run.master[K1 + 1].current_mA);
}

// The same objects on the bench's own controller (no scenario): compensation 0 sets its fixed
// inverse's edges to 0, 1 puts the (new) edges back. With Kp = Ki = Kd = 0 the PID's output is
// its frozen integrator I > 0, so by hand (slopes 1, no smoothing): i = I under none, I + 300
// under fixed with dz_right_mA = 300 (written while none was in force); the replay equals the run.
TEST(HilSchedule, CompensationOfTheBenchControllerAndItsReplay) {
  const BenchLayout L;
  constexpr std::size_t N = 600, K1 = 300, K2 = 450;
  MasterConfig mc = master_cfg();
  mc.log_capacity = N + 1;
  mc.controller.dz_inverse = {279.36, 279.36, 1.0, 1.0, 0.0};
  SlaveConfig sc = slave_cfg();
  sc.log_capacity = N;
  MasterNode master(L, mc);
  SlaveNode slave(L, sc);
  auto xl = std::make_unique<XcpLink>();
  master.attach(xl.get());
  ASSERT_EQ(master.calibration().compensation, 1.0);  // the bench controller: fixed
  MemLink link;
  master.step(link.a(), 0.0);
  ASSERT_TRUE(slave.wait_connect(link.b(), std::chrono::nanoseconds(0)));
  for (std::size_t k = 1; k <= N; ++k) {
    CalibrationPage p = master.calibration();
    if (k == K1) {
      p.kp = p.ki_per_s = p.kd_s = 0.0;
      p.compensation = 0.0;
      p.dz_right_mA = 300.0;
      p.dither_mA = 50.0;  // no effect without a scenario (logged all the same)
    } else if (k == K2) {
      p.compensation = 1.0;
    }
    if (k == K1 || k == K2) {
      ASSERT_TRUE(xl->pages.push(p));
    }
    const double t = static_cast<double>(k) * kT;
    slave.step(link.b(), t - 0.5 * kT);
    master.step(link.a(), t);
  }
  const std::vector<MasterStepLog> log(master.log().begin(), master.log().end());
  const double I = log[K1].integrator_mA;
  ASSERT_GT(I, 0.0);
  ASSERT_LT(I + 300.0, 2000.0);
  for (std::size_t k = K1; k <= N; ++k) {
    ASSERT_EQ(log[k].integrator_mA, I) << k;
    ASSERT_NEAR(log[k].current_mA, k < K2 ? I : I + 300.0, 1e-9) << k;
  }
  // K1: kp, ki_per_s, kd_s, dz_right_mA, compensation, dither_mA; K2: compensation
  ASSERT_EQ(master.calibration_events().size(), 7u);
  SimulationResult run;
  run.master = log;
  run.slave.assign(slave.log().begin(), slave.log().end());
  expect_same(run, simulate_bench(L, mc, sc, observed_schedule(run.master, run.slave)));
}
