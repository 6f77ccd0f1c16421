// lash hil slave / master / latency: one node (or the bare loop) in this process.
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cmd_hil.hpp"
#include "lash/can/log.hpp"
#include "lash/hil/handover.hpp"
#include "lash/hil/launch.hpp"
#include "lash/hil/node_report.hpp"
#include "lash/rt/dma_latency.hpp"

namespace lash::cli::hilcli {
namespace {

struct SlaveOptions {
  CommonOptions common;
  double duration = 600.0;
  std::string log = "slave.csv";
  std::string stats;
  std::int64_t seed = -1;
  double connect_timeout = 0.0;
  int result_fd = -1;
};

struct MasterOptions {
  CommonOptions common;
  double duration = 10.0;
  std::string reference = "step:from=500,to=1500,time=1";
  std::string log = "master.csv";
  std::string bus_log;
  std::string events;
  std::string stats;
  double dto_timeout = 0.0;
  std::string xcp = "on";
  int result_fd = -1;
};

struct LatencyOptions {
  CommonOptions common;
  double duration = 10.0;
  bool json_out = false;
};

void write_text(const std::string& path, const std::string& text) {
  AtomicFile f(path);
  f.stream() << text;
  f.commit();
}

void warn_all(const char* who, const std::vector<std::string>& warnings) {
  for (const auto& w : warnings) fmt::print(stderr, "lash hil {}: warning: {}\n", who, w);
}

void warn_ring(const char* who, const hil::LogStats& l) {
  if (l.ring_full > 0)
    fmt::print(stderr, "lash hil {}: warning: the log writer fell behind: {} log items were not written (ring full)\n",
               who, l.ring_full);
}

int run_slave(const SlaveOptions& o) {
  hil::BenchSettings s = load_settings(o.common);
  if (o.seed >= 0) s.plant.seed = static_cast<std::uint64_t>(o.seed);
  hil::SlaveRunOptions ro;
  ro.loop = loop_options(o.common, s);
  ro.duration_s = o.duration;
  ro.connect_timeout_s = o.connect_timeout;
  ro.logs.csv = o.log;
  ro.logs.events = std::filesystem::path(o.log).replace_extension("").string() + ".events.csv";
  (void)hil::steps_for(o.duration, s.step_s, "--duration");
  hil::install_node_signal_handlers();
  const hil::SlaveRun r = hil::run_slave_node(s, ro, hil::node_stop_flag(), [&](const std::string& address) {
    fmt::print("lash hil slave: ready on {} (step {} ms)\n", address, format_double(s.step_s * 1e3));
    std::fflush(stdout);
  });
  warn_all("slave", r.loop.warnings);
  if (o.result_fd >= 0) hil::write_run(o.result_fd, r);
  if (!r.stats.connected) {
    if (hil::node_stop_flag().load()) {
      fmt::print(stderr, "lash hil slave: stopped before a CCP CONNECT arrived\n");
      return kExitOk;
    }
    fmt::print(stderr, "lash hil slave: no CCP CONNECT within {} s on {}\n", format_double(o.connect_timeout), s.bus);
    return kExitFailed;
  }
  if (!o.stats.empty()) write_text(o.stats, hil::slave_stats_json(r));
  const auto& tet = r.stats.tet_us;
  const auto& f = r.stats.frames;
  fmt::print(stderr,
             "lash hil slave: {} steps ({}), TET mean {:.2f} us max {:.2f} us (CAN I/O mean {:.2f} us), overruns {}, "
             "commands received {} late {} lost {}; cpu_dma_latency {}\n",
             r.stats.result.steps, rt::to_string(r.stats.result.reason), tet.mean, tet.max, r.stats.io_us.mean,
             r.stats.result.overruns, f.received, f.late, f.lost, r.stats.dma_latency_held ? "held at 0" : "not held");
  warn_ring("slave", r.stats.logs);
  return kExitOk;
}

int run_master(const MasterOptions& o) {
  const hil::BenchSettings s = load_settings(o.common);
  hil::MasterRunOptions ro;
  ro.loop = loop_options(o.common, s);
  ro.duration_s = o.duration;
  ro.reference = o.reference;
  ro.dto_timeout_s = o.dto_timeout;
  ro.xcp = o.xcp == "on";
  ro.logs.csv = o.log;
  ro.logs.events =
      o.events.empty() ? (std::filesystem::path(o.log).replace_extension("").string() + ".events.csv") : o.events;
  ro.logs.bus_log = o.bus_log;
  if (!o.bus_log.empty() && can::log_format_of(o.bus_log) != can::LogFormat::candump)
    throw InputError("", 0, "--bus-log", "the bus log is written while the master runs, as candump -L text: give a "
                                         "name that does not end in .asc, .blf or .trc (got " + o.bus_log + ")");
  (void)hil::parse_reference(o.reference);
  (void)hil::steps_for(o.duration, s.step_s, "--duration");
  hil::install_node_signal_handlers();
  const hil::MasterRun r = hil::run_master_node(s, ro, hil::node_stop_flag());
  warn_all("master", r.loop.warnings);
  if (o.result_fd >= 0) hil::write_run(o.result_fd, r);
  if (!o.stats.empty()) write_text(o.stats, hil::master_stats_json(r, o.reference));
  for (const auto& e : r.events)
    fmt::print(stderr, "lash hil master: t = {:.3f} s (step {}): {}\n", e.t_s, e.step, to_string(e.kind));
  if (r.stats.state == hil::MasterState::failed) {
    fmt::print(stderr,
               "lash hil master: error: no positive DTO reply to CCP CONNECT within {} s on {} — is a slave running "
               "on this bus?\n",
               format_double(o.dto_timeout > 0 ? o.dto_timeout : s.dto_timeout_s), s.bus);
    return kExitFailed;
  }
  const auto& tet = r.stats.tet_us;
  const auto& f = r.stats.frames;
  warn_ring("master", r.stats.logs);
  fmt::print(stderr,
             "lash hil master: {} steps ({}), handshake {:.4f} s, TET mean {:.2f} us max {:.2f} us, overruns {}, "
             "sensor frames received {} late {} lost {}; cpu_dma_latency {}\n",
             r.stats.result.steps, rt::to_string(r.stats.result.reason), r.stats.handshake_s, tet.mean, tet.max,
             r.stats.result.overruns, f.received, f.late, f.lost, r.stats.dma_latency_held ? "held at 0" : "not held");
  return kExitOk;
}

/// A node started by `lash hil run` from its launch file (hil/launch.hpp): the launch's fields
/// become the options of `lash hil slave` / `lash hil master`.
int run_node(const std::string& launch_file) {
  const hil::NodeLaunch l = hil::read_launch(launch_file);
  CommonOptions c;
  c.config = l.config.string();
  c.bus = l.bus;
  c.step_ms = l.step_s * 1e3;
  c.fifo = l.loop.fifo;
  c.cpu = l.loop.cpu;
  c.spin_us = l.loop.spin_us;
  c.lock_memory = l.loop.lock_memory;
  c.no_dma_latency = !l.loop.hold_dma_latency;
  c.overrun_policy = l.loop.policy == rt::OverrunPolicy::stop ? "stop" : "tolerate";
  c.max_overruns = l.loop.max_overruns;
  c.scenario = l.scenario.string();
  if (!c.scenario.empty()) {
    c.compensation = l.compensation;
    c.compensation_given = true;
  }
  c.controller = controller_overrides_from_keys(l.controller, launch_file);
  if (l.role == hil::NodeLaunch::Role::slave) {
    SlaveOptions o;
    o.common = c;
    o.duration = l.duration_s;
    o.log = l.logs.csv.string();
    o.stats = l.stats.string();
    o.seed = l.seed;
    o.connect_timeout = l.connect_timeout_s;
    o.result_fd = l.result_fd;
    return run_slave(o);
  }
  MasterOptions o;
  o.common = c;
  o.duration = l.duration_s;
  o.reference = l.reference;
  o.log = l.logs.csv.string();
  o.bus_log = l.logs.bus_log.string();
  o.events = l.logs.events.string();
  o.stats = l.stats.string();
  o.dto_timeout = l.dto_timeout_s;
  o.xcp = l.xcp ? "on" : "off";
  o.result_fd = l.result_fd;
  return run_master(o);
}

/// The periodic loop alone, no bus and no task (like cyclictest).
int run_latency(const LatencyOptions& o) {
  const hil::BenchSettings s = load_settings(o.common);
  const hil::LoopOptions lo = loop_options(o.common, s);
  const std::size_t steps = hil::steps_for(o.duration, s.step_s, "--duration");
  rt::LoopConfig lc = hil::make_loop_config(lo, steps);
  lc.keep_records = false;  // statistics over a stream: memory independent of --duration
  rt::PeriodicLoop loop(lc);
  rt::StreamSummary wake(steps);
  hil::install_node_signal_handlers();
  const auto warnings = loop.apply_realtime_settings();
  warn_all("latency", warnings);
  rt::RunResult r;
  bool held = false;
  {
    const rt::DmaLatencyHold dma(lo.hold_dma_latency);
    held = dma.held();
    r = loop.run_with_io([]() noexcept {}, [](std::size_t, std::int64_t) noexcept { return true; }, []() noexcept {},
                         [&](std::size_t, const rt::StepRecord& rec) noexcept {
                           wake.add(static_cast<double>(rec.wake_latency_ns) * 1e-3);
                         },
                         hil::node_stop_flag());
  }
  const auto w = wake.result();
  if (o.json_out) {
    nlohmann::json j{{"steps", r.steps},
                     {"stop_reason", rt::to_string(r.reason)},
                     {"overruns", r.overruns},
                     {"step_s", s.step_s},
                     {"dma_latency_held", held},
                     {"warnings", warnings},
                     {"wake_latency_us",
                      {{"n", w.n}, {"mean", w.mean}, {"min", w.min}, {"max", w.max}, {"std", w.std}, {"p99", w.p99}}}};
    fmt::print("{}\n", j.dump(2));
  } else {
    fmt::print("lash hil latency: {} steps of {} ms ({}): wake-up latency [us] mean {:.2f} min {:.2f} p99 {:.2f} "
               "max {:.2f} std {:.2f}; overruns {}; cpu_dma_latency {}\n",
               r.steps, format_double(s.step_s * 1e3), rt::to_string(r.reason), w.mean, w.min, w.p99, w.max, w.std,
               r.overruns, held ? "held at 0" : "not held");
    for (const auto& e : loop.overruns())
      fmt::print("  overrun at step {} (t = {:.3f} s): {:.1f} us late\n", e.step, static_cast<double>(e.t_ns) * 1e-9,
                 static_cast<double>(e.late_ns) * 1e-3);
  }
  return kExitOk;
}

}  // namespace

void add_hil_nodes(CLI::App* hil, std::function<int()>& run_selected) {
  auto so = std::make_shared<SlaveOptions>();
  auto* slave = hil->add_subcommand("slave", "Slave ECU + pilot-valve plant emulator");
  add_common(slave, so->common);
  add_scenario(slave, so->common);
  add_controller(slave, so->common);
  add_duration(slave, so->duration, "Longest run; stops earlier on SIGINT/SIGTERM/SIGHUP");
  slave->add_option("--log", so->log, "Per-step CSV log");
  slave->add_option("--stats", so->stats, "Statistics JSON");
  slave->add_option("--seed", so->seed, "Noise seed (-1 = from the settings)")->check(CLI::Range(std::int64_t{-1}, INT64_MAX));
  slave->add_option("--connect-timeout", so->connect_timeout, "Give up without a CCP CONNECT after this long [s] (0 = wait)")
      ->check(CLI::Range(0.0, 1e6));
  slave->add_option("--result-fd", so->result_fd, "")->group("");  // hand-over to `hil run`

  auto mo = std::make_shared<MasterOptions>();
  auto* master = hil->add_subcommand("master", "Master ECU: CCP connect, then PID + deadzone inverse + saturation");
  add_common(master, mo->common);
  add_scenario(master, mo->common);
  add_controller(master, mo->common);
  add_duration(master, mo->duration, "Control time after the CCP handshake");
  master->add_option("--reference", mo->reference,
                     "KIND:key=value,... ; step:from=,to=,time= | square|sine|triangle:amplitude=,offset=,"
                     "frequency= [rad/s] or frequency_hz= | random:variance=,tau=,offset= | constant:amplitude=");
  master->add_option("--log", mo->log, "Per-step CSV log");
  master->add_option("--bus-log", mo->bus_log, "candump -L log of the frames the master sent and received (wall clock)");
  master->add_option("--events", mo->events, "Events CSV (default: <log>.events.csv)");
  master->add_option("--stats", mo->stats, "Statistics JSON");
  master->add_option("--dto-timeout", mo->dto_timeout, "Give up without a DTO reply after this long [s] (0 = from the settings)")
      ->check(CLI::Range(0.0, 3600.0));
  master->add_option("--xcp", mo->xcp, "XCP-on-CAN slave for calibration and DAQ (docs/xcp.md): on | off")
      ->check(CLI::IsMember({"on", "off"}));
  master->add_option("--result-fd", mo->result_fd, "")->group("");

  auto lo = std::make_shared<LatencyOptions>();
  auto* lat = hil->add_subcommand("latency", "The periodic loop alone (no bus, no task): wake-up latency and overruns");
  add_common(lat, lo->common);
  add_duration(lat, lo->duration, "Measurement time");
  lat->add_flag("--json", lo->json_out, "Print the statistics as one JSON object");

  auto launch = std::make_shared<std::string>();
  auto* node = hil->add_subcommand("node", "A node of `lash hil run`, from its launch file");
  node->group("");  // hidden: started by `lash hil run` (hil/launch.hpp)
  node->add_option("launch", *launch, "Launch file (JSON) written by `lash hil run`")->required();

  run_selected = [=]() -> int {
    if (node->parsed()) return run_node(*launch);
    if (slave->parsed()) return run_slave(*so);
    if (master->parsed()) return run_master(*mo);
    if (lat->parsed()) return run_latency(*lo);
    return -1;
  };
}

}  // namespace lash::cli::hilcli
