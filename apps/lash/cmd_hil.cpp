// lash hil: real-time HIL emulation of the hydraulic bench (thesis paper 2, SPEC B).
//   lash hil slave    — slave ECU + pilot-valve plant emulator on a bus
//   lash hil master   — master ECU (CCP connect, PID + deadzone inverse + saturation)
//   lash hil run      — both as separate processes on a private UDP bus, with a report
//   lash hil simulate — the same step functions in a closed-loop simulation
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "lash/can/bus.hpp"
#include "lash/can/controller_bus.hpp"
#include "lash/can/log.hpp"
#include "lash/control/step_metrics.hpp"
#include "lash/hil/netns.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/hil/report.hpp"
#include "lash/hil/settings.hpp"
#include "lash/hil/simulate.hpp"
#include "lash/rt/periodic.hpp"

namespace lash::cli {
namespace {

using nlohmann::json;

std::atomic<bool> g_stop{false};

extern "C" void on_stop_signal(int) { g_stop.store(true); }

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: clock_nanosleep and blocking receives return EINTR
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

// ----------------------------------------------------------------------------- shared options

struct CommonOptions {
  std::string config;
  std::string bus;
  double step_ms = 0.0;  // 0 = from the settings file
  int fifo = 0;
  int cpu = -1;
  double spin_us = 0.0;
  bool lock_memory = false;
  std::string overrun_policy = "tolerate";
  std::size_t max_overruns = 10;
};

void add_common(CLI::App* sub, CommonOptions& o) {
  sub->add_option("--config", o.config, "Node settings (TOML); default config/hil/bench.toml");
  sub->add_option("--bus", o.bus, "Bus address (udp:GROUP:PORT, mem:NAME, socketcan:IF); default from the settings");
  sub->add_option("--step-ms", o.step_ms, "Fixed step [ms]; default from the settings (5 ms)");
  sub->add_option("--fifo", o.fifo, "SCHED_FIFO priority 1-99 (0 = default scheduler)");
  sub->add_option("--cpu", o.cpu, "Pin the loop to this CPU");
  sub->add_option("--spin-us", o.spin_us, "Wake this long before each release and busy-wait to it [us] (0 = sleep only)");
  sub->add_flag("--lock-memory", o.lock_memory, "mlockall() the process");
  sub->add_option("--overrun-policy", o.overrun_policy, "tolerate | stop");
  sub->add_option("--max-overruns", o.max_overruns, "Policy stop: stop after this many consecutive overruns");
}

hil::BenchSettings load_settings(const CommonOptions& o) {
  const std::filesystem::path file =
      o.config.empty() ? hil::default_settings_path(source_dir()) : std::filesystem::path(o.config);
  hil::BenchSettings s = hil::load_bench_settings(file);
  for (const auto& w : s.warnings) fmt::print(stderr, "lash: warning: {}\n", w);
  if (!o.bus.empty()) s.bus = o.bus;
  if (o.step_ms != 0.0) {
    if (!(o.step_ms > 0) || !std::isfinite(o.step_ms)) throw InputError("", 0, "--step-ms", "must be > 0 [ms]");
    s.set_step(o.step_ms * 1e-3);
  }
  return s;
}

rt::LoopConfig loop_config(const CommonOptions& o, double step_s, std::size_t steps) {
  rt::LoopConfig c;
  c.period_ns = static_cast<std::int64_t>(std::llround(step_s * 1e9));
  c.max_steps = steps;
  if (o.fifo < 0 || o.fifo > 99) throw InputError("", 0, "--fifo", "must be in 0..99");
  c.fifo_priority = o.fifo;
  c.cpu = o.cpu;
  if (!(o.spin_us >= 0) || !std::isfinite(o.spin_us)) throw InputError("", 0, "--spin-us", "must be >= 0 [us]");
  c.spin_ns = static_cast<std::int64_t>(std::llround(o.spin_us * 1e3));
  if (c.spin_ns >= c.period_ns) throw InputError("", 0, "--spin-us", "must be shorter than the step");
  c.lock_memory = o.lock_memory;
  if (o.overrun_policy == "tolerate")
    c.policy = rt::OverrunPolicy::tolerate;
  else if (o.overrun_policy == "stop")
    c.policy = rt::OverrunPolicy::stop;
  else
    throw InputError("", 0, "--overrun-policy", "expected tolerate or stop, got '" + o.overrun_policy + "'");
  if (o.max_overruns == 0) throw InputError("", 0, "--max-overruns", "must be >= 1");
  c.max_consecutive_overruns = o.max_overruns;
  return c;
}

std::size_t steps_for(double duration_s, double step_s, const char* option) {
  if (!(duration_s > 0) || !std::isfinite(duration_s)) throw InputError("", 0, option, "must be > 0 [s]");
  const double n = std::round(duration_s / step_s);
  if (n > 1e8) throw InputError("", 0, option, "too many steps (> 1e8)");
  return static_cast<std::size_t>(std::max(1.0, n));
}

json summary_json(const rt::Summary& s) {
  return json{{"n", s.n}, {"mean", s.mean}, {"min", s.min}, {"max", s.max}, {"std", s.std}, {"p99", s.p99}};
}

json loop_json(const rt::PeriodicLoop& loop, const rt::RunResult& r, const std::vector<std::string>& warnings) {
  json j;
  j["steps"] = r.steps;
  j["stop_reason"] = rt::to_string(r.reason);
  j["tet_us"] = summary_json(loop.tet_us());
  j["io_us"] = summary_json(loop.io_us());
  j["cycle_us"] = summary_json(loop.cycle_us());
  j["wake_latency_us"] = summary_json(loop.wake_latency_us());
  j["overruns"] = r.overruns;
  json ov = json::array();
  for (const auto& e : loop.overruns()) ov.push_back({{"step", e.step}, {"t_s", static_cast<double>(e.t_ns) * 1e-9}, {"late_us", static_cast<double>(e.late_ns) * 1e-3}});
  j["overrun_events"] = ov;
  j["warnings"] = warnings;
  j["step_s"] = static_cast<double>(loop.config().period_ns) * 1e-9;
  return j;
}

void write_json(const std::string& path, const json& j) {
  AtomicFile f(path);
  f.stream() << j.dump(2) << '\n';
  f.commit();
}

double realtime_now_s() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

std::unique_ptr<can::Bus> open_node_bus(const std::string& address, const hil::BenchLayout& L, bool master) {
  auto bus = can::open_bus(address);
  if (master)
    bus->set_filters({{L.sensors_id, 0x7FF, false}, {L.dto_id, 0x7FF, false}});
  else
    bus->set_filters({{L.command_id, 0x7FF, false}, {L.cro_id, 0x7FF, false}});
  return bus;
}

/// The nodes' CAN controller: reception may take a fifth of the step, however hard the bus is
/// flooded (a babbling node); what is left waits on the wire for the next step.
can::ControllerConfig controller_config(std::int64_t period_ns) {
  can::ControllerConfig c;
  c.budget_ns = period_ns / 5;
  return c;
}

/// Receive statistics of one cyclic message, with the plausibility drops per reason (hil/e2e.hpp).
json frames_json(const hil::SeqTracker& t) {
  json drops = json::object();
  for (std::size_t i = 0; i < hil::kDropReasons; ++i)
    drops[hil::to_string(static_cast<hil::Drop>(i))] = t.drops.n[i];
  return json{{"received", t.received}, {"accepted", t.accepted}, {"late", t.late},
              {"lost", t.lost},         {"duplicates", t.drops[hil::Drop::repeated]}, {"resyncs", t.resyncs},
              {"dropped", t.drops.total()}, {"dropped_by_reason", drops}};
}

/// The safe-state machine's transitions (nodes.hpp).
json events_json(std::span<const hil::NodeEvent> events) {
  json ev = json::array();
  for (const auto& e : events)
    ev.push_back({{"step", e.step}, {"t_s", e.t_s}, {"event", to_string(e.kind)}, {"from", to_string(e.from)},
                  {"to", to_string(e.to)}});
  return ev;
}

void write_events(const std::string& path, std::span<const hil::NodeEvent> events) {
  AtomicFile f(path);
  f.stream() << "step,t_s,event,from,to\n";
  for (const auto& e : events)
    f.stream() << e.step << ',' << format_double(e.t_s) << ',' << to_string(e.kind) << ',' << to_string(e.from) << ','
               << to_string(e.to) << '\n';
  f.commit();
}

json controller_json(const can::ControllerBus& ctl) {
  const auto& cs = ctl.controller_stats();
  return json{{"rx_overflows", cs.rx_overflows}, {"tx_overflows", cs.tx_overflows}, {"tx_failures", cs.tx_failures},
              {"rx_reads", cs.rx_reads},         {"pulls_cut", cs.pulls_cut}};
}

// ----------------------------------------------------------------------------- slave

struct SlaveOptions {
  CommonOptions common;
  double duration = 600.0;
  std::string log = "slave.csv";
  std::string stats;
  std::int64_t seed = -1;
  double connect_timeout = 0.0;  // 0 = wait until stopped
};

int run_slave(const SlaveOptions& o) {
  install_stop_handlers();
  hil::BenchSettings s = load_settings(o.common);
  if (o.seed >= 0) s.plant.seed = static_cast<std::uint64_t>(o.seed);
  const hil::BenchLayout L = hil::BenchLayout::from_dbc(s.dbc_file);
  hil::SlaveConfig sc;
  sc.plant = s.plant;
  sc.dto_reply = hil::load_dto_reply(s.dto_log, L);
  const std::size_t steps = steps_for(o.duration, s.step_s, "--duration");
  sc.log_capacity = steps;
  hil::SlaveNode slave(L, sc);
  rt::LoopConfig lc = loop_config(o.common, s.step_s, steps);
  rt::PeriodicLoop loop(lc);
  const auto warnings = loop.apply_realtime_settings();
  for (const auto& w : warnings) fmt::print(stderr, "lash hil slave: warning: {}\n", w);
  auto bus = open_node_bus(s.bus, L, false);
  // The task sees an emulated CAN controller; its reception and transmission are the I/O phases.
  can::ControllerBus ctl(*bus, controller_config(lc.period_ns));
  fmt::print("lash hil slave: ready on {} (step {} ms)\n", bus->address(), format_double(s.step_s * 1e3));
  std::fflush(stdout);

  const std::int64_t t_open = rt::monotonic_ns();
  bool connected = false;
  while (!g_stop.load()) {
    if (slave.wait_connect(*bus, std::chrono::milliseconds(100))) {
      connected = true;
      break;
    }
    if (o.connect_timeout > 0 && static_cast<double>(rt::monotonic_ns() - t_open) * 1e-9 > o.connect_timeout) break;
  }
  if (!connected) {
    if (g_stop.load()) {
      fmt::print(stderr, "lash hil slave: stopped before a CCP CONNECT arrived\n");
      return kExitOk;
    }
    fmt::print(stderr, "lash hil slave: no CCP CONNECT (CRO id 0x{:X}) within {} s on {}\n", L.cro_id,
               format_double(o.connect_timeout), bus->address());
    return kExitFailed;
  }
  const std::int64_t t_connect = rt::monotonic_ns();
  fmt::print(stderr, "lash hil slave: CCP CONNECT answered with the recorded DTO; stepping\n");
  // The slave's grid sits half a period after the master's (see nodes.hpp). The loop and its
  // buffers exist already, so the first step is not delayed by allocation or page faults.
  loop.set_start_ns(t_connect + lc.period_ns / 2);
  const rt::RunResult r = loop.run_with_io(
      [&]() noexcept { ctl.pull(); },
      [&](std::size_t, std::int64_t t_ns) noexcept {
        slave.step(ctl, static_cast<double>(t_ns) * 1e-9);
        return true;
      },
      [&]() noexcept { ctl.flush(); }, g_stop);

  // Logs (after the run; the loop stopped at a step boundary).
  const auto log = slave.log();
  const auto rec = loop.records();
  std::vector<double> c_step, c_t, c_state, c_cnt, c_fresh, c_drop, c_i, c_p, c_y, c_raw, c_tet, c_io, c_lat;
  for (std::size_t i = 0; i < log.size(); ++i) {
    c_step.push_back(log[i].step);
    c_state.push_back(static_cast<double>(log[i].state));
    c_drop.push_back(log[i].dropped);
    c_t.push_back(static_cast<double>(rec[i].release_ns) * 1e-9);
    c_cnt.push_back(static_cast<double>(log[i].command_counter));
    c_fresh.push_back(log[i].command_fresh ? 1 : 0);
    c_i.push_back(log[i].current_mA);
    c_p.push_back(log[i].pressure_kPa);
    c_y.push_back(log[i].measured_kPa);
    c_raw.push_back(log[i].pilot_raw);
    c_tet.push_back(static_cast<double>(rec[i].tet_ns) * 1e-3);
    c_io.push_back(static_cast<double>(rec[i].io_ns) * 1e-3);
    c_lat.push_back(static_cast<double>(rec[i].wake_latency_ns) * 1e-3);
  }
  write_columns_csv(o.log,
                    {"step", "t_s", "state", "command_counter", "command_fresh", "dropped", "current_mA", "pressure_kPa",
                     "measured_kPa", "pilot_raw", "tet_us", "io_us", "wake_latency_us"},
                    {&c_step, &c_t, &c_state, &c_cnt, &c_fresh, &c_drop, &c_i, &c_p, &c_y, &c_raw, &c_tet, &c_io, &c_lat});
  json j = loop_json(loop, r, warnings);
  const auto& c = slave.commands();
  const auto bs = bus->stats();
  j["frames"] = frames_json(c);
  j["frames"].update({{"sent", slave.frames_sent()}, {"ignored", slave.ignored_frames()},
                      {"send_failures", slave.send_failures()}, {"bus_filtered", bs.filtered},
                      {"bus_dropped", bs.dropped}});
  j["state"] = to_string(slave.state());
  j["events"] = events_json(slave.events());
  j["can_controller"] = controller_json(ctl);
  j["dto_replies"] = slave.dto_replies();
  j["seed"] = s.plant.seed;
  if (!o.stats.empty()) write_json(o.stats, j);
  write_events(std::filesystem::path(o.log).replace_extension("").string() + ".events.csv", slave.events());
  const auto tet = loop.tet_us();
  fmt::print(stderr,
             "lash hil slave: {} steps ({}), TET mean {:.2f} us max {:.2f} us (CAN I/O mean {:.2f} us), overruns {}, "
             "commands received {} "
             "late {} lost {}\n",
             r.steps, rt::to_string(r.reason), tet.mean, tet.max, loop.io_us().mean, r.overruns, c.received, c.late,
             c.lost);
  return kExitOk;
}

// ----------------------------------------------------------------------------- master

struct MasterOptions {
  CommonOptions common;
  double duration = 10.0;
  std::string reference = "step:from=500,to=1500,time=1";
  std::string log = "master.csv";
  std::string bus_log;
  std::string events;
  std::string stats;
  double dto_timeout = 0.0;  // 0 = from settings
};

hil::MasterConfig master_config(const hil::BenchSettings& s, const std::string& reference, double dto_timeout) {
  hil::MasterConfig mc;
  mc.controller = s.controller;
  mc.reference = hil::parse_reference(reference);
  mc.dto_timeout_s = dto_timeout > 0 ? dto_timeout : s.dto_timeout_s;
  mc.fault_missed_periods = s.fault_missed_periods;
  mc.cro_retry_steps = s.cro_retry_steps;
  return mc;
}


int run_master(const MasterOptions& o) {
  install_stop_handlers();
  const hil::BenchSettings s = load_settings(o.common);
  if (o.dto_timeout < 0) throw InputError("", 0, "--dto-timeout", "must be > 0 [s]");
  const hil::BenchLayout L = hil::BenchLayout::from_dbc(s.dbc_file);
  hil::MasterConfig mc = master_config(s, o.reference, o.dto_timeout);
  const std::size_t control_steps = steps_for(o.duration, s.step_s, "--duration");
  const std::size_t steps = control_steps + static_cast<std::size_t>(std::ceil(mc.dto_timeout_s / s.step_s)) + 2;
  mc.log_capacity = steps;
  hil::MasterNode master(L, mc);
  rt::PeriodicLoop loop(loop_config(o.common, s.step_s, steps));
  const auto warnings = loop.apply_realtime_settings();
  for (const auto& w : warnings) fmt::print(stderr, "lash hil master: warning: {}\n", w);
  auto bus = open_node_bus(s.bus, L, true);
  const auto N = static_cast<std::int64_t>(control_steps);
  can::ControllerBus ctl(*bus, controller_config(loop.config().period_ns));
  const rt::RunResult r = loop.run_with_io(
      [&]() noexcept { ctl.pull(); },
      [&](std::size_t, std::int64_t t_ns) noexcept {
        const bool ok = master.step(ctl, static_cast<double>(t_ns) * 1e-9);
        return ok && master.control_steps() < N;
      },
      [&]() noexcept { ctl.flush(); }, g_stop);
  const double epoch = realtime_now_s() - static_cast<double>(rt::monotonic_ns() - loop.start_ns()) * 1e-9;

  // Logs.
  const auto log = master.log();
  const auto rec = loop.records();
  std::vector<double> c_step, c_t, c_state, c_m, c_r, c_y, c_sc, c_fresh, c_drop, c_i, c_int, c_cc, c_tet, c_io, c_lat;
  for (std::size_t i = 0; i < log.size() && i < rec.size(); ++i) {
    const auto& l = log[i];
    c_step.push_back(l.step);
    c_t.push_back(static_cast<double>(rec[i].release_ns) * 1e-9);
    c_state.push_back(static_cast<double>(l.state));
    c_m.push_back(static_cast<double>(l.control_step));
    c_r.push_back(l.reference_kPa);
    c_y.push_back(l.measured_kPa);
    c_sc.push_back(l.sensor_counter);
    c_fresh.push_back(l.sensor_fresh ? 1 : 0);
    c_drop.push_back(l.dropped);
    c_i.push_back(l.current_mA);
    c_int.push_back(l.integrator_mA);
    c_cc.push_back(l.command_sent ? l.command_counter : -1.0);
    c_tet.push_back(static_cast<double>(rec[i].tet_ns) * 1e-3);
    c_io.push_back(static_cast<double>(rec[i].io_ns) * 1e-3);
    c_lat.push_back(static_cast<double>(rec[i].wake_latency_ns) * 1e-3);
  }
  write_columns_csv(o.log,
                    {"step", "t_s", "state", "control_step", "reference_kPa", "measured_kPa", "sensor_counter",
                     "sensor_fresh", "dropped", "current_mA", "integrator_mA", "command_counter", "tet_us", "io_us",
                     "wake_latency_us"},
                    {&c_step, &c_t, &c_state, &c_m, &c_r, &c_y, &c_sc, &c_fresh, &c_drop, &c_i, &c_int, &c_cc, &c_tet,
                     &c_io, &c_lat});
  if (!o.bus_log.empty()) {
    std::vector<can::LogEntry> entries;
    entries.reserve(master.bus_log().size());
    for (const auto& f : master.bus_log()) {
      can::LogEntry e;
      e.frame = f.frame;
      e.frame.timestamp_s = epoch + f.frame.timestamp_s;
      e.interface = "hil0";
      entries.push_back(e);
    }
    can::write_log(o.bus_log, entries);
  }
  const std::string events_path =
      o.events.empty() ? (std::filesystem::path(o.log).replace_extension("").string() + ".events.csv") : o.events;
  write_events(events_path, master.events());

  json j = loop_json(loop, r, warnings);
  const auto& sn = master.sensors();
  const auto bs = bus->stats();
  j["frames"] = frames_json(sn);
  j["frames"].update({{"sent", master.frames_sent()}, {"ignored", master.ignored_frames()},
                      {"send_failures", master.send_failures()}, {"bus_filtered", bs.filtered},
                      {"bus_dropped", bs.dropped}, {"bus_log_dropped", master.bus_log_dropped()}});
  j["can_controller"] = controller_json(ctl);
  j["state"] = to_string(master.state());
  j["control_steps"] = master.control_steps();
  j["handshake_s"] = master.handshake_s();
  j["events"] = events_json(master.events());
  j["reference"] = o.reference;
  if (!o.stats.empty()) write_json(o.stats, j);

  for (const auto& e : master.events())
    fmt::print(stderr, "lash hil master: t = {:.3f} s (step {}): {}\n", e.t_s, e.step, to_string(e.kind));
  if (master.state() == hil::MasterState::failed) {
    fmt::print(stderr,
               "lash hil master: error: no positive DTO reply to CCP CONNECT (CRO id 0x{:X}) within {} s on {} — "
               "is a slave running on this bus?\n",
               L.cro_id, format_double(mc.dto_timeout_s), bus->address());
    return kExitFailed;
  }
  const auto tet = loop.tet_us();
  fmt::print(stderr,
             "lash hil master: {} steps ({}), handshake {:.4f} s, TET mean {:.2f} us max {:.2f} us, overruns {}, "
             "sensor frames received {} late {} lost {}\n",
             r.steps, rt::to_string(r.reason), master.handshake_s(), tet.mean, tet.max, r.overruns, sn.received,
             sn.late, sn.lost);
  return kExitOk;
}

// ----------------------------------------------------------------------------- latency

struct LatencyOptions {
  CommonOptions common;
  double duration = 10.0;
  bool json_out = false;
};

/// The periodic loop alone, no bus and no task (like cyclictest): what this machine's scheduler
/// gives a node with the same real-time options, before any emulation runs on it.
int run_latency(const LatencyOptions& o) {
  install_stop_handlers();
  const hil::BenchSettings s = load_settings(o.common);
  const std::size_t steps = steps_for(o.duration, s.step_s, "--duration");
  rt::PeriodicLoop loop(loop_config(o.common, s.step_s, steps));
  const auto warnings = loop.apply_realtime_settings();
  for (const auto& w : warnings) fmt::print(stderr, "lash hil latency: warning: {}\n", w);
  const rt::RunResult r = loop.run([](std::size_t, std::int64_t) noexcept { return true; }, g_stop);
  const json j = loop_json(loop, r, warnings);
  if (o.json_out) {
    fmt::print("{}\n", j.dump(2));
  } else {
    const auto w = loop.wake_latency_us();
    fmt::print("lash hil latency: {} steps of {} ms ({}): wake-up latency [us] mean {:.2f} min {:.2f} p99 {:.2f} "
               "max {:.2f} std {:.2f}; overruns {}\n",
               r.steps, format_double(s.step_s * 1e3), rt::to_string(r.reason), w.mean, w.min, w.p99, w.max, w.std,
               r.overruns);
    for (const auto& e : loop.overruns())
      fmt::print("  overrun at step {} (t = {:.3f} s): {:.1f} us late\n", e.step, static_cast<double>(e.t_ns) * 1e-9,
                 static_cast<double>(e.late_ns) * 1e-3);
  }
  return kExitOk;
}

// ----------------------------------------------------------------------------- simulate

struct SimulateOptions {
  std::string config;
  double step_ms = 0.0;
  double duration = 5.0;
  std::string reference = "step:from=500,to=1500,time=1";
  std::int64_t seed = -1;
  std::string out = "hil_sim.csv";
};

int run_simulate(const SimulateOptions& o) {
  CommonOptions co;
  co.config = o.config;
  co.step_ms = o.step_ms;
  hil::BenchSettings s = load_settings(co);
  if (o.seed >= 0) s.plant.seed = static_cast<std::uint64_t>(o.seed);
  const hil::BenchLayout L = hil::BenchLayout::from_dbc(s.dbc_file);
  hil::SlaveConfig sc;
  sc.plant = s.plant;
  sc.dto_reply = hil::load_dto_reply(s.dto_log, L);
  const hil::MasterConfig mc = master_config(s, o.reference, 0.0);
  const std::size_t N = steps_for(o.duration, s.step_s, "--duration");
  const hil::SimulationResult sim = hil::simulate_bench(L, mc, sc, N);
  std::vector<double> c_m, c_t, c_r, c_y, c_i, c_p;
  for (std::size_t m = 0; m < N; ++m) {
    const auto& ml = sim.master[m + 1];
    c_m.push_back(static_cast<double>(ml.control_step));
    c_t.push_back(static_cast<double>(m) * s.step_s);
    c_r.push_back(ml.reference_kPa);
    c_y.push_back(ml.measured_kPa);
    c_i.push_back(ml.current_mA);
    c_p.push_back(sim.slave[m].pressure_kPa);
  }
  write_columns_csv(o.out, {"control_step", "t_s", "reference_kPa", "measured_kPa", "current_mA", "pressure_kPa"},
                    {&c_m, &c_t, &c_r, &c_y, &c_i, &c_p});
  fmt::print(stderr, "lash hil simulate: {} steps at {} ms -> {}\n", N, format_double(s.step_s * 1e3), o.out);
  if (auto w = hil::find_step(c_r, s.step_s)) {
    std::vector<double> t(c_t.begin() + static_cast<std::ptrdiff_t>(w->begin), c_t.begin() + static_cast<std::ptrdiff_t>(w->end));
    std::vector<double> p(c_p.begin() + static_cast<std::ptrdiff_t>(w->begin), c_p.begin() + static_cast<std::ptrdiff_t>(w->end));
    const StepMetrics sm = step_metrics(t, p, w->t_step_s, w->y0, w->y1);
    fmt::print("step {} -> {} kPa at t = {} s: 90% rise {:.4f} s, 10% settling {:.4f} s, overshoot {:.1f} %\n",
               format_double(w->y0), format_double(w->y1), format_double(w->t_step_s), sm.rise_s, sm.settling_s,
               sm.overshoot_pct);
  }
  return kExitOk;
}

// ----------------------------------------------------------------------------- run

struct RunOptions {
  CommonOptions common;
  double duration = 5.0;
  std::string reference = "step:from=500,to=1500,time=1";
  std::string out_dir = "hil-out";
  bool json_out = false;
  bool no_isolate = false;
  std::int64_t seed = -1;
  int slave_cpu = -1;  // -1 = as --cpu
};

struct Child {
  pid_t pid = -1;
  int stdout_fd = -1;
};

Child spawn(const std::vector<std::string>& args, bool pipe_stdout) {
  int fds[2] = {-1, -1};
  if (pipe_stdout && pipe(fds) != 0) throw SystemError("pipe failed");
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw SystemError("fork failed");
  if (pid == 0) {
    if (pipe_stdout) {
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      close(fds[1]);
    }
    execv("/proc/self/exe", argv.data());
    _exit(127);
  }
  Child c;
  c.pid = pid;
  if (pipe_stdout) {
    close(fds[1]);
    c.stdout_fd = fds[0];
  }
  return c;
}

bool wait_ready(int fd, double timeout_s) {
  std::string got;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  char buf[256];
  while (std::chrono::steady_clock::now() < end) {
    fd_set set;
    FD_ZERO(&set);
    FD_SET(fd, &set);
    timeval tv{0, 100000};
    if (select(fd + 1, &set, nullptr, nullptr, &tv) > 0) {
      const ssize_t n = read(fd, buf, sizeof buf);
      if (n <= 0) return false;
      got.append(buf, static_cast<std::size_t>(n));
      if (got.find("ready") != std::string::npos) return true;
    }
  }
  return false;
}

int wait_child(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

json read_json(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw SystemError("cannot read " + path);
  return json::parse(f);
}

std::vector<std::string> common_args(const CommonOptions& c, const std::string& config, const std::string& bus,
                                     double step_ms) {
  std::vector<std::string> a{"--config", config, "--bus", bus, "--step-ms", format_double(step_ms)};
  if (c.fifo > 0) a.insert(a.end(), {"--fifo", std::to_string(c.fifo)});
  if (c.cpu >= 0) a.insert(a.end(), {"--cpu", std::to_string(c.cpu)});
  if (c.spin_us > 0) a.insert(a.end(), {"--spin-us", format_double(c.spin_us)});
  if (c.lock_memory) a.push_back("--lock-memory");
  a.insert(a.end(), {"--overrun-policy", c.overrun_policy, "--max-overruns", std::to_string(c.max_overruns)});
  return a;
}

int run_run(const RunOptions& o) {
  hil::BenchSettings s = load_settings(o.common);
  if (o.seed >= 0) s.plant.seed = static_cast<std::uint64_t>(o.seed);
  const hil::BenchLayout L = hil::BenchLayout::from_dbc(s.dbc_file);
  const hil::MasterConfig mc = master_config(s, o.reference, 0.0);  // validates the reference early
  (void)steps_for(o.duration, s.step_s, "--duration");
  std::filesystem::create_directories(o.out_dir);
  const std::string config =
      o.common.config.empty() ? hil::default_settings_path(source_dir()).string() : o.common.config;

  std::string isolation = "host network (--no-isolate)";
  if (!o.no_isolate) {
    const hil::NetnsResult ns = hil::enter_private_netns();
    if (!ns.ok)
      throw InputError("", 0, "--no-isolate",
                       "cannot create a private network namespace (" + ns.error +
                           "); run as root or with user namespaces enabled, or pass --no-isolate to use the host "
                           "network");
    isolation = "private network namespace (" + ns.how + ")";
  }
  const std::string dir = o.out_dir;
  std::vector<std::string> slave_args{"lash", "hil", "slave"};
  CommonOptions slave_common = o.common;
  if (o.slave_cpu >= 0) slave_common.cpu = o.slave_cpu;
  for (auto& a : common_args(slave_common, config, s.bus, s.step_s * 1e3)) slave_args.push_back(a);
  slave_args.insert(slave_args.end(), {"--duration", format_double(o.duration + s.dto_timeout_s + 5.0), "--log",
                                       dir + "/slave.csv", "--stats", dir + "/slave.json", "--seed",
                                       std::to_string(s.plant.seed)});
  Child slave = spawn(slave_args, true);
  if (!wait_ready(slave.stdout_fd, 10.0)) {
    kill(slave.pid, SIGTERM);
    wait_child(slave.pid);
    throw RunError("the slave did not start (no 'ready' line within 10 s)");
  }
  std::vector<std::string> master_args{"lash", "hil", "master"};
  for (auto& a : common_args(o.common, config, s.bus, s.step_s * 1e3)) master_args.push_back(a);
  master_args.insert(master_args.end(),
                     {"--duration", format_double(o.duration), "--reference", o.reference, "--log", dir + "/master.csv",
                      "--bus-log", dir + "/master_bus.log", "--events", dir + "/master.events.csv", "--stats",
                      dir + "/master.json"});
  Child master = spawn(master_args, false);
  const int master_rc = wait_child(master.pid);
  kill(slave.pid, SIGTERM);
  const int slave_rc = wait_child(slave.pid);
  close(slave.stdout_fd);
  if (master_rc != 0) {
    fmt::print(stderr, "lash hil run: the master exited with status {} (slave: {})\n", master_rc, slave_rc);
    return kExitFailed;
  }
  if (slave_rc != 0) {
    fmt::print(stderr, "lash hil run: the slave exited with status {}\n", slave_rc);
    return kExitFailed;
  }

  // Collect.
  const json mj = read_json(dir + "/master.json");
  const json sj = read_json(dir + "/slave.json");
  const CsvTable mt = read_csv(dir + "/master.csv");
  const CsvTable st = read_csv(dir + "/slave.csv");
  std::vector<std::int64_t> m_of;
  for (double v : mt["control_step"]) m_of.push_back(static_cast<std::int64_t>(v));
  const std::int64_t M = mj.at("control_steps").get<std::int64_t>();

  // The same step functions, simulated.
  hil::SlaveConfig sc;
  sc.plant = s.plant;
  sc.dto_reply = hil::load_dto_reply(s.dto_log, L);
  const hil::SimulationResult sim = hil::simulate_bench(L, mc, sc, static_cast<std::size_t>(std::max<std::int64_t>(M, 1)));
  const hil::SimulationDiff diff = hil::compare_with_simulation(m_of, mt["measured_kPa"], mt["current_mA"], sim.master);

  // Step response on the emulated plant pressure (slave step s = control step m).
  std::vector<double> ref, t_m;
  for (std::size_t i = 0; i < m_of.size(); ++i)
    if (m_of[i] >= 0) {
      ref.push_back(mt["reference_kPa"][i]);
      t_m.push_back(static_cast<double>(m_of[i]) * s.step_s);
    }
  json step_json = json::object();
  const auto& p_slave = st["pressure_kPa"];
  const auto& y_slave = st["measured_kPa"];
  std::optional<StepMetrics> sm, sm_meas;
  std::optional<hil::StepWindow> win = hil::find_step(ref, s.step_s);
  if (win && win->end <= p_slave.size()) {
    const auto b = static_cast<std::ptrdiff_t>(win->begin), e = static_cast<std::ptrdiff_t>(win->end);
    std::vector<double> t(t_m.begin() + b, t_m.begin() + e);
    sm = step_metrics(t, std::vector<double>(p_slave.begin() + b, p_slave.begin() + e), win->t_step_s, win->y0, win->y1);
    sm_meas = step_metrics(t, std::vector<double>(y_slave.begin() + b, y_slave.begin() + e), win->t_step_s, win->y0,
                           win->y1);
    step_json = {{"t_step_s", win->t_step_s}, {"from_kPa", win->y0}, {"to_kPa", win->y1},
                 {"rise_s", sm->rise_s},      {"settling_s", sm->settling_s}, {"overshoot_pct", sm->overshoot_pct},
                 {"signal", "plant pressure (noise-free, slave log)"},
                 {"measured", {{"rise_s", sm_meas->rise_s}, {"settling_s", sm_meas->settling_s},
                               {"overshoot_pct", sm_meas->overshoot_pct}}}};
  }

  json out;
  out["duration_s"] = o.duration;
  out["step_ms"] = s.step_s * 1e3;
  out["reference"] = o.reference;
  out["isolation"] = isolation;
  out["bus"] = s.bus;
  auto node = [](const json& j) {
    return json{{"tet_us", j.at("tet_us")},       {"io_us", j.at("io_us")},
                {"cycle_us", j.at("cycle_us")},   {"wake_latency_us", j.at("wake_latency_us")},
                {"overruns", j.at("overruns")},   {"steps", j.at("steps")},
                {"frames", j.at("frames")},       {"warnings", j.at("warnings")}};
  };
  out["master"] = node(mj);
  out["master"]["handshake_s"] = mj.at("handshake_s");
  out["master"]["events"] = mj.at("events");
  out["master"]["control_steps"] = M;
  out["slave"] = node(sj);
  out["slave"]["events"] = sj.at("events");
  out["slave"]["state"] = sj.at("state");
  out["master"]["state"] = mj.at("state");
  const auto& mf = mj.at("frames");
  const auto& sf = sj.at("frames");
  out["frames"] = {{"sent", mf.at("sent").get<std::uint64_t>() + sf.at("sent").get<std::uint64_t>()},
                   {"received", mf.at("received").get<std::uint64_t>() + sf.at("received").get<std::uint64_t>()},
                   {"late", mf.at("late").get<std::uint64_t>() + sf.at("late").get<std::uint64_t>()},
                   {"lost", mf.at("lost").get<std::uint64_t>() + sf.at("lost").get<std::uint64_t>()}};
  out["step_response"] = step_json;
  out["max_abs_diff_vs_simulation_kPa"] = diff.max_abs_diff_kPa;
  out["max_abs_diff_vs_simulation_mA"] = diff.max_abs_diff_mA;
  out["compared_steps"] = diff.compared;
  if (diff.first_diff_step) out["first_diff_control_step"] = *diff.first_diff_step;
  // Steps that consumed another frame than the one meant for them (master step m ← slave step m,
  // slave step s ← master step s − 1): late frames, lost frames or a node running late.
  std::set<std::int64_t> off;
  for (std::size_t i = 0; i < m_of.size(); ++i)
    if (m_of[i] >= 0 && (mt["sensor_fresh"][i] == 0 || static_cast<std::int64_t>(mt["sensor_counter"][i]) != m_of[i]))
      off.insert(m_of[i]);
  for (std::size_t i = 0; i < st.rows(); ++i) {
    const auto sstep = static_cast<std::int64_t>(st["step"][i]);
    if (sstep > 0 && sstep < M && (st["command_fresh"][i] == 0 || static_cast<std::int64_t>(st["command_counter"][i]) != sstep - 1))
      off.insert(sstep);
  }
  out["off_schedule_steps"] = off.size();
  out["out_dir"] = dir;
  write_json(dir + "/report.json", out);

  if (o.json_out) {
    fmt::print("{}\n", out.dump(2));
  } else {
    auto line = [](const char* who, const json& j) {
      const auto& t = j.at("tet_us");
      const auto& io = j.at("io_us");
      const auto& c = j.at("cycle_us");
      const auto& w = j.at("wake_latency_us");
      fmt::print("{:<7} TET [us] mean {:7.3f} min {:7.3f} max {:8.3f} std {:7.3f} p99 {:8.3f} | CAN I/O [us] mean {:7.2f} "
                 "p99 {:8.2f} | cycle [us] mean {:7.2f} max {:8.2f}\n",
                 who, t.at("mean").get<double>(), t.at("min").get<double>(), t.at("max").get<double>(),
                 t.at("std").get<double>(), t.at("p99").get<double>(), io.at("mean").get<double>(),
                 io.at("p99").get<double>(), c.at("mean").get<double>(), c.at("max").get<double>());
      fmt::print("{:<7} wake-up latency [us] mean {:7.2f} p99 {:8.2f} max {:8.2f} | overruns {}\n", "",
                 w.at("mean").get<double>(), w.at("p99").get<double>(), w.at("max").get<double>(),
                 j.at("overruns").get<std::uint64_t>());
    };
    fmt::print("lash hil run: {} s at {} ms, reference {}, bus {} in a {}\n", format_double(o.duration),
               format_double(s.step_s * 1e3), o.reference, s.bus, isolation);
    fmt::print("CCP handshake {:.4f} s; {} control steps\n", mj.at("handshake_s").get<double>(), M);
    line("master", mj);
    line("slave", sj);
    fmt::print("frames: sent {} received {} late {} lost {}\n", out["frames"]["sent"].get<std::uint64_t>(),
               out["frames"]["received"].get<std::uint64_t>(), out["frames"]["late"].get<std::uint64_t>(),
               out["frames"]["lost"].get<std::uint64_t>());
    if (sm)
      fmt::print("step {} -> {} kPa at {} s: 90% rise {:.4f} s, 10% settling {:.4f} s, overshoot {:.1f} % "
                 "(plant pressure; measured: {:.4f} s, {:.4f} s, {:.1f} %)\n",
                 format_double(win->y0), format_double(win->y1), format_double(win->t_step_s), sm->rise_s,
                 sm->settling_s, sm->overshoot_pct, sm_meas->rise_s, sm_meas->settling_s, sm_meas->overshoot_pct);
    else
      fmt::print("step response: no reference step held >= 0.5 s in this run\n");
    fmt::print("max |emulation - simulation|: {} kPa, {} mA over {} steps ({} steps used an off-schedule frame)\n",
               format_double(diff.max_abs_diff_kPa), format_double(diff.max_abs_diff_mA), diff.compared, off.size());
    fmt::print("logs in {}/ (master.csv, master.events.csv, master_bus.log, slave.csv, slave.events.csv, *.json, "
               "report.json)\n",
               dir);
  }
  return kExitOk;
}

}  // namespace

Command add_hil(CLI::App& app) {
  auto* hil = app.add_subcommand("hil", "Real-time HIL emulation of the hydraulic bench over CAN (SPEC B)");
  hil->require_subcommand(1);

  auto so = std::make_shared<SlaveOptions>();
  auto* slave = hil->add_subcommand("slave", "Slave ECU + pilot-valve plant emulator");
  add_common(slave, so->common);
  slave->add_option("--duration", so->duration, "Longest run [s] (log buffer size); stops earlier on SIGINT/SIGTERM");
  slave->add_option("--log", so->log, "Per-step CSV log");
  slave->add_option("--stats", so->stats, "Statistics JSON");
  slave->add_option("--seed", so->seed, "Noise seed (default from the settings)");
  slave->add_option("--connect-timeout", so->connect_timeout, "Give up without a CCP CONNECT after this long [s] (0 = wait)");

  auto mo = std::make_shared<MasterOptions>();
  auto* master = hil->add_subcommand("master", "Master ECU: CCP connect, then PID + deadzone inverse + saturation");
  add_common(master, mo->common);
  master->add_option("--duration", mo->duration, "Control time [s] after the CCP handshake");
  master->add_option("--reference", mo->reference,
                     "KIND:key=value,... ; step:from=,to=,time= | square|sine|triangle:amplitude=,offset=,"
                     "frequency= [rad/s] or frequency_hz= | random:variance=,tau=,offset= | constant:amplitude=");
  master->add_option("--log", mo->log, "Per-step CSV log");
  master->add_option("--bus-log", mo->bus_log, "candump -L log of the frames the master sent and received");
  master->add_option("--events", mo->events, "Events CSV (default: <log>.events.csv)");
  master->add_option("--stats", mo->stats, "Statistics JSON");
  master->add_option("--dto-timeout", mo->dto_timeout, "Give up without a DTO reply after this long [s]");

  auto lo = std::make_shared<LatencyOptions>();
  auto* lat = hil->add_subcommand("latency", "The periodic loop alone (no bus, no task): wake-up latency and overruns");
  add_common(lat, lo->common);
  lat->add_option("--duration", lo->duration, "Measurement time [s]");
  lat->add_flag("--json", lo->json_out, "Print the statistics as one JSON object");

  auto ro = std::make_shared<RunOptions>();
  auto* run = hil->add_subcommand("run", "Slave and master as two processes on a private UDP bus; report");
  add_common(run, ro->common);
  run->add_option("--duration", ro->duration, "Control time [s]");
  run->add_option("--reference", ro->reference, "Reference (see `lash hil master --help`)");
  run->add_option("--out-dir", ro->out_dir, "Where the logs go");
  run->add_option("--seed", ro->seed, "Noise seed of the plant");
  run->add_flag("--json", ro->json_out, "Print the report as one JSON object");
  run->add_flag("--no-isolate", ro->no_isolate, "Use the host's network instead of a private namespace");
  run->add_option("--slave-cpu", ro->slave_cpu, "Pin the slave to this CPU (default: as --cpu, which pins the master)");

  auto sio = std::make_shared<SimulateOptions>();
  auto* sim = hil->add_subcommand("simulate", "Closed-loop simulation through the nodes' step functions");
  sim->add_option("--config", sio->config, "Node settings (TOML)");
  sim->add_option("--step-ms", sio->step_ms, "Fixed step [ms]");
  sim->add_option("--duration", sio->duration, "Control time [s]");
  sim->add_option("--reference", sio->reference, "Reference (see `lash hil master --help`)");
  sim->add_option("--seed", sio->seed, "Noise seed of the plant");
  sim->add_option("-o,--output", sio->out, "Output CSV");

  return {hil, [=] {
            if (slave->parsed()) return run_slave(*so);
            if (master->parsed()) return run_master(*mo);
            if (run->parsed()) return run_run(*ro);
            if (lat->parsed()) return run_latency(*lo);
            return run_simulate(*sio);
          }};
}

}  // namespace lash::cli
