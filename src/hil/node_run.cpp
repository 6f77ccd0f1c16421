#include "lash/hil/node_run.hpp"

#include <signal.h>
#include <time.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "lash/can/log.hpp"
#include "lash/io/atomic_file.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"
#include "lash/rt/dma_latency.hpp"
#include "lash/hil/xcp_server.hpp"
#include "lash/io/numeric.hpp"
#include "json_parts.hpp"

namespace lash::hil {

namespace {
InputError option_error(const std::string& option, const std::string& message) {
  return InputError("", 0, option, message);
}

/// Peak resident set of this process [kB] (getrusage ru_maxrss).
long peak_rss_kB() {
  rusage u{};
  return getrusage(RUSAGE_SELF, &u) == 0 ? u.ru_maxrss : -1;
}

double realtime_now_s() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}
}  // namespace

// ----------------------------------------------------------------------------- options

void LoopOptions::validate() const {
  const double step_ms = step_s * 1e3;
  if (!std::isfinite(step_ms) || step_ms < kMinStepMs - 1e-12 || step_ms > kMaxStepMs)
    throw option_error("loop.step_s", "must be in " + format_double(kMinStepMs) + ".." + format_double(kMaxStepMs) +
                                          " [ms], got " + format_double(step_ms) + " ms");
  if (fifo < 0 || fifo > 99) throw option_error("loop.fifo", "must be 1..99 (0 = default scheduler), got " + std::to_string(fifo));
  if (cpu < -1) throw option_error("loop.cpu", "must be a CPU number >= 0 (-1 = no pinning)");
  if (!(spin_us >= 0) || !std::isfinite(spin_us)) throw option_error("loop.spin_us", "must be >= 0 [us]");
  if (spin_us * 1e-6 >= step_s) throw option_error("loop.spin_us", "must be shorter than the step");
  if (max_overruns == 0) throw option_error("loop.max_overruns", "must be >= 1");
}

rt::OverrunPolicy parse_overrun_policy(const std::string& text) {
  if (text == "tolerate") return rt::OverrunPolicy::tolerate;
  if (text == "stop") return rt::OverrunPolicy::stop;
  throw option_error("loop.policy", "expected tolerate or stop, got '" + text + "'");
}

std::size_t steps_for(double duration_s, double step_s, const std::string& option) {
  if (!(duration_s > 0) || !std::isfinite(duration_s)) throw option_error(option, "must be > 0 [s]");
  const double n = std::round(duration_s / step_s);
  if (n > static_cast<double>(kMaxSteps))
    throw option_error(option, "too long: " + format_double(n) + " steps of " + format_double(step_s * 1e3) +
                                   " ms; at most " + std::to_string(kMaxSteps) + " steps");
  return static_cast<std::size_t>(std::max(1.0, n));
}

rt::LoopConfig make_loop_config(const LoopOptions& o, std::size_t steps) {
  o.validate();
  rt::LoopConfig c;
  c.period_ns = static_cast<std::int64_t>(std::llround(o.step_s * 1e9));
  c.max_steps = steps;
  c.fifo_priority = o.fifo;
  c.cpu = o.cpu;
  c.spin_ns = static_cast<std::int64_t>(std::llround(o.spin_us * 1e3));
  c.lock_memory = o.lock_memory;
  c.policy = o.policy;
  c.max_consecutive_overruns = o.max_overruns;
  return c;
}

can::ControllerConfig node_controller_config(std::int64_t period_ns) {
  can::ControllerConfig c;
  c.budget_ns = period_ns / 5;
  return c;
}

std::unique_ptr<can::Bus> open_node_bus(const std::string& address, const BenchLayout& L, bool master) {
  auto bus = can::open_bus(address);
  if (master)
    bus->set_filters({{L.sensors_id, 0x7FF, false}, {L.dto_id, 0x7FF, false}});
  else
    bus->set_filters({{L.command_id, 0x7FF, false}, {L.cro_id, 0x7FF, false}});
  return bus;
}

SlaveConfig slave_config(const BenchSettings& s, const BenchLayout& layout, std::size_t log_capacity) {
  SlaveConfig sc;
  sc.plant = s.plant;
  if (s.dto_log.empty()) {  // settings built in code (lash closed-loop --scenario): a positive CONNECT reply
    can::Frame dto;
    dto.id = layout.dto_id;
    dto.len = 8;
    dto.data[0] = can::ccp::kCommandReturn;
    dto.data[1] = can::ccp::kAcknowledge;
    sc.dto_reply = {dto};
  } else {
    sc.dto_reply = load_dto_reply(s.dto_log, layout);
  }
  sc.log_capacity = log_capacity;
  if (s.scenario) sc.rig = s.scenario->plant;
  return sc;
}

MasterConfig master_config(const BenchSettings& s, const std::string& reference, double dto_timeout_s,
                           std::size_t log_capacity) {
  MasterConfig mc;
  mc.controller = s.controller;
  mc.reference = s.scenario ? s.scenario->reference : parse_reference(reference);
  if (s.scenario) mc.law = s.scenario->law;
  mc.dto_timeout_s = dto_timeout_s > 0 ? dto_timeout_s : s.dto_timeout_s;
  mc.fault_missed_periods = s.fault_missed_periods;
  mc.cro_retry_steps = s.cro_retry_steps;
  mc.log_capacity = log_capacity;
  return mc;
}

// ----------------------------------------------------------------------------- runs

namespace {
void take_loop(const rt::PeriodicLoop& loop, LoopTrace& t) {
  t.records.assign(loop.records().begin(), loop.records().end());
  t.overruns.assign(loop.overruns().begin(), loop.overruns().end());
}

// Stops a node's log writer (its last rows reach the disk; a write error becomes a warning) and
// takes its counts and the loop's summaries into the node's statistics.
void finish_writer(NodeLogWriter& writer, NodeStats& stats, LoopTrace& loop) {
  try {
    writer.stop();
  } catch (const std::exception& e) {
    loop.warnings.push_back(e.what());
  }
  stats.logs = writer.stats();
  const LoopSummaries sum = writer.loop();
  stats.tet_us = sum.tet_us;
  stats.io_us = sum.io_us;
  stats.cycle_us = sum.cycle_us;
  stats.wake_latency_us = sum.wake_latency_us;
}

FrameStats frame_stats(const SeqTracker& seq, std::uint64_t sent, std::uint64_t ignored, std::uint64_t send_failures,
                       const can::BusStats& bs) {
  FrameStats f;
  f.sent = sent;
  f.received = seq.received;
  f.accepted = seq.accepted;
  f.late = seq.late;
  f.lost = seq.lost;
  f.duplicates = seq.drops[Drop::repeated];
  f.resyncs = seq.resyncs;
  f.dropped = seq.drops.total();
  f.dropped_by_reason = seq.drops.n;
  f.ignored = ignored;
  f.send_failures = send_failures;
  f.bus_filtered = bs.filtered;
  f.bus_dropped = bs.dropped;
  return f;
}
}  // namespace

SlaveRun run_slave_node(const BenchSettings& s, const SlaveRunOptions& o, const std::atomic<bool>& stop,
                        const std::function<void(const std::string&)>& on_ready) {
  const BenchLayout L = BenchLayout::from_dbc(s.dbc_file);
  const std::size_t steps = steps_for(o.duration_s, s.step_s, "duration_s");
  if (!(o.connect_timeout_s >= 0) || !std::isfinite(o.connect_timeout_s))
    throw option_error("connect_timeout_s", "must be >= 0 [s] (0 = wait until stopped)");
  SlaveNode slave(L, slave_config(s, L, 1));  // one row: handed to the writer after each step
  rt::LoopConfig lc = make_loop_config(o.loop, steps);
  lc.keep_records = false;
  rt::PeriodicLoop loop(lc);
  // The writer thread is started before the real-time settings: it keeps the default
  // scheduler and every CPU (a thread inherits them from the thread that creates it).
  NodeLogWriter writer(NodeLogWriter::Node::slave, o.logs, steps);
  SlaveRun out;
  out.loop.warnings = loop.apply_realtime_settings();
  auto bus = open_node_bus(s.bus, L, false);
  // The task sees an emulated CAN controller; its reception and transmission are the I/O phases.
  can::ControllerBus ctl(*bus, node_controller_config(lc.period_ns));
  if (on_ready) on_ready(bus->address());

  const std::int64_t t_open = rt::monotonic_ns();
  while (!stop.load()) {
    if (slave.wait_connect(*bus, std::chrono::milliseconds(100))) {
      out.stats.connected = true;
      break;
    }
    if (o.connect_timeout_s > 0 && static_cast<double>(rt::monotonic_ns() - t_open) * 1e-9 > o.connect_timeout_s) break;
  }
  out.stats.period_ns = lc.period_ns;
  out.stats.seed = s.plant.seed;
  std::size_t events_seen = 0;
  if (out.stats.connected) {
    const std::int64_t t_connect = rt::monotonic_ns();
    // The slave's grid sits half a period after the master's (see nodes.hpp). The loop and its
    // buffers exist already, so the first step is not delayed by allocation or page faults.
    loop.set_start_ns(t_connect + lc.period_ns / 2);
    const rt::DmaLatencyHold dma(o.loop.hold_dma_latency);
    out.stats.dma_latency_held = dma.held();
    out.stats.epoch_s = realtime_now_s() - static_cast<double>(rt::monotonic_ns() - (t_connect + lc.period_ns / 2)) * 1e-9;
    writer.set_epoch(out.stats.epoch_s);
    out.stats.result = loop.run_with_io(
        [&]() noexcept { ctl.pull(); },
        [&](std::size_t, std::int64_t t_ns) noexcept {
          slave.step(ctl, static_cast<double>(t_ns) * 1e-9);
          return true;
        },
        [&]() noexcept { ctl.flush(); },
        // After the timed cycle: hand the step's events and row to the writer (never waits).
        [&](std::size_t, const rt::StepRecord& rec) noexcept {
          const auto ev = slave.events();
          for (; events_seen < ev.size(); ++events_seen) writer.push(ev[events_seen]);
          if (!slave.log().empty()) writer.push(SlaveRow{slave.log()[0], rec});
          slave.clear_step_log();
        },
        stop);
  }
  for (const auto ev = slave.events(); events_seen < ev.size(); ++events_seen) writer.push(ev[events_seen]);
  finish_writer(writer, out.stats, out.loop);
  take_loop(loop, out.loop);
  out.events.assign(slave.events().begin(), slave.events().end());
  out.stats.state = slave.state();
  out.stats.frames = frame_stats(slave.commands(), slave.frames_sent(), slave.ignored_frames(), slave.send_failures(),
                                 bus->stats());
  out.stats.controller = ctl.controller_stats();
  out.stats.dto_replies = slave.dto_replies();
  out.stats.peak_rss_kB = peak_rss_kB();
  return out;
}

MasterRun run_master_node(const BenchSettings& s, const MasterRunOptions& o, const std::atomic<bool>& stop) {
  if (!(o.dto_timeout_s >= 0) || !std::isfinite(o.dto_timeout_s))
    throw option_error("dto_timeout_s", "must be > 0 [s]");
  const BenchLayout L = BenchLayout::from_dbc(s.dbc_file);
  MasterConfig mc = master_config(s, o.reference, o.dto_timeout_s);
  const std::size_t control_steps = steps_for(o.duration_s, s.step_s, "duration_s");
  const auto wait_steps = ceil_to<std::size_t>(mc.dto_timeout_s / s.step_s);
  if (!wait_steps || *wait_steps > kMaxSteps)
    throw option_error("dto_timeout_s", "too long: " + format_double(mc.dto_timeout_s) + " s; at most " + std::to_string(kMaxSteps) +
                                            " steps of " + format_double(s.step_s * 1e3) + " ms");
  const std::size_t steps = control_steps + *wait_steps + 2;
  mc.log_capacity = 1;                 // one row and one step's frames: handed to the writer after each step
  mc.bus_log_capacity = kStepFrames;
  MasterNode master(L, mc);
  rt::LoopConfig lc = make_loop_config(o.loop, steps);
  lc.keep_records = false;
  rt::PeriodicLoop loop(lc);
  // The XCP slave and the log writer: their own threads; the step meets them through lock-free
  // queues. Started before the loop's real-time settings, so that they keep the default
  // scheduler and every CPU (a thread inherits SCHED_FIFO and the affinity of its creator).
  std::unique_ptr<XcpLink> link;
  std::unique_ptr<XcpServer> xcp;
  if (o.xcp) {
    link = std::make_unique<XcpLink>();
    xcp = std::make_unique<XcpServer>(s.bus, L, *link, initial_calibration(mc));
    master.attach(link.get());
  }
  NodeLogWriter writer(NodeLogWriter::Node::master, o.logs, steps);
  MasterRun out;
  out.loop.warnings = loop.apply_realtime_settings();
  auto bus = open_node_bus(s.bus, L, true);
  const auto N = static_cast<std::int64_t>(control_steps);
  can::ControllerBus ctl(*bus, node_controller_config(loop.config().period_ns));
  std::size_t events_seen = 0, calibration_seen = 0;
  double last_tet_us = 0.0;  // the previous step's TET [µs], for the console's status over XCP
  {
    const rt::DmaLatencyHold dma(o.loop.hold_dma_latency);
    out.stats.dma_latency_held = dma.held();
    // r_0 fixed here, so that the wall-clock epoch of the bus log is known before the first step.
    const std::int64_t start = rt::monotonic_ns() + loop.config().period_ns;
    loop.set_start_ns(start);
    out.stats.epoch_s = realtime_now_s() - static_cast<double>(rt::monotonic_ns() - start) * 1e-9;
    writer.set_epoch(out.stats.epoch_s);
    out.stats.result = loop.run_with_io(
        [&]() noexcept { ctl.pull(); },
        [&](std::size_t k, std::int64_t t_ns) noexcept {
          if (link) {  // console status over XCP: the previous step's TET, this step's wake-up latency
            master.set_loop_figures(last_tet_us,
                                    static_cast<double>(t_ns - static_cast<std::int64_t>(k) * loop.config().period_ns) * 1e-3,
                                    static_cast<double>(loop.overrun_count()));
          }
          const bool ok = master.step(ctl, static_cast<double>(t_ns) * 1e-9);
          return ok && master.control_steps() < N;
        },
        [&]() noexcept { ctl.flush(); },
        // After the timed cycle: hand the step's events, frames and row to the writer (never waits).
        [&](std::size_t, const rt::StepRecord& rec) noexcept {
          last_tet_us = static_cast<double>(rec.tet_ns) * 1e-3;  // the records are streamed, not kept
          const auto ev = master.events();
          for (; events_seen < ev.size(); ++events_seen) writer.push(ev[events_seen]);
          const auto cal = master.calibration_events();
          for (; calibration_seen < cal.size(); ++calibration_seen) writer.push(cal[calibration_seen]);
          for (const auto& f : master.bus_log()) writer.push(f);
          if (!master.log().empty()) writer.push(MasterRow{master.log()[0], rec});
          master.clear_step_logs();
        },
        stop);
  }
  out.stats.period_ns = loop.config().period_ns;
  if (xcp) {
    xcp->stop();
    const XcpServerStats xs = xcp->stats();
    out.stats.xcp = true;
    out.stats.xcp_commands = xs.commands;
    out.stats.xcp_errors = xs.errors;
    out.stats.xcp_dtos = xs.dtos;
    out.stats.xcp_samples_lost = xs.samples_lost;
    out.stats.xcp_pages = xs.pages;
  }
  finish_writer(writer, out.stats, out.loop);
  out.calibration.assign(master.calibration_events().begin(), master.calibration_events().end());
  take_loop(loop, out.loop);
  out.events.assign(master.events().begin(), master.events().end());
  out.stats.frames = frame_stats(master.sensors(), master.frames_sent(), master.ignored_frames(),
                                 master.send_failures(), bus->stats());
  out.stats.frames.bus_log_dropped = master.bus_log_dropped();
  out.stats.controller = ctl.controller_stats();
  out.stats.state = master.state();
  out.stats.control_steps = master.control_steps();
  out.stats.handshake_s = master.handshake_s();
  out.stats.compensation = master.compensation();
  out.stats.peak_rss_kB = peak_rss_kB();
  return out;
}

namespace {
std::atomic<bool> g_node_stop{false};
extern "C" void on_node_signal(int) { g_node_stop.store(true); }
}  // namespace

const std::atomic<bool>& node_stop_flag() noexcept { return g_node_stop; }

void install_node_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_node_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaction(s, &sa, nullptr);
}

}  // namespace lash::hil
