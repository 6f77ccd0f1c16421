// --console options and the wiring of `lash hil run --console` (docs/console.md).
#include "console_options.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>

#include <fmt/core.h>

#include "lash/console/server.hpp"
#include "lash/console/xcp_bridge.hpp"
#include "lash/hil/bench_layout.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/hil/xcp_server.hpp"
#include "lash/io/error.hpp"
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

void slave_tap(const hil::BenchSettings& s, const hil::BenchLayout& L, console::Server& server,
               const console::XcpBridge& bridge, const std::atomic<bool>& stop) {
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
  while (!stop.load()) {
    const auto f = bus->receive(std::chrono::milliseconds(50));
    if (!f) continue;
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
}  // namespace

struct HilConsole::Impl {
  std::unique_ptr<console::XcpBridge> bridge;
  std::unique_ptr<console::Server> server;
  hil::BenchSettings settings;
  hil::BenchLayout layout;
  std::atomic<bool> stop{false};
  std::thread tap;
};

HilConsole::HilConsole(const ConsoleArgs& a, const hil::BenchSettings& s) : impl_(std::make_unique<Impl>()) {
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
  co.extra_feeds = {kSlaveSignals};
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
      [im = impl_.get()] { slave_tap(im->settings, im->layout, *im->server, *im->bridge, im->stop); });
}

void HilConsole::stop() {
  impl_->stop.store(true);
  if (impl_->tap.joinable()) impl_->tap.join();
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
