// --console options and the wiring of `lash hil run --console` (docs/console.md).
#include "console_options.hpp"

#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <string_view>
#include <thread>

#include <fmt/core.h>

#include "lash/console/server.hpp"
#include "lash/console/xcp_bridge.hpp"
#include "lash/hil/bench_layout.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/hil/xcp_server.hpp"
#include "lash/io/error.hpp"
#include "lash/io/line_tail.hpp"
#include "lash/rigs/pilot_valve_model.hpp"

#ifndef LASH_UPLOT_DIR
#define LASH_UPLOT_DIR ""
#endif

namespace lash::cli {

void add_console_options(CLI::App* app, ConsoleArgs& a) {
  a.opt = app->add_option("--console", a.port,
                          "Serve the live console (docs/console.md) on 127.0.0.1:PORT (no PORT or 0: any free port); "
                          "prints its URL")
              ->expected(0, 1);
  app->add_option("--console-bind", a.bind, "The console's address (default loopback only)")->needs(a.opt);
  app->add_flag("--console-read-only", a.read_only, "The console shows, but changes nothing")->needs(a.opt);
}

namespace {
std::filesystem::path uplot_dir() {
  if (const char* e = std::getenv("LASH_UPLOT_DIR"); e && *e) return e;
  return LASH_UPLOT_DIR;
}
int parse_port(const std::string& s) {
  if (s.empty()) return 0;
  try {
    std::size_t n = 0;
    const int p = std::stoi(s, &n);
    if (n == s.size() && p >= 0 && p <= 65535) return p;
  } catch (const std::exception&) {
  }
  throw InputError("", 0, "--console", "PORT must be 0..65535, got '" + s + "'");
}
}  // namespace

console::ConsoleOptions console_options(const ConsoleArgs& a, std::string title) {
  console::ConsoleOptions co;
  co.bind = a.bind;
  co.port = parse_port(a.port);
  co.read_only = a.read_only;
  co.uplot_dir = uplot_dir();
  co.title = std::move(title);
  return co;
}

namespace {
/// The slave's side of the bench as it crosses the bus (feed 1 of the console): its sensor frames
/// (Sensor_Counter = the slave's step, the pilot pressure code and its decoded value) and the
/// command frames it receives (current, counter): the slave.csv columns of the same names.
/// Time: the frame's arrival on this thread's clock, moved onto the master's DAQ clock with the
/// bridge's offset (XcpBridge::ecu_time_offset_s); no sample before the first DAQ sample.
const std::vector<std::string> kSlaveSignals{"slave_step", "slave_pilot_raw", "slave_measured_kPa",
                                             "slave_current_mA", "slave_command_counter"};

/// steady_s() - k * step_s for the slave's step k: the earliest over every sensor frame seen (its
/// Sensor_Counter unwrapped from 2^bits to the step), NaN before the first one. The slave sends
/// the frame of step k during step k, so this is the slave's step-0 release plus the smallest
/// send-to-arrival delay seen; slave_log_tail puts the log's rows on the tap's clock with it.
void note_slave_origin(std::atomic<double>& origin, double a) {
  double cur = origin.load();
  while ((std::isnan(cur) || a < cur) && !origin.compare_exchange_weak(cur, a)) {
  }
}

void slave_tap(const hil::BenchSettings& s, const hil::BenchLayout& L, console::Server& server,
               const console::XcpBridge& bridge, const std::atomic<bool>& stop, std::atomic<double>& origin) {
  std::unique_ptr<can::Bus> bus;
  try {
    bus = can::open_bus(s.bus);
    bus->set_filters({{L.sensors_id, 0x7FF, false}, {L.command_id, 0x7FF, false}});
  } catch (const std::exception& e) {
    server.set_status_text("slave_tap", std::string("cannot open the bus: ") + e.what());
    return;
  }
  const double zero = s.scenario ? hil::kScenarioPressureZero_kPa : 0.0;
  console::Sample smp;
  smp.count = static_cast<std::uint32_t>(kSlaveSignals.size());
  for (auto& v : smp.values) v = std::nan("");
  std::uint64_t frames = 0;
  const std::uint32_t bits = L.sensor_counter_bits();
  const std::uint64_t modulus = std::uint64_t{1} << bits;
  bool have_counter = false;
  std::uint64_t step = 0;  // the last sensor frame's counter, unwrapped
  while (!stop.load()) {
    const auto f = bus->receive(std::chrono::milliseconds(50));
    if (!f) continue;
    if (f->id == L.sensors_id) {
      const std::uint64_t c = L.unpack_sensors(*f).counter;
      if (!have_counter) {
        step = c;
        have_counter = true;
      } else {
        step += (c - (step % modulus) + modulus) % modulus;  // frames arrive in order on one bus
      }
      note_slave_origin(origin, console::steady_s() - static_cast<double>(step) * s.step_s);
    }
    const double off = bridge.ecu_time_offset_s();
    if (std::isnan(off)) continue;
    if (f->id == L.sensors_id) {
      const hil::SensorMsg m = L.unpack_sensors(*f);
      smp.values[0] = m.counter;
      smp.values[1] = m.pilot_raw;
      smp.values[2] = decode_pressure_raw(m.pilot_raw) - zero;
    } else {
      const hil::CommandMsg c = L.unpack_command(*f);
      smp.values[3] = c.solenoid_a_mA - c.solenoid_b_mA;
      smp.values[4] = c.counter;
    }
    smp.t_s = console::steady_s() - off;
    server.feed(1).push(smp);
    if (++frames % 200 == 0) server.set_status("slave_frames", static_cast<double>(frames));
  }
}
/// The slave's own log as it grows (feed 2): the columns of <out-dir>/slave.csv that do not cross
/// the bus, as slave_log_<column>. Time: step k at origin + k * step_s, moved onto the master's
/// DAQ clock like the tap's signals (the bridge's offset). Rows are read only once both are known
/// (from the file's start, so none is lost); the status shows the slave's state by name.
const std::vector<std::string> kSlaveLogColumns{"step",   "state", "command_fresh", "dropped", "pressure_kPa",
                                                "tet_us", "io_us", "wake_latency_us"};

std::vector<std::string> slave_log_signals() {
  std::vector<std::string> v;
  for (const auto& c : kSlaveLogColumns) v.push_back("slave_log_" + c);
  return v;
}

void slave_log_tail(const std::filesystem::path& csv, double step_s, console::Server& server,
                    const console::XcpBridge& bridge, const std::atomic<bool>& stop,
                    const std::atomic<double>& origin) {
  LineTail tail(csv);
  std::vector<std::size_t> col;  // file column of each kSlaveLogColumns entry; empty: header not read
  std::uint64_t restarts = 0, rows = 0, bad = 0;
  std::size_t step_col = 0;
  double last_state = std::nan("");
  console::Sample smp;
  smp.count = static_cast<std::uint32_t>(kSlaveLogColumns.size());
  std::vector<std::string_view> fields;
  auto split = [&fields](std::string_view line) {
    fields.clear();
    for (std::size_t p = 0;;) {
      const std::size_t q = line.find(',', p);
      fields.push_back(line.substr(p, q == std::string_view::npos ? std::string_view::npos : q - p));
      if (q == std::string_view::npos) break;
      p = q + 1;
    }
  };
  auto on_line = [&](std::string_view line) {
    split(line);
    if (col.empty()) {  // the header
      std::vector<std::size_t> c;
      for (const auto& name : kSlaveLogColumns) {
        std::size_t i = 0;
        while (i < fields.size() && fields[i] != name) ++i;
        if (i == fields.size()) {
          server.set_status_text("slave_log", csv.filename().string() + ": no column '" + name + "'");
          c.clear();
          break;
        }
        c.push_back(i);
      }
      col = c;
      if (!col.empty()) {
        step_col = col[0];
        server.set_status_text("slave_log", "following " + csv.filename().string());
      }
      return;
    }
    const double t0 = origin.load(), off = bridge.ecu_time_offset_s();
    double step = std::nan("");
    for (std::size_t j = 0; j < col.size(); ++j) {
      double v = std::nan("");
      if (col[j] < fields.size()) {
        const auto f = fields[col[j]];
        if (std::from_chars(f.data(), f.data() + f.size(), v).ec != std::errc{}) v = std::nan("");
      }
      smp.values[j] = v;
      if (col[j] == step_col) step = v;
    }
    if (std::isnan(step)) {  // a damaged row: counted, not shown
      server.set_status("slave_log_bad_rows", static_cast<double>(++bad));
      return;
    }
    smp.t_s = t0 + step * step_s - off;
    server.feed(2).push(smp);
    ++rows;
    const double state = smp.values[1];
    if (!std::isnan(state) && state != last_state) {
      const std::string name(hil::to_string(static_cast<hil::NodeState>(static_cast<int>(state))));
      if (!std::isnan(last_state)) server.add_event(smp.t_s, "slave_state", name);
      last_state = state;
      server.set_status_text("slave_state", name);
    }
  };
  server.set_status_text("slave_log", "waiting for the first sensor frame and DAQ sample (the time base)");
  constexpr std::size_t kChunk = 64 * 1024;  // about 800 rows, a fifth of the feed's ring
  while (!stop.load()) {
    bool more = false;
    if (!std::isnan(origin.load()) && !std::isnan(bridge.ecu_time_offset_s())) {
      if (tail.restarts() != restarts) {  // the file was replaced: its header comes again
        restarts = tail.restarts();
        col.clear();
      }
      const std::uint64_t before = tail.offset();
      tail.poll(on_line, kChunk);
      if (!tail.opened()) server.set_status_text("slave_log", "waiting for " + csv.filename().string());
      more = tail.offset() - before >= kChunk;
      server.set_status("slave_log_rows", static_cast<double>(rows));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(more ? 10 : 50));
  }
}
}  // namespace

struct HilConsole::Impl {
  std::unique_ptr<console::XcpBridge> bridge;
  std::unique_ptr<console::Server> server;
  hil::BenchSettings settings;
  hil::BenchLayout layout;
  std::filesystem::path slave_csv;
  std::atomic<bool> stop{false};
  std::atomic<double> slave_origin{std::numeric_limits<double>::quiet_NaN()};
  std::thread tap, log_tail;
};

HilConsole::HilConsole(const ConsoleArgs& a, const hil::BenchSettings& s, const std::filesystem::path& out_dir)
    : impl_(std::make_unique<Impl>()) {
  const hil::BenchLayout L = hil::BenchLayout::from_dbc(s.dbc_file);
  console::XcpBridgeOptions bo;
  bo.bus = s.bus;
  bo.info = hil::master_a2l_info(L, s.step_s);
  bo.objects = hil::master_xcp_config(L).objects;
  bo.state_name = [](double v) {
    return std::string(hil::to_string(static_cast<hil::NodeState>(static_cast<int>(v))));
  };
  impl_->bridge = std::make_unique<console::XcpBridge>(bo);
  console::ConsoleOptions co = console_options(a, "lash hil run (master, measured over XCP DAQ)");
  co.signals = impl_->bridge->signals();
  co.extra_feeds = {kSlaveSignals, slave_log_signals()};
  impl_->slave_csv = out_dir / "slave.csv";
  impl_->settings = s;
  impl_->layout = L;
  co.params = impl_->bridge->params();
  co.decimation.base_s = s.step_s;
  auto* bridge = impl_->bridge.get();
  impl_->server = std::make_unique<console::Server>(
      co, [bridge](const std::string& n, double v) { return bridge->tune(n, v); });
  fmt::print(stderr, "lash console: {}\n", impl_->server->url());
  std::fflush(stderr);
}

HilConsole::~HilConsole() { stop(); }

void HilConsole::start() {
  impl_->server->start();
  impl_->bridge->start(*impl_->server);
  impl_->tap = std::thread(
      [im = impl_.get()] { slave_tap(im->settings, im->layout, *im->server, *im->bridge, im->stop, im->slave_origin); });
  impl_->log_tail = std::thread([im = impl_.get()] {
    slave_log_tail(im->slave_csv, im->settings.step_s, *im->server, *im->bridge, im->stop, im->slave_origin);
  });
}

void HilConsole::stop() {
  impl_->stop.store(true);
  if (impl_->tap.joinable()) impl_->tap.join();
  if (impl_->log_tail.joinable()) impl_->log_tail.join();
  if (impl_->bridge) impl_->bridge->stop();
  if (impl_->server) impl_->server->stop();
}

}  // namespace lash::cli

namespace lash::cli {

struct MonitorConsole::Impl {
  std::unique_ptr<console::Server> server;
  std::atomic<std::uint64_t> samples{0};
  std::atomic<double> last_sample_s{std::nan("")};  // steady_s() of the last sample
  double stale_timeout_s = 0.5;
  std::atomic<bool> stop{false};
  std::thread status;
};

MonitorConsole::MonitorConsole(const ConsoleArgs& a, monitor::MonitorSettings& s) : impl_(std::make_unique<Impl>()) {
  console::ConsoleOptions co = console_options(a, "lash monitor " + s.source);
  co.read_only = true;  // nothing to tune: the monitor only listens
  co.signals = {"v", "y"};
  co.decimation.base_s = s.dt_s > 0 ? s.dt_s : 0.001;
  impl_->server = std::make_unique<console::Server>(co, console::Tuner{});
  impl_->stale_timeout_s = s.stale_timeout_s;
  fmt::print(stderr, "lash console: {}\n", impl_->server->url());
  std::fflush(stderr);
  impl_->server->start();
  auto* im = impl_.get();
  s.on_sample = [im](double t, double v, double y) {
    console::Sample smp;
    smp.t_s = t;
    smp.count = 2;
    smp.values[0] = v;
    smp.values[1] = y;
    im->server->feed().push(smp);
    im->samples.fetch_add(1, std::memory_order_relaxed);
    im->last_sample_s.store(console::steady_s(), std::memory_order_relaxed);
  };
  impl_->status = std::thread([im] {
    std::uint64_t last = 0;
    double t_last = console::steady_s();
    while (!im->stop.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      const double now = console::steady_s();
      if (now - t_last >= 1.0) {
        const std::uint64_t n = im->samples.load();
        im->server->set_status("samples_per_s", static_cast<double>(n - last) / (now - t_last));
        last = n;
        t_last = now;
      }
      const double ls = im->last_sample_s.load();
      im->server->set_status_text("stale", std::isnan(ls) ? "waiting for the first sample"
                                           : now - ls > im->stale_timeout_s
                                               ? fmt::format("stale: no sample for {:.1f} s", now - ls)
                                               : "ok");
    }
  });
}

MonitorConsole::~MonitorConsole() { stop(); }

void MonitorConsole::period(const monitor::Period& p, const monitor::MonitorCounts& c) {
  auto& sv = *impl_->server;
  for (const auto& v : p.params) sv.add_estimate(p.t, v.name, v.value, v.lo, v.hi, v.identified);
  for (const auto& e : p.events)
    sv.add_event(e.t, e.kind,
                 e.param.empty() ? e.kind : fmt::format("{} {:.4g} -> {:.4g}", e.param, e.before, e.after));
  sv.set_status_text("period", p.status);
  sv.set_status("periods", static_cast<double>(c.periods));
  sv.set_status("frames", static_cast<double>(c.frames));
  sv.set_status("frames_dropped", static_cast<double>(c.dropped()));
  sv.set_status("stale_silences", static_cast<double>(c.stale));
  sv.set_status("counter_jumps", static_cast<double>(c.counter_jumps));
  sv.set_status("events", static_cast<double>(c.events));
}

void MonitorConsole::stop() {
  impl_->stop.store(true);
  if (impl_->status.joinable()) impl_->status.join();
  if (impl_->server) impl_->server->stop();
}

}  // namespace lash::cli
