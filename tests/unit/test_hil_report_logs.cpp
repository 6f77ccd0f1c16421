// `lash hil run`'s report computed by streaming over the nodes' CSV logs
// (hil/report_logs.hpp) against the same report computed as the session did before, with the
// logs read back whole into memory (read_master_log / read_slave_log of hil_log_read.hpp,
// make_run_report, the simulations of the ideal and of the observed schedule): the two
// report.json texts are equal character for character (the JSON prints each double to its
// shortest round trip, so equal text is equal bits). Besides, figures checked against
// hand-counted values of the schedule.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <numbers>

#include "lash/hil/handover.hpp"
#include "lash/hil/node_report.hpp"
#include "lash/hil/report.hpp"
#include "lash/hil/report_logs.hpp"
#include "lash/hil/schedule.hpp"
#include "lash/hil/sim_run.hpp"
#include "lash/io/error.hpp"
#include "hil_log_read.hpp"
#include "hil_test_bench.hpp"
#include "recorded_dto.hpp"

using namespace lash;
using namespace lash::hil;
using test::read_master_log;
using test::read_slave_log;

namespace {

using test::kT;
using test::master_cfg;
using test::slave_cfg;

std::filesystem::path temp_dir() {
  const auto d = std::filesystem::temp_directory_path() / ("lash_hil_report_logs_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

rt::StepRecord record(std::size_t k) {  // loop figures with ties and a spread tail
  const auto K = static_cast<std::int64_t>(k);
  return rt::StepRecord{K * 5'000'000, (K * 31) % 5000, 1000 + (K * 7919) % 1000, 500 + K % 13};
}

/// A run as the nodes would have logged it: the bench with late and skipped frames (master
/// control step 50 without a sensor frame, 81 with frame 80; slave step 120 without a command),
/// the master's measured pressure at control step 300 off by 0.25 kPa (so that neither
/// simulation matches every step), and loop records.
struct Logged {
  MasterRun master;
  SlaveRun slave;
};

Logged logged_run(std::size_t N) {
  FrameSchedule sch = ideal_schedule(N);
  sch.master[50].seq = -1;
  sch.master[80].seq = -1;
  sch.master[81].seq = 80;
  sch.slave[120].seq = -1;
  const BenchLayout L;
  const SimulationResult sim = simulate_bench(L, master_cfg(), slave_cfg(), sch);
  Logged r;
  r.master.log = sim.master;
  r.master.log[301].measured_kPa += 0.25;  // control step 300 (row 0 is the connecting step)
  r.slave.log = sim.slave;
  for (std::size_t k = 0; k < r.master.log.size(); ++k) r.master.loop.records.push_back(record(k));
  for (std::size_t k = 0; k < r.slave.log.size(); ++k) r.slave.loop.records.push_back(record(3 * k + 1));
  r.master.stats.control_steps = static_cast<std::int64_t>(N);
  r.master.stats.result.steps = r.master.log.size();
  r.master.stats.handshake_s = kT;
  r.master.stats.frames.sent = 11;
  r.slave.stats.frames.received = 7;
  r.slave.stats.result.steps = r.slave.log.size();
  return r;
}

/// The session's report before the streaming (session.cpp of the parent commit): the logs read
/// back whole onto the handed-over runs (whose log and records are empty), then make_run_report
/// with the ideal-schedule simulation, then the replay of the observed schedule.
RunReport report_in_memory(const std::filesystem::path& mcsv, const std::filesystem::path& scsv, const Logged& handed,
                           const BenchScenario* scenario) {
  RunReport rep;
  rep.step_s = kT;
  MasterRun m;
  m.stats = handed.master.stats;
  SlaveRun s;
  s.stats = handed.slave.stats;
  read_master_log(mcsv, m.log, m.loop.records);
  read_slave_log(scsv, s.log, s.loop.records);
  const std::vector<SlaveRun> sruns{s};
  const BenchLayout L;
  std::vector<MasterStepLog> simulated;
  if (m.stats.control_steps > 0) {
    FrameSchedule ideal = ideal_schedule(static_cast<std::size_t>(m.stats.control_steps));
    ideal.calibration = observed_schedule(m.log, {}).calibration;
    simulated = simulate_bench(L, master_cfg(), slave_cfg(), ideal).master;
  }
  make_run_report(rep, &m, sruns, simulated, scenario);
  if (simulated.empty()) return rep;
  if (sruns[0].log.empty()) {
    rep.observed_schedule_note = "not replayed: the schedule of one slave from start to end is needed";
    return rep;
  }
  try {
    FrameSchedule fs = observed_schedule(m.log, sruns[0].log);
    const std::size_t kept = replayable_control_steps(fs);
    if (kept < fs.master.size()) {
      fs.master.resize(kept);
      rep.observed_schedule_note =
          "replayed the first " + std::to_string(kept) + " control steps: the slave's log ends before the master's";
    }
    rep.vs_observed_schedule = compare_with_simulation(m.log, simulate_bench(L, master_cfg(), slave_cfg(), fs).master);
  } catch (const std::invalid_argument& e) {
    rep.observed_schedule_note = std::string("not replayed: ") + e.what();
  }
  return rep;
}

RunReport report_streamed(const std::filesystem::path& mcsv, const std::filesystem::path& scsv, const Logged& handed,
                          const BenchScenario* scenario) {
  RunReport rep;
  rep.step_s = kT;
  MasterRun m;
  m.stats = handed.master.stats;
  SlaveRun s;
  s.stats = handed.slave.stats;
  RunLogs logs;
  logs.master = scan_master_log(mcsv);
  logs.slave = scan_slave_log(scsv);
  make_run_report_from_logs(rep, &m, {s}, logs, BenchLayout{}, master_cfg(), slave_cfg(), scenario);
  return rep;
}

void write_logs(const std::filesystem::path& d, const Logged& r) {
  write_master_csv(d / "master.csv", r.master);
  write_slave_csv(d / "slave.csv", r.slave);
}

}  // namespace

TEST(HilReportLogs, StreamedReportEqualsTheReportOfTheLogsInMemory) {
  const auto d = temp_dir();
  const Logged r = logged_run(1200);  // 6 s: reference steps at 1 s, 2 s, …
  write_logs(d, r);
  const RunReport a = report_in_memory(d / "master.csv", d / "slave.csv", r, nullptr);
  const RunReport b = report_streamed(d / "master.csv", d / "slave.csv", r, nullptr);
  EXPECT_EQ(run_report_json(a), run_report_json(b));

  // Hand-counted: control steps 50 (no sensor frame) and 81 (frame 80) used another frame than
  // theirs, and so did slave step 120 (no command); step 80 used none (frame 80 came late).
  EXPECT_EQ(b.off_schedule, 4u);
  EXPECT_EQ(b.vs_simulation.compared, 1200u);
  ASSERT_TRUE(b.vs_simulation.first_diff_step.has_value());
  EXPECT_EQ(*b.vs_simulation.first_diff_step, 50);  // the late frame: the ideal schedule departs there
  ASSERT_TRUE(b.vs_observed_schedule.has_value());
  EXPECT_EQ(b.vs_observed_schedule->compared, 1200u);
  EXPECT_EQ(*b.vs_observed_schedule->first_diff_step, 300);  // the replay departs only at the altered row
  EXPECT_DOUBLE_EQ(b.vs_observed_schedule->max_abs_diff_kPa, 0.25);
  EXPECT_EQ(b.vs_observed_schedule->max_abs_diff_mA, 0.0);
  ASSERT_TRUE(b.step.has_value());
  // Square wave of period 2 s, r(m) = 900 + 400·sign(sin(π·m·T)): sin(π·200·T) = sin(π) rounds
  // to +1.2e-16, so the first jump is at sample 201.
  EXPECT_EQ(b.step->window.begin, 201u);
  EXPECT_DOUBLE_EQ(b.step->window.t_step_s, 1.005);
  EXPECT_EQ(b.step->window.y0, 1300.0);
  EXPECT_EQ(b.step->window.y1, 500.0);
  // Loop figures of the master's 1201 rows: TET 1000 + (7919·k mod 1000) ns.
  EXPECT_EQ(b.master.tet_us.n, 1201u);
  EXPECT_DOUBLE_EQ(b.master.tet_us.min, 1.0);
  EXPECT_DOUBLE_EQ(b.master.tet_us.max, 1.999);
  std::filesystem::remove_all(d);
}

TEST(HilReportLogs, ScenarioFiguresAndKilledNodes) {
  const auto d = temp_dir();
  Logged r = logged_run(1200);
  BenchScenario sc;
  sc.file = "valve.toml";
  sc.mode = CompensationMode::fixed;
  sc.score_t0_s = 1.0;
  sc.score_t1_s = 5.0;
  sc.first_drift_s = 3.0;
  write_logs(d, r);
  {
    const RunReport a = report_in_memory(d / "master.csv", d / "slave.csv", r, &sc);
    const RunReport b = report_streamed(d / "master.csv", d / "slave.csv", r, &sc);
    EXPECT_EQ(run_report_json(a), run_report_json(b));
    ASSERT_TRUE(b.scenario.has_value());
    EXPECT_EQ(b.scenario->window.samples, 801u);           // t = 1.000 … 5.000 s
    EXPECT_EQ(b.scenario->before_drift->samples, 600u);    // t = 0 … 2.995 s
    EXPECT_EQ(b.scenario->after_drift->samples, 600u);     // t = 3.000 … 5.995 s
    EXPECT_DOUBLE_EQ(b.scenario->after_drift->t1_s, 6.0);
  }
  // The slave killed at step 700 mid-line: the replay stops where its schedule does.
  r.slave.log.resize(700);
  r.slave.loop.records.resize(700);
  write_logs(d, r);
  { std::ofstream(d / "slave.csv", std::ios::app) << "700,3.5,2,69"; }
  // The master killed too, its last line cut.
  { std::ofstream(d / "master.csv", std::ios::app) << "1201,6.005,2"; }
  {
    const RunReport a = report_in_memory(d / "master.csv", d / "slave.csv", r, &sc);
    const RunReport b = report_streamed(d / "master.csv", d / "slave.csv", r, &sc);
    EXPECT_EQ(run_report_json(a), run_report_json(b));
    EXPECT_EQ(b.observed_schedule_note,
              "replayed the first 700 control steps: the slave's log ends before the master's");
    EXPECT_EQ(b.vs_observed_schedule->compared, 700u);
    EXPECT_EQ(b.scenario->window.samples, 500u);        // t = 1.000 … 3.495 s
    ASSERT_TRUE(b.scenario->after_drift.has_value());
    EXPECT_EQ(b.scenario->after_drift->samples, 100u);  // t = 3.000 … 3.495 s
    EXPECT_DOUBLE_EQ(b.scenario->after_drift->t1_s, 3.5);
    const NodeLogScan s = scan_slave_log(d / "slave.csv");
    EXPECT_EQ(s.read.rows, 700u);
    EXPECT_EQ(s.read.cut_lines, 1u);
  }
  // A slave log ending inside the step's window: no step figures, either way.
  r = logged_run(1200);
  r.slave.log.resize(250);  // the window of the step at 1 s runs to 2 s
  r.slave.loop.records.resize(250);
  write_logs(d, r);
  {
    const RunReport a = report_in_memory(d / "master.csv", d / "slave.csv", r, nullptr);
    const RunReport b = report_streamed(d / "master.csv", d / "slave.csv", r, nullptr);
    EXPECT_EQ(run_report_json(a), run_report_json(b));
    EXPECT_FALSE(b.step.has_value());
  }
  std::filesystem::remove_all(d);
}

// `lash hil simulate --schedule` in constant memory (ScheduleFiles, TraceCompare) against the
// schedule and trace read whole (read_schedule, read_master_trace): the same CSV, byte for byte,
// and the same differences from the log; the same errors for a bad log.
TEST(HilReportLogs, ScheduleFilesEqualTheScheduleReadWhole) {
  const auto d = temp_dir();
  Logged r = logged_run(1200);
  r.slave.log.resize(700);  // a slave killed first: the replay stops where its schedule does
  r.slave.loop.records.resize(700);
  write_logs(d, r);
  const BenchLayout L;
  FrameSchedule fs = read_schedule(d / "master.csv", d / "slave.csv");
  const std::size_t kept = replayable_control_steps(fs);
  fs.master.resize(kept);
  const std::vector<MasterStepLog> trace = read_master_trace(d / "master.csv");
  const SimulationFileRun a = simulate_to_csv(L, master_cfg(), slave_cfg(), fs, kT, d / "a.csv", nullptr, &trace);

  ScheduleFiles sf(d / "master.csv", d / "slave.csv");
  EXPECT_EQ(sf.logged_control_steps(), 1200u);
  EXPECT_EQ(sf.slave_steps(), 700u);
  EXPECT_EQ(sf.replayable(), 700u);  // control step 700 uses slave step 700's frame
  EXPECT_EQ(kept, 700u);
  EXPECT_EQ(sf.calibration().size(), fs.calibration.size());
  sf.limit(sf.replayable());
  const SimulationFileRun b = simulate_to_csv(L, master_cfg(), slave_cfg(), sf, kT, d / "b.csv", nullptr, d / "master.csv");
  auto text = [](const std::filesystem::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(a.rows, 700u);
  EXPECT_EQ(b.rows, a.rows);
  EXPECT_EQ(text(d / "a.csv"), text(d / "b.csv"));
  ASSERT_TRUE(a.vs_log && b.vs_log);
  EXPECT_EQ(b.vs_log->compared, 700u);
  EXPECT_EQ(b.vs_log->compared, a.vs_log->compared);
  EXPECT_EQ(b.vs_log->max_abs_diff_kPa, a.vs_log->max_abs_diff_kPa);
  EXPECT_EQ(b.vs_log->max_abs_diff_mA, a.vs_log->max_abs_diff_mA);
  EXPECT_EQ(b.vs_log->first_diff_step, a.vs_log->first_diff_step);
  EXPECT_EQ(*b.vs_log->first_diff_step, 300);  // the altered row: the replay equals the log before it
  EXPECT_DOUBLE_EQ(b.vs_log->max_abs_diff_kPa, 0.25);

  // A bad value: the same file, line and column either way.
  {
    std::string s = text(d / "slave.csv");
    const std::size_t line3 = s.find('\n', s.find('\n') + 1) + 1;  // the second row
    std::string row = s.substr(line3, s.find('\n', line3) - line3);
    std::size_t c = 0;
    for (int k = 0; k < 4; ++k) c = row.find(',', c) + 1;  // command_fresh is the 5th column
    row.replace(c, row.find(',', c) - c, "2");
    s.replace(line3, s.find('\n', line3) - line3, row);
    std::ofstream(d / "bad.csv") << s;
  }
  std::string e1, e2;
  int l1 = 0, l2 = 0;
  try {
    (void)read_schedule(d / "master.csv", d / "bad.csv");
  } catch (const InputError& e) {
    e1 = e.field();
    l1 = e.line();
  }
  try {
    ScheduleFiles bad(d / "master.csv", d / "bad.csv");
  } catch (const InputError& e) {
    e2 = e.field();
    l2 = e.line();
  }
  EXPECT_EQ(e1, "command_fresh");
  EXPECT_EQ(l1, 3);
  EXPECT_EQ(e2, e1);
  EXPECT_EQ(l2, l1);
  std::filesystem::remove_all(d);
}
