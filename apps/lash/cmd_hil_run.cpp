// lash hil run / simulate: the two-process session with its report, and the simulation.
#include <cstdio>
#include <filesystem>

#include <fmt/core.h>

#include "cmd_hil.hpp"
#include "console_options.hpp"
#include "lash/hil/report.hpp"
#include "lash/hil/schedule.hpp"
#include "lash/hil/session.hpp"
#include "lash/hil/sim_run.hpp"
#include "lash/hil/simulate.hpp"

namespace lash::cli::hilcli {
namespace {

struct RunOptions {
  CommonOptions common;
  double duration = 5.0;
  std::string reference = "step:from=500,to=1500,time=1";
  std::string out_dir = "hil-out";
  bool json_out = false;
  bool duration_given = false;
  bool no_isolate = false;
  bool restart_slave = false;
  std::int64_t seed = -1;
  int slave_cpu = -1;
  std::string xcp = "on";
  ConsoleArgs console;
};

struct SimulateOptions {
  std::string config;
  double step_ms = 0.0;
  double duration = 5.0;
  std::string reference = "step:from=500,to=1500,time=1";
  std::int64_t seed = -1;
  std::string out = "hil_sim.csv";
  CommonOptions scenario;  // --scenario, --compensation
  bool duration_given = false;
  std::string schedule, slave_schedule;
};

// --scenario runs: the tracking figures (the keys of `lash closed-loop --json`).
void print_scenario(const hil::ScenarioFigures& f) {
  auto line = [](const char* what, const hil::Tracking& t) {
    fmt::print("tracking {} [{}, {}] s: rms error {:.6g} kPa, max |error| {:.6g} kPa ({} samples)\n", what,
               format_double(t.t0_s), format_double(t.t1_s), t.rms_error, t.max_abs_error, t.samples);
  };
  const auto& c = f.compensation;
  fmt::print("scenario {} (pilot_valve), compensation {}\n", f.file, to_string(f.mode));
  line("over the score window", f.window);
  if (f.before_drift) line("before the drift", *f.before_drift);
  if (f.after_drift) line("after the drift ", *f.after_drift);
  fmt::print("inverse at the end: right {:.6g} mA, left {:.6g} mA; {} parameter updates; adaptation: {} ({})\n",
             c.right, c.left, c.updates, to_string(c.reason), c.estimator_reason);
}

void print_node(const char* who, const hil::NodeFigures& n) {
  fmt::print("{:<7} TET [us] mean {:7.3f} min {:7.3f} max {:8.3f} std {:7.3f} p99 {:8.3f} | CAN I/O [us] mean {:7.2f} "
             "p99 {:8.2f} | cycle [us] mean {:7.2f} max {:8.2f}\n",
             who, n.tet_us.mean, n.tet_us.min, n.tet_us.max, n.tet_us.std, n.tet_us.p99, n.io_us.mean, n.io_us.p99,
             n.cycle_us.mean, n.cycle_us.max);
  fmt::print("{:<7} wake-up latency [us] mean {:7.2f} p99 {:8.2f} max {:8.2f} | overruns {} | cpu_dma_latency {}\n", "",
             n.wake_latency_us.mean, n.wake_latency_us.p99, n.wake_latency_us.max, n.overruns,
             n.dma_latency_held ? "held at 0" : "not held");
}

void print_exit(const char* who, const hil::NodeExit& e) {
  if (e.signal)
    fmt::print("{} killed by signal {} at t = {:.3f} s\n", who, e.signal, e.t_s);
  else if (e.status != 0)
    fmt::print("{} exited with status {} at t = {:.3f} s\n", who, e.status, e.t_s);
}

void print_report(const hil::RunReport& r) {
  fmt::print("lash hil run: {} s at {} ms, reference {}, bus {} in a {}\n", format_double(r.duration_s),
             format_double(r.step_s * 1e3), r.reference, r.bus, r.isolation);
  if (r.interrupted) fmt::print("INTERRUPTED by signal {}: the logs end where the nodes stopped\n", r.interrupt_signal);
  print_exit("master", r.master_exit);
  for (const auto& e : r.slave_exits) print_exit("slave", e);
  for (const auto& g : r.restarts)
    if (g.restarted_s >= 0)
      fmt::print("slave died at t = {:.3f} s and was restarted at t = {:.3f} s (gap {:.3f} s)\n", g.died.t_s,
                 g.restarted_s, g.gap_s());
  auto recovered = [](const char* who, const std::optional<hil::LogRecovery>& rec) {
    if (rec)
      fmt::print("{} handed nothing over (killed): recovered {} rows up to t = {:.3f} s from {}{}\n", who, rec->rows,
                 rec->last_t_s, rec->file, rec->cut_lines ? " (an unfinished last line dropped)" : "");
  };
  recovered("master", r.master_recovered);
  recovered("slave", r.slave_recovered);
  if (!r.have_master) {
    fmt::print("no master log (the master handed nothing over and left no row in master.csv)\n");
    return;
  }
  fmt::print("CCP handshake {:.4f} s; {} control steps\n", r.handshake_s, r.control_steps);
  print_node("master", r.master);
  if (r.have_slave) print_node("slave", r.slave);
  fmt::print("frames: sent {} received {} late {} lost {}\n", r.frames.sent, r.frames.received, r.frames.late,
             r.frames.lost);
  if (r.step) {
    const auto& w = r.step->window;
    const auto& p = r.step->plant;
    fmt::print("step {} -> {} kPa at {} s: 90% rise {:.4f} s, 10% settling {:.4f} s, overshoot {:.1f} % (plant pressure",
               format_double(w.y0), format_double(w.y1), format_double(w.t_step_s), p.rise_s, p.settling_s,
               p.overshoot_pct);
    if (r.step->measured)
      fmt::print("; measured: {:.4f} s, {:.4f} s, {:.1f} %", r.step->measured->rise_s, r.step->measured->settling_s,
                 r.step->measured->overshoot_pct);
    fmt::print(")\n");
  } else {
    fmt::print("step response: no reference step held >= 0.5 s in this run\n");
  }
  fmt::print("max |emulation - simulation|: {} kPa, {} mA over {} steps ({} steps used an off-schedule frame)\n",
             format_double(r.vs_simulation.max_abs_diff_kPa), format_double(r.vs_simulation.max_abs_diff_mA),
             r.vs_simulation.compared, r.off_schedule);
  if (r.vs_observed_schedule)
    fmt::print("max |emulation - simulation of the observed schedule|: {} kPa, {} mA over {} steps\n",
               format_double(r.vs_observed_schedule->max_abs_diff_kPa),
               format_double(r.vs_observed_schedule->max_abs_diff_mA), r.vs_observed_schedule->compared);
  else
    fmt::print("observed schedule: {}\n", r.observed_schedule_note);
  if (r.scenario) print_scenario(*r.scenario);
  fmt::print("logs in {}/ (master.csv, master.events.csv, master_bus.log, slave.csv, slave.events.csv, *.json, "
             "report.json)\n",
             r.out_dir);
}

int run_run(const RunOptions& o) {
  hil::SessionOptions so;
  so.settings = load_settings(o.common);
  if (o.seed >= 0) so.settings.plant.seed = static_cast<std::uint64_t>(o.seed);
  so.config = settings_path(o.common);
  so.loop = loop_options(o.common, so.settings);
  so.slave_cpu = o.slave_cpu;
  so.duration_s = o.duration;
  if (so.settings.scenario) {  // the scenario's duration unless --duration is given
    if (!o.duration_given) so.duration_s = so.settings.scenario->duration_s;
    so.scenario = o.common.scenario;
    so.compensation = o.common.compensation;
  }
  so.controller = controller_override_keys(o.common.controller);
  so.node_command = {"/proc/self/exe", "hil", "node"};  // `lash hil node LAUNCH.json` (cmd_hil_nodes.cpp)
  so.reference = o.reference;
  so.out_dir = o.out_dir;
  so.isolate = !o.no_isolate;
  so.restart_slave = o.restart_slave;
  so.xcp = o.xcp == "on";
  so.validate();
  std::unique_ptr<HilConsole> con;  // bound here, in the host's network namespace
  if (o.console.enabled()) {
    if (!so.xcp) throw InputError("", 0, "--console", "needs the master's XCP slave (not --xcp off)");
    con = std::make_unique<HilConsole>(o.console, so.settings, o.out_dir);
    so.on_nodes_started = [&con] { con->start(); };
  }
  hil::install_session_signal_handlers();
  hil::Session session(so);
  const hil::RunReport r =
      session.run([](const std::string& line) { fmt::print(stderr, "lash hil run: {}\n", line); });
  if (con) con->stop();
  if (o.json_out) {
    std::fputs(hil::run_report_json(r).c_str(), stdout);
  } else {
    print_report(r);
  }
  if (r.interrupted) return 128 + r.interrupt_signal;
  // A slave the watchdog replaced is reported, not a failure; the last one must end cleanly.
  bool ok = r.have_master && r.master_exit.status == 0 && !r.slave_exits.empty() && r.slave_exits.back().status == 0;
  for (const auto& g : r.restarts) ok = ok && g.restarted_s >= 0;
  if (!ok) fmt::print(stderr, "lash hil run: a node failed (see {}/report.json)\n", o.out_dir);
  return ok ? kExitOk : kExitFailed;
}

int run_simulate(const SimulateOptions& o) {
  CommonOptions co;
  co.config = o.config;
  co.step_ms = o.step_ms;
  co.scenario = o.scenario.scenario;
  co.compensation = o.scenario.compensation;
  co.compensation_given = o.scenario.compensation_given;
  co.controller = o.scenario.controller;
  hil::BenchSettings s = load_settings(co);
  const double duration = s.scenario && !o.duration_given ? s.scenario->duration_s : o.duration;
  if (o.seed >= 0) s.plant.seed = static_cast<std::uint64_t>(o.seed);
  const hil::BenchLayout L = hil::BenchLayout::from_dbc(s.dbc_file);
  const hil::SlaveConfig sc = hil::slave_config(s, L);
  const hil::MasterConfig mc = hil::master_config(s, o.reference);
  hil::SimulationFileRun run;
  std::size_t N = 0;
  if (o.schedule.empty()) {  // streamed: memory independent of --duration (docs/hil.md)
    N = hil::steps_for(duration, s.step_s, "--duration");
    run = hil::simulate_to_csv(L, mc, sc, hil::lazy_ideal_schedule(N), s.step_s, o.out,
                               s.scenario ? &*s.scenario : nullptr);
  } else {  // the run's own schedule: as many control steps as master.csv holds
    const std::filesystem::path mpath(o.schedule);
    const std::filesystem::path spath =
        o.slave_schedule.empty() ? mpath.parent_path() / "slave.csv" : std::filesystem::path(o.slave_schedule);
    hil::ScheduleFiles fs(mpath, spath);  // read as the replay goes: memory independent of the log's length
    const std::size_t logged = fs.logged_control_steps();
    const std::size_t kept = fs.replayable();
    if (kept < logged) {  // a slave killed before the master: its log ends first
      fmt::print("schedule of {}: the slave's log ({} steps) ends before the master's; replaying the first {} of {} "
                 "control steps\n",
                 o.schedule, fs.slave_steps(), kept, logged);
      fs.limit(kept);
    }
    run = hil::simulate_to_csv(L, mc, sc, fs, s.step_s, o.out, s.scenario ? &*s.scenario : nullptr, mpath);
    fmt::print("schedule of {} ({} control steps): max |log - simulation| {} kPa, {} mA over {} steps\n", o.schedule,
               fs.master_steps(), format_double(run.vs_log->max_abs_diff_kPa),
               format_double(run.vs_log->max_abs_diff_mA), run.vs_log->compared);
  }
  fmt::print(stderr, "lash hil simulate: {} steps at {} ms -> {}\n", run.rows, format_double(s.step_s * 1e3), o.out);
  if (run.scenario) {
    print_scenario(*run.scenario);
    return kExitOk;
  }
  if (const auto& sr = run.step)
    fmt::print("step {} -> {} kPa at t = {} s: 90% rise {:.4f} s, 10% settling {:.4f} s, overshoot {:.1f} %\n",
               format_double(sr->window.y0), format_double(sr->window.y1), format_double(sr->window.t_step_s),
               sr->plant.rise_s, sr->plant.settling_s, sr->plant.overshoot_pct);
  return kExitOk;
}

}  // namespace

void add_hil_run(CLI::App* hil, std::function<int()>& run_selected) {
  auto ro = std::make_shared<RunOptions>();
  auto* run = hil->add_subcommand("run", "Slave and master as two processes on a private UDP bus; report");
  add_common(run, ro->common);
  add_duration(run, ro->duration, "Control time (with --scenario: the scenario's duration_s)")
      ->each([ro](const std::string&) { ro->duration_given = true; });
  add_scenario(run, ro->common);
  add_controller(run, ro->common);
  run->add_option("--reference", ro->reference, "Reference (see `lash hil master --help`)");
  run->add_option("--out-dir", ro->out_dir, "Where the logs go (the files of a run are replaced, never mixed)");
  run->add_option("--seed", ro->seed, "Noise seed of the plant (-1 = from the settings)")
      ->check(CLI::Range(std::int64_t{-1}, INT64_MAX));
  run->add_flag("--json", ro->json_out, "Print the report as one JSON object");
  run->add_flag("--no-isolate", ro->no_isolate, "Use the host's network instead of a private namespace");
  run->add_flag("--restart-slave", ro->restart_slave, "Watchdog: start a slave that died again (the report shows the gap)");
  run->add_option("--slave-cpu", ro->slave_cpu, "Pin the slave to this CPU (-1 = as --cpu, which pins the master)")
      ->check(CLI::Range(-1, 4095));
  run->add_option("--xcp", ro->xcp, "The master's XCP-on-CAN slave (docs/xcp.md): on | off")
      ->check(CLI::IsMember({"on", "off"}));
  add_console_options(run, ro->console);

  auto sio = std::make_shared<SimulateOptions>();
  auto* sim = hil->add_subcommand("simulate", "Closed-loop simulation through the nodes' step functions");
  sim->option_defaults()->always_capture_default();
  sim->add_option("--config", sio->config, "Node settings (TOML)");
  sim->add_option("--step-ms", sio->step_ms,
                  "Fixed step [ms], " + format_double(hil::kMinStepMs) + ".." + format_double(hil::kMaxStepMs) +
                      " (0 = from the settings)")
      ->check(CLI::Range(0.0, hil::kMaxStepMs));
  add_duration(sim, sio->duration, "Control time (with --scenario: the scenario's duration_s)")
      ->each([sio](const std::string&) { sio->duration_given = true; });
  add_scenario(sim, sio->scenario);
  add_controller(sim, sio->scenario);
  sim->add_option("--reference", sio->reference, "Reference (see `lash hil master --help`)");
  sim->add_option("--seed", sio->seed, "Noise seed of the plant (-1 = from the settings)")
      ->check(CLI::Range(std::int64_t{-1}, INT64_MAX));
  sim->add_option("-o,--output", sio->out, "Output CSV");
  sim->add_option("--schedule", sio->schedule,
                  "Replay the frame schedule a run logged: its master.csv (sensor_seq); runs as many control steps "
                  "as it holds (--duration unused) and prints the largest difference from the log [kPa, mA]")
      ->check(CLI::ExistingFile);
  auto* sched = sim->get_option("--schedule");
  sim->add_option("--slave-schedule", sio->slave_schedule,
                  "The run's slave.csv (command_counter, command_fresh); default: slave.csv beside --schedule")
      ->check(CLI::ExistingFile)
      ->needs(sched);

  run_selected = [=]() -> int {
    if (run->parsed()) return run_run(*ro);
    if (sim->parsed()) return run_simulate(*sio);
    return -1;
  };
}

}  // namespace lash::cli::hilcli
