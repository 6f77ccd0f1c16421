// --console options and the wiring of `lash hil run --console` (docs/console.md).
#include "console_options.hpp"

#include <cstdlib>
#include <string>

#include <fmt/core.h>

#include "lash/console/server.hpp"
#include "lash/console/xcp_bridge.hpp"
#include "lash/hil/bench_layout.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/hil/xcp_server.hpp"
#include "lash/io/error.hpp"

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

struct HilConsole::Impl {
  std::unique_ptr<console::XcpBridge> bridge;
  std::unique_ptr<console::Server> server;
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
  console::ConsoleOptions co;
  co.bind = a.bind;
  co.port = parse_port(a.port);
  co.read_only = a.read_only;
  co.uplot_dir = uplot_dir();
  co.title = "lash hil run (master, measured over XCP DAQ)";
  co.signals = impl_->bridge->signals();
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
}

void HilConsole::stop() {
  if (impl_->bridge) impl_->bridge->stop();
  if (impl_->server) impl_->server->stop();
}

}  // namespace lash::cli
