// hil::RunReport from in-memory runs, with hand-computed numbers (issue 11 item 1).
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "lash/hil/node_run.hpp"
#include "lash/hil/report.hpp"

using namespace lash;
using namespace lash::hil;

namespace {

MasterStepLog mrow(std::int64_t m, bool fresh, std::uint16_t counter, double y, double i) {
  MasterStepLog l;
  l.step = static_cast<std::uint32_t>(m + 1);
  l.control_step = m;
  l.state = MasterState::running;
  l.sensor_fresh = fresh;
  l.sensor_counter = counter;
  l.measured_kPa = y;
  l.current_mA = i;
  l.command_sent = true;
  return l;
}

SlaveStepLog srow(std::uint32_t s, bool fresh, std::uint64_t counter) {
  SlaveStepLog l;
  l.step = s;
  l.command_fresh = fresh;
  l.command_counter = counter;
  return l;
}

/// Master: a connecting row, then control steps 0..4. Step 2 got no sensor frame (counter 1
/// held), step 3 got slave step 2's frame (late). Slave: step 3 got no command, step 4 got the
/// command of master step 2 instead of 3.
MasterRun master_run() {
  MasterRun r;
  MasterStepLog connecting;
  connecting.control_step = -1;
  r.log.push_back(connecting);
  r.log.push_back(mrow(0, true, 0, 500.0, 100.0));
  r.log.push_back(mrow(1, true, 1, 510.0, 110.0));
  r.log.push_back(mrow(2, false, 1, 510.0, 120.0));
  r.log.push_back(mrow(3, true, 2, 530.0, 130.0));
  r.log.push_back(mrow(4, true, 4, 540.0, 140.0));
  for (int k = 0; k < 6; ++k)  // TET 1..6 µs, I/O 0.5 µs, wake-up latency 10·k µs
    r.loop.records.push_back(rt::StepRecord{k * 5'000'000LL, 10'000LL * k, 1000LL * (k + 1), 500});
  r.stats.result = {6, 0, rt::StopReason::step_returned_false};
  r.stats.control_steps = 5;
  r.stats.handshake_s = 0.005;
  r.stats.frames.sent = 6;
  r.stats.frames.received = 4;
  r.stats.frames.late = 1;
  return r;
}

SlaveRun slave_run() {
  SlaveRun r;
  r.log = {srow(0, false, 0), srow(1, true, 0), srow(2, true, 1), srow(3, false, 1), srow(4, true, 2)};
  r.loop.records.assign(5, rt::StepRecord{0, 0, 2000, 1000});
  r.stats.result = {5, 0, rt::StopReason::requested};
  r.stats.frames.sent = 5;
  r.stats.frames.received = 4;
  r.stats.frames.lost = 1;
  return r;
}

}  // namespace

TEST(HilRunReport, OffScheduleStepsByHand) {
  const MasterRun m = master_run();
  const SlaveRun s = slave_run();
  // Master side: {2 (no frame), 3 (counter 2 ≠ 3)}; slave side: {3 (no command), 4 (counter 2 ≠ 3)}.
  EXPECT_EQ(off_schedule_steps(m.log, s.log, 5), 3u);
  EXPECT_EQ(off_schedule_steps(m.log, {}, 5), 2u);
  // Slave step 5 is past the control steps: not counted even though it is wrong.
  std::vector<SlaveStepLog> late = s.log;
  late.push_back(srow(5, false, 0));
  EXPECT_EQ(off_schedule_steps(m.log, late, 5), 3u);
  // Sensor counters are 16-bit: control step 65536 uses counter 0 and is on schedule. The
  // slave logs the command counter unwrapped: slave step 65537 needs 65536, not 0.
  EXPECT_EQ(off_schedule_steps({mrow(65536, true, 0, 0, 0)}, {srow(65537, true, 65536)}, 70000), 0u);
  EXPECT_EQ(off_schedule_steps({}, {srow(65537, true, 0)}, 70000), 1u);
  EXPECT_EQ(off_schedule_steps({mrow(65536, true, 1, 0, 0)}, {}, 70000), 1u);
}

TEST(HilRunReport, FiguresAndSimulationDiffByHand) {
  const MasterRun m = master_run();
  std::vector<MasterStepLog> sim;
  sim.push_back(m.log[0]);
  for (std::size_t i = 1; i < m.log.size(); ++i) sim.push_back(m.log[i]);
  sim[4].measured_kPa += 2.5;  // control step 3
  sim[5].current_mA -= 1.0;    // control step 4
  RunReport rep;
  rep.step_s = 0.005;
  make_run_report(rep, &m, {slave_run()}, sim);
  ASSERT_TRUE(rep.have_master && rep.have_slave);
  EXPECT_EQ(rep.vs_simulation.compared, 5u);
  EXPECT_DOUBLE_EQ(rep.vs_simulation.max_abs_diff_kPa, 2.5);
  EXPECT_DOUBLE_EQ(rep.vs_simulation.max_abs_diff_mA, 1.0);
  ASSERT_TRUE(rep.vs_simulation.first_diff_step.has_value());
  EXPECT_EQ(*rep.vs_simulation.first_diff_step, 3);
  EXPECT_EQ(rep.off_schedule, 3u);
  // TET 1..6 µs: mean 3.5, sample std sqrt(3.5), p99 = the 6th smallest (nearest rank ⌈5.94⌉).
  EXPECT_DOUBLE_EQ(rep.master.tet_us.mean, 3.5);
  EXPECT_NEAR(rep.master.tet_us.std, std::sqrt(3.5), 1e-12);
  EXPECT_DOUBLE_EQ(rep.master.tet_us.p99, 6.0);
  EXPECT_DOUBLE_EQ(rep.master.io_us.mean, 0.5);
  EXPECT_DOUBLE_EQ(rep.master.cycle_us.mean, 4.0);
  EXPECT_DOUBLE_EQ(rep.master.wake_latency_us.max, 50.0);
  EXPECT_DOUBLE_EQ(rep.slave.cycle_us.mean, 3.0);
  EXPECT_EQ(rep.control_steps, 5);
  // Frames summed over both nodes.
  EXPECT_EQ(rep.frames.sent, 11u);
  EXPECT_EQ(rep.frames.received, 8u);
  EXPECT_EQ(rep.frames.late, 1u);
  EXPECT_EQ(rep.frames.lost, 1u);
  // No reference step in a zero reference: no step response.
  EXPECT_FALSE(rep.step.has_value());
  rep.interrupted = true;
  rep.interrupt_signal = 15;
  const std::string j = run_report_json(rep);
  EXPECT_NE(j.find("\"interrupted\": true"), std::string::npos);
  EXPECT_NE(j.find("\"off_schedule_steps\": 3"), std::string::npos);
  EXPECT_NE(j.find("\"max_abs_diff_vs_simulation_kPa\": 2.5"), std::string::npos);
}

TEST(HilRunReport, StepResponseOfARampByHand) {
  // 1 s at 0 kPa, then 100 kPa; the plant ramps 10 kPa per 10 ms sample: it reaches 90 kPa
  // (90 % rise, and the 10 % band) 9 samples = 0.09 s after the step, never overshoots.
  const double dt = 0.01;
  std::vector<double> ref, p;
  for (int k = 0; k < 300; ++k) {
    ref.push_back(k < 100 ? 0.0 : 100.0);
    p.push_back(k < 100 ? 0.0 : std::min(100.0, 10.0 * (k - 100)));
  }
  const auto r = step_response(ref, dt, p, &p);
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(r->window.t_step_s, 1.0, 1e-12);
  EXPECT_NEAR(r->plant.rise_s, 0.09, 1e-9);
  EXPECT_NEAR(r->plant.settling_s, 0.09, 1e-9);
  EXPECT_EQ(r->plant.overshoot_pct, 0.0);
  ASSERT_TRUE(r->measured.has_value());
  EXPECT_NEAR(r->measured->rise_s, 0.09, 1e-9);
  // A pressure trace shorter than the window: no figures rather than reading past it.
  EXPECT_FALSE(step_response(ref, dt, std::vector<double>(150, 0.0)).has_value());
}

TEST(HilRunReport, HandOverRoundTrip) {
  const int fd = memfd_create("test", MFD_CLOEXEC);
  ASSERT_GE(fd, 0);
  MasterRun m = master_run();
  m.loop.warnings = {"first", ""};
  m.events.push_back(MasterEvent{3, 0.015, MasterEventKind::sensor_timeout});
  write_run(fd, m);
  MasterRun back;
  ASSERT_TRUE(read_run(fd, back));
  EXPECT_EQ(back.log.size(), 6u);
  EXPECT_EQ(back.log[4].sensor_counter, 2);
  EXPECT_EQ(back.loop.records[5].tet_ns, 6000);
  EXPECT_EQ(back.loop.warnings, m.loop.warnings);
  ASSERT_EQ(back.events.size(), 1u);
  EXPECT_EQ(back.events[0].kind, MasterEventKind::sensor_timeout);
  EXPECT_EQ(back.stats.control_steps, 5);
  // The slave's safe-state events and end state travel too.
  const int sfd = memfd_create("slave", MFD_CLOEXEC);
  ASSERT_GE(sfd, 0);
  SlaveRun sr = slave_run();
  sr.stats.state = NodeState::safe;
  sr.events.push_back(NodeEvent{7, 0.035, NodeEventKind::ramp_done, NodeState::degraded, NodeState::safe});
  write_run(sfd, sr);
  SlaveRun sback;
  ASSERT_TRUE(read_run(sfd, sback));
  EXPECT_EQ(sback.stats.state, NodeState::safe);
  ASSERT_EQ(sback.events.size(), 1u);
  EXPECT_EQ(sback.events[0].step, 7u);
  EXPECT_EQ(sback.events[0].from, NodeState::degraded);
  EXPECT_EQ(sback.events[0].to, NodeState::safe);
  close(sfd);
  // An empty or cut-short hand-over (a killed node) reads as nothing.
  const int empty = memfd_create("empty", MFD_CLOEXEC);
  SlaveRun s;
  EXPECT_FALSE(read_run(empty, s));
  ASSERT_EQ(ftruncate(fd, 40), 0);
  MasterRun cut;
  EXPECT_FALSE(read_run(fd, cut));
  close(fd);
  close(empty);
}

#include <fstream>

TEST(HilSettings, InlineControllerHasTheGainsFileSchemaFlatKeysDeprecated) {
  const std::string src = LASH_SOURCE_DIR;
  const std::string dir = ::testing::TempDir();
  const std::string head = "dbc = \"" + src + "/config/hydraulic_bench.dbc\"\ndto_log = \"" + src +
                           "/config/hil/ccp_connect.log\"\n";
  std::ofstream(dir + "/nested.toml") << head
                                      << "[controller.pid]\nkp = 2\nki_per_s = 30\nkd_s = 0.5\n"
                                         "[controller.deadzone_inverse]\noffset_mA = 250\n"
                                         "[controller.saturation]\nmax_mA = 1800\n";
  std::ofstream(dir + "/flat.toml") << head
                                    << "[controller]\nkp = 2\nki_per_s = 30\nkd_s = 0.5\ndeadzone_inverse_mA = 250\n"
                                       "current_max_mA = 1800\n";
  const BenchSettings a = load_bench_settings(dir + "/nested.toml");
  const BenchSettings b = load_bench_settings(dir + "/flat.toml");
  EXPECT_TRUE(a.warnings.empty());
  EXPECT_EQ(b.warnings.size(), 5u);
  for (const BenchSettings* s : {&a, &b}) {
    EXPECT_EQ(s->controller.pid.gains.kp, 2.0);
    EXPECT_EQ(s->controller.pid.gains.ki_per_s, 30.0);
    EXPECT_EQ(s->controller.pid.gains.kd_s, 0.5);
    EXPECT_EQ(s->controller.dz_inverse.offset_left, 250.0);
    EXPECT_EQ(s->controller.current_max_mA, 1800.0);
    EXPECT_EQ(s->controller.pid.dt_s, 0.005);  // the bench's step
  }
}
