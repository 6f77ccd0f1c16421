#include "lash/hil/node_run.hpp"

#include <signal.h>
#include <time.h>
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
    throw option_error("--step-ms", "must be in " + format_double(kMinStepMs) + ".." + format_double(kMaxStepMs) +
                                        " [ms], got " + format_double(step_ms));
  if (fifo < 0 || fifo > 99) throw option_error("--fifo", "must be 1..99 (0 = default scheduler), got " + std::to_string(fifo));
  if (cpu < -1) throw option_error("--cpu", "must be a CPU number >= 0 (-1 = no pinning)");
  if (!(spin_us >= 0) || !std::isfinite(spin_us)) throw option_error("--spin-us", "must be >= 0 [us]");
  if (spin_us * 1e-6 >= step_s) throw option_error("--spin-us", "must be shorter than the step");
  if (max_overruns == 0) throw option_error("--max-overruns", "must be >= 1");
}

rt::OverrunPolicy parse_overrun_policy(const std::string& text) {
  if (text == "tolerate") return rt::OverrunPolicy::tolerate;
  if (text == "stop") return rt::OverrunPolicy::stop;
  throw option_error("--overrun-policy", "expected tolerate or stop, got '" + text + "'");
}

std::size_t steps_for(double duration_s, double step_s, const std::string& option) {
  if (!(duration_s > 0) || !std::isfinite(duration_s)) throw option_error(option, "must be > 0 [s]");
  const double n = std::round(duration_s / step_s);
  if (n > static_cast<double>(kMaxSteps))
    throw option_error(option, "too long: " + format_double(n) + " steps of " + format_double(step_s * 1e3) +
                                   " ms; at most " + std::to_string(kMaxSteps) + " steps (the logs are preallocated)");
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
  const std::size_t steps = steps_for(o.duration_s, s.step_s, "--duration");
  if (!(o.connect_timeout_s >= 0) || !std::isfinite(o.connect_timeout_s))
    throw option_error("--connect-timeout", "must be >= 0 [s] (0 = wait until stopped)");
  SlaveNode slave(L, slave_config(s, L, steps));
  const rt::LoopConfig lc = make_loop_config(o.loop, steps);
  rt::PeriodicLoop loop(lc);
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
  if (out.stats.connected) {
    const std::int64_t t_connect = rt::monotonic_ns();
    // The slave's grid sits half a period after the master's (see nodes.hpp). The loop and its
    // buffers exist already, so the first step is not delayed by allocation or page faults.
    loop.set_start_ns(t_connect + lc.period_ns / 2);
    const rt::DmaLatencyHold dma(o.loop.hold_dma_latency);
    out.stats.dma_latency_held = dma.held();
    out.stats.epoch_s = realtime_now_s() - static_cast<double>(rt::monotonic_ns() - (t_connect + lc.period_ns / 2)) * 1e-9;
    out.stats.result = loop.run_with_io(
        [&]() noexcept { ctl.pull(); },
        [&](std::size_t, std::int64_t t_ns) noexcept {
          slave.step(ctl, static_cast<double>(t_ns) * 1e-9);
          return true;
        },
        [&]() noexcept { ctl.flush(); }, stop);
  }
  take_loop(loop, out.loop);
  out.log.assign(slave.log().begin(), slave.log().end());
  out.events.assign(slave.events().begin(), slave.events().end());
  out.stats.state = slave.state();
  out.stats.frames = frame_stats(slave.commands(), slave.frames_sent(), slave.ignored_frames(), slave.send_failures(),
                                 bus->stats());
  out.stats.controller = ctl.controller_stats();
  out.stats.dto_replies = slave.dto_replies();
  return out;
}

MasterRun run_master_node(const BenchSettings& s, const MasterRunOptions& o, const std::atomic<bool>& stop) {
  if (!(o.dto_timeout_s >= 0) || !std::isfinite(o.dto_timeout_s))
    throw option_error("--dto-timeout", "must be > 0 [s]");
  const BenchLayout L = BenchLayout::from_dbc(s.dbc_file);
  MasterConfig mc = master_config(s, o.reference, o.dto_timeout_s);
  const std::size_t control_steps = steps_for(o.duration_s, s.step_s, "--duration");
  const auto wait_steps = ceil_to<std::size_t>(mc.dto_timeout_s / s.step_s);
  if (!wait_steps || *wait_steps > kMaxSteps)
    throw option_error("--dto-timeout", "too long: " + format_double(mc.dto_timeout_s) + " s; at most " + std::to_string(kMaxSteps) +
                                            " steps of " + format_double(s.step_s * 1e3) + " ms");
  const std::size_t steps = control_steps + *wait_steps + 2;
  mc.log_capacity = steps;
  MasterNode master(L, mc);
  rt::PeriodicLoop loop(make_loop_config(o.loop, steps));
  // The XCP slave: its own thread and socket; the step meets it through two lock-free queues.
  // Started before the loop's real-time settings, so that it keeps the default scheduler and
  // every CPU (a thread inherits SCHED_FIFO and the affinity of the thread that creates it).
  std::unique_ptr<XcpLink> link;
  std::unique_ptr<XcpServer> xcp;
  if (o.xcp) {
    link = std::make_unique<XcpLink>();
    xcp = std::make_unique<XcpServer>(s.bus, L, *link, initial_calibration(mc));
    master.attach(link.get());
  }
  MasterRun out;
  out.loop.warnings = loop.apply_realtime_settings();
  auto bus = open_node_bus(s.bus, L, true);
  const auto N = static_cast<std::int64_t>(control_steps);
  can::ControllerBus ctl(*bus, node_controller_config(loop.config().period_ns));
  {
    const rt::DmaLatencyHold dma(o.loop.hold_dma_latency);
    out.stats.dma_latency_held = dma.held();
    out.stats.result = loop.run_with_io(
        [&]() noexcept { ctl.pull(); },
        [&](std::size_t k, std::int64_t t_ns) noexcept {
          if (link) {  // console status over XCP: the previous step's TET, this step's wake-up latency
            const auto rec = loop.records();
            master.set_loop_figures(rec.empty() ? 0.0 : static_cast<double>(rec.back().tet_ns) * 1e-3,
                                    static_cast<double>(t_ns - static_cast<std::int64_t>(k) * loop.config().period_ns) * 1e-3,
                                    static_cast<double>(loop.overruns().size()));
          }
          const bool ok = master.step(ctl, static_cast<double>(t_ns) * 1e-9);
          return ok && master.control_steps() < N;
        },
        [&]() noexcept { ctl.flush(); }, stop);
  }
  out.stats.epoch_s = realtime_now_s() - static_cast<double>(rt::monotonic_ns() - loop.start_ns()) * 1e-9;
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
  out.calibration.assign(master.calibration_events().begin(), master.calibration_events().end());
  take_loop(loop, out.loop);
  out.log.assign(master.log().begin(), master.log().end());
  out.events.assign(master.events().begin(), master.events().end());
  out.bus_log.assign(master.bus_log().begin(), master.bus_log().end());
  out.stats.frames = frame_stats(master.sensors(), master.frames_sent(), master.ignored_frames(),
                                 master.send_failures(), bus->stats());
  out.stats.frames.bus_log_dropped = master.bus_log_dropped();
  out.stats.controller = ctl.controller_stats();
  out.stats.state = master.state();
  out.stats.control_steps = master.control_steps();
  out.stats.handshake_s = master.handshake_s();
  out.stats.compensation = master.compensation();
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

// ----------------------------------------------------------------------------- files

namespace {
void write_columns(const std::filesystem::path& path, const std::vector<std::string>& names,
                   const std::vector<std::vector<double>>& cols) {
  AtomicFile f(path);
  std::string line;
  for (std::size_t i = 0; i < names.size(); ++i) line += (i ? "," : "") + names[i];
  line += '\n';
  f.stream() << line;
  const std::size_t n = cols.empty() ? 0 : cols[0].size();
  for (std::size_t k = 0; k < n; ++k) {
    line.clear();
    for (std::size_t c = 0; c < cols.size(); ++c) {
      if (c) line += ',';
      append_double(line, cols[c][k]);
    }
    line += '\n';
    f.stream() << line;
  }
  f.commit();
}

double us(std::int64_t ns) { return static_cast<double>(ns) * 1e-3; }
}  // namespace

void write_slave_csv(const std::filesystem::path& path, const SlaveRun& r) {
  std::vector<std::vector<double>> c(13);
  const std::size_t n = std::min(r.log.size(), r.loop.records.size());
  for (std::size_t i = 0; i < n; ++i) {
    const auto& l = r.log[i];
    const auto& rec = r.loop.records[i];
    const double row[] = {static_cast<double>(l.step), static_cast<double>(rec.release_ns) * 1e-9,
                          static_cast<double>(l.state), static_cast<double>(l.command_counter),
                          l.command_fresh ? 1.0 : 0.0, static_cast<double>(l.dropped), l.current_mA,
                          l.pressure_kPa, l.measured_kPa, static_cast<double>(l.pilot_raw), us(rec.tet_ns),
                          us(rec.io_ns), us(rec.wake_latency_ns)};
    for (std::size_t j = 0; j < c.size(); ++j) c[j].push_back(row[j]);
  }
  write_columns(path,
                {"step", "t_s", "state", "command_counter", "command_fresh", "dropped", "current_mA", "pressure_kPa",
                 "measured_kPa", "pilot_raw", "tet_us", "io_us", "wake_latency_us"},
                c);
}

void write_master_csv(const std::filesystem::path& path, const MasterRun& r) {
  const auto cal = calibration_fields();
  std::vector<std::vector<double>> c(16 + cal.size());
  const std::size_t n = std::min(r.log.size(), r.loop.records.size());
  for (std::size_t i = 0; i < n; ++i) {
    const auto& l = r.log[i];
    const auto& rec = r.loop.records[i];
    const double row[] = {static_cast<double>(l.step), static_cast<double>(rec.release_ns) * 1e-9,
                          static_cast<double>(l.state), static_cast<double>(l.control_step), l.reference_kPa,
                          l.measured_kPa, static_cast<double>(l.sensor_counter), l.sensor_fresh ? 1.0 : 0.0,
                          static_cast<double>(l.sensor_seq), static_cast<double>(l.dropped), l.current_mA, l.integrator_mA,
                          l.command_sent ? static_cast<double>(l.command_counter) : -1.0,
                          us(rec.tet_ns), us(rec.io_ns), us(rec.wake_latency_ns)};
    for (std::size_t j = 0; j < 16; ++j) c[j].push_back(row[j]);
    for (std::size_t j = 0; j < cal.size(); ++j) c[16 + j].push_back(l.calibration.*cal[j].member);
  }
  std::vector<std::string> names{"step", "t_s", "state", "control_step", "reference_kPa", "measured_kPa", "sensor_counter",
                                 "sensor_fresh", "sensor_seq", "dropped", "current_mA", "integrator_mA", "command_counter",
                                 "tet_us", "io_us", "wake_latency_us"};
  for (const auto& f : cal) names.emplace_back(f.name);  // the calibration page of each step (calibration.hpp)
  write_columns(path, names, c);
}

void write_events(const std::filesystem::path& path, const std::vector<NodeEvent>& events) {
  AtomicFile f(path);
  f.stream() << "step,t_s,event,from,to\n";
  for (const auto& e : events)
    f.stream() << e.step << ',' << format_double(e.t_s) << ',' << to_string(e.kind) << ',' << to_string(e.from) << ','
               << to_string(e.to) << '\n';
  f.commit();
}

void write_events(const std::filesystem::path& path, const std::vector<NodeEvent>& events,
                  const std::vector<CalibrationEvent>& calibration) {
  AtomicFile f(path);
  f.stream() << "step,t_s,event,from,to,name,old,new\n";
  std::size_t j = 0;
  const auto fields = calibration_fields();
  auto cal_row = [&](const CalibrationEvent& c) {
    f.stream() << c.step << ',' << format_double(c.t_s) << ",calibration,,," << fields[c.field].name << ','
               << format_double(c.old_value) << ',' << format_double(c.new_value) << '\n';
  };
  for (const auto& e : events) {
    while (j < calibration.size() && calibration[j].step < e.step) cal_row(calibration[j++]);
    f.stream() << e.step << ',' << format_double(e.t_s) << ',' << to_string(e.kind) << ',' << to_string(e.from) << ','
               << to_string(e.to) << ",,,\n";
  }
  while (j < calibration.size()) cal_row(calibration[j++]);
  f.commit();
}

void write_bus_log(const std::filesystem::path& path, const MasterRun& r) {
  std::vector<can::LogEntry> entries;
  entries.reserve(r.bus_log.size());
  for (const auto& f : r.bus_log) {
    can::LogEntry e;
    e.frame = f.frame;
    // Sent frames carry the loop time of their step; received ones the bus's wall-clock
    // receive time (kernel timestamp), which must not get the epoch a second time.
    if (f.sent) e.frame.timestamp_s = r.stats.epoch_s + f.frame.timestamp_s;
    e.interface = "hil0";
    entries.push_back(e);
  }
  can::write_log(path, entries);
}

namespace {
using nlohmann::json;
using detail::summary_json;

json loop_json(const NodeStats& st, const LoopTrace& t) {
  json j;
  j["steps"] = st.result.steps;
  j["stop_reason"] = rt::to_string(st.result.reason);
  j["tet_us"] = summary_json(rt::tet_us(t.records));
  j["io_us"] = summary_json(rt::io_us(t.records));
  j["cycle_us"] = summary_json(rt::cycle_us(t.records));
  j["wake_latency_us"] = summary_json(rt::wake_latency_us(t.records));
  j["overruns"] = st.result.overruns;
  json ov = json::array();
  for (const auto& e : t.overruns)
    ov.push_back({{"step", e.step}, {"t_s", static_cast<double>(e.t_ns) * 1e-9}, {"late_us", us(e.late_ns)}});
  j["overrun_events"] = ov;
  j["warnings"] = t.warnings;
  j["step_s"] = static_cast<double>(st.period_ns) * 1e-9;
  j["dma_latency_held"] = st.dma_latency_held;
  const auto& cs = st.controller;
  j["can_controller"] = {{"rx_overflows", cs.rx_overflows}, {"tx_overflows", cs.tx_overflows},
                         {"tx_failures", cs.tx_failures},   {"rx_reads", cs.rx_reads},
                         {"pulls_cut", cs.pulls_cut}};
  j["frames"] = detail::frames_json(st.frames);
  return j;
}
}  // namespace

std::string slave_stats_json(const SlaveRun& r) {
  json j = loop_json(r.stats, r.loop);
  j["state"] = to_string(r.stats.state);
  j["events"] = detail::events_json(r.events);
  j["dto_replies"] = r.stats.dto_replies;
  j["seed"] = r.stats.seed;
  j["connected"] = r.stats.connected;
  return j.dump(2) + "\n";
}

std::string master_stats_json(const MasterRun& r, const std::string& reference) {
  json j = loop_json(r.stats, r.loop);
  j["frames"]["bus_log_dropped"] = r.stats.frames.bus_log_dropped;
  j["state"] = to_string(r.stats.state);
  j["control_steps"] = r.stats.control_steps;
  j["handshake_s"] = r.stats.handshake_s;
  j["events"] = detail::events_json(r.events);
  j["reference"] = reference;
  if (r.stats.xcp)
    j["xcp"] = {{"commands", r.stats.xcp_commands}, {"errors", r.stats.xcp_errors}, {"dtos", r.stats.xcp_dtos},
                {"samples_lost", r.stats.xcp_samples_lost}, {"pages", r.stats.xcp_pages},
                {"calibration_events", r.calibration.size()}};
  return j.dump(2) + "\n";
}

// ----------------------------------------------------------------------------- hand-over

namespace {
constexpr std::uint64_t kMagic = 0x6C6173682D72756EULL;  // "lash-run"

void write_all(int fd, const void* p, std::size_t n) {
  const auto* b = static_cast<const char*>(p);
  while (n > 0) {
    const ssize_t w = ::write(fd, b, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) throw SystemError(std::string("cannot hand the run over: ") + std::strerror(errno));
    b += w;
    n -= static_cast<std::size_t>(w);
  }
}

struct Writer {
  int fd;
  template <class T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    write_all(fd, &v, sizeof v);
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(static_cast<std::uint64_t>(v.size()));
    if (!v.empty()) write_all(fd, v.data(), v.size() * sizeof(T));
  }
  void strings(const std::vector<std::string>& v) {
    pod(static_cast<std::uint64_t>(v.size()));
    for (const auto& s : v) {
      pod(static_cast<std::uint64_t>(s.size()));
      write_all(fd, s.data(), s.size());
    }
  }
};

struct Reader {
  explicit Reader(int f) : fd(f) {
    struct stat st {};
    if (::fstat(fd, &st) == 0 && st.st_size >= 0) size = static_cast<std::uint64_t>(st.st_size);
  }
  int fd;
  off_t at = 0;
  bool ok = true;
  std::uint64_t size = 0;  ///< of the hand-over file: no count read from it may ask for more bytes than it holds
  bool fits(std::uint64_t n, std::uint64_t elem) const noexcept {
    const auto left = size - std::min<std::uint64_t>(size, static_cast<std::uint64_t>(at));
    return elem == 0 || n <= left / elem;
  }
  bool raw(void* p, std::size_t n) {
    auto* b = static_cast<char*>(p);
    while (ok && n > 0) {
      const ssize_t r = ::pread(fd, b, n, at);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) ok = false;
      else {
        b += r;
        n -= static_cast<std::size_t>(r);
        at += r;
      }
    }
    return ok;
  }
  template <class T>
  bool pod(T& v) {
    return raw(&v, sizeof v);
  }
  template <class T>
  bool vec(std::vector<T>& v) {
    std::uint64_t n = 0;
    if (!pod(n) || n > (std::uint64_t{1} << 32) || !fits(n, sizeof(T))) return ok = false;
    v.resize(n);
    return n == 0 || raw(v.data(), n * sizeof(T));
  }
  bool strings(std::vector<std::string>& v) {
    std::uint64_t n = 0;
    if (!pod(n) || n > 4096 || !fits(n, sizeof(std::uint64_t))) return ok = false;
    v.resize(n);
    for (auto& s : v) {
      std::uint64_t len = 0;
      if (!pod(len) || len > (1u << 20) || !fits(len, 1)) return ok = false;
      s.resize(len);
      if (len && !raw(s.data(), len)) return false;
    }
    return ok;
  }
};

void write_common(Writer& w, const NodeStats& st, const LoopTrace& t) {
  w.pod(kMagic);
  w.pod(st);
  w.vec(t.records);
  w.vec(t.overruns);
  w.strings(t.warnings);
}
bool read_common(Reader& r, NodeStats& st, LoopTrace& t) {
  std::uint64_t magic = 0;
  return r.pod(magic) && magic == kMagic && r.pod(st) && r.vec(t.records) && r.vec(t.overruns) && r.strings(t.warnings);
}
}  // namespace

void write_run(int fd, const SlaveRun& run) {
  Writer w{fd};
  write_common(w, run.stats, run.loop);
  w.vec(run.log);
  w.vec(run.events);
}

void write_run(int fd, const MasterRun& run) {
  Writer w{fd};
  write_common(w, run.stats, run.loop);
  w.vec(run.log);
  w.vec(run.events);
  w.vec(run.bus_log);
  w.vec(run.calibration);
}

bool read_run(int fd, SlaveRun& run) {
  Reader r(fd);
  return read_common(r, run.stats, run.loop) && r.vec(run.log) && r.vec(run.events);
}

bool read_run(int fd, MasterRun& run) {
  Reader r(fd);
  return read_common(r, run.stats, run.loop) && r.vec(run.log) && r.vec(run.events) && r.vec(run.bus_log) &&
         r.vec(run.calibration);
}

}  // namespace lash::hil
