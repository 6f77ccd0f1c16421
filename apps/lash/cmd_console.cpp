// lash console demo: the console fed by a synthetic producer (docs/console.md, the load case:
// 32 signals at 1 kHz). Parse, wire lash::console, print.
#include <chrono>
#include <fstream>
#include <thread>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "cmd_can.hpp"
#include "console_options.hpp"
#include "lash/console/server.hpp"
#include "lash/console/synthetic.hpp"

namespace lash::cli {
namespace {

struct DemoOptions {
  console::SyntheticOptions syn;
  ConsoleArgs console;
};

/// Resident set size of this process [kB] (/proc/self/status VmRSS), 0 when unknown.
long rss_kB() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return 0;
}

int run_demo(const DemoOptions& o) {
  o.syn.validate();
  console::SyntheticProducer producer(o.syn);
  console::ConsoleOptions co = console_options(
      o.console, fmt::format("lash console demo ({} synthetic signals at {} Hz)", o.syn.signals, o.syn.rate_hz));
  co.signals = producer.names();
  co.decimation.base_s = 1.0 / o.syn.rate_hz;
  console::Server server(co, {});
  fmt::print(stderr, "lash console: {}\n", server.url());
  std::fflush(stderr);
  can_cmd::install_stop_handler();
  server.start();
  producer.start(server.feed());
  const auto t0 = std::chrono::steady_clock::now();
  std::uint64_t last = 0;
  int sec = 0;
  while (!can_cmd::g_stop.load() && !producer.done()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (el >= sec + 1) {
      ++sec;
      const std::uint64_t n = producer.produced();
      server.set_status("producer_samples_per_s", static_cast<double>(n - last));
      server.set_status("rss_kB", static_cast<double>(rss_kB()));
      last = n;
      if (sec % 10 == 0) server.add_event(static_cast<double>(n) / o.syn.rate_hz, "demo", fmt::format("{} s", sec));
    }
  }
  producer.stop();
  server.stop();
  fmt::print("lash console demo: {} samples of {} signals, {} dropped by the console's ring, {} requests, rss {} kB\n",
             producer.produced(), o.syn.signals, server.drops(), server.requests(), rss_kB());
  return kExitOk;
}

}  // namespace

Command add_console(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  auto* sub = app.add_subcommand("console", "The live console (docs/console.md)");
  sub->require_subcommand(1);
  auto* demo = sub->add_subcommand(
      "demo", "Serve the console fed by a synthetic producer (the load case: 32 signals at 1 kHz); "
              "prints the URL; runs until --duration or Ctrl-C");
  demo->add_option("--signals", o->syn.signals, "Number of signals (1..32, default 32)");
  demo->add_option("--rate", o->syn.rate_hz, "Samples per second [Hz] (default 1000)");
  demo->add_option("--duration", o->syn.duration_s, "Stop after this long [s] (default 0: until Ctrl-C)");
  demo->add_option("--seed", o->syn.seed, "Seed of the signals' noise (default 1)");
  add_console_options(demo, o->console);
  return {sub, [o] { return run_demo(*o); }};
}

}  // namespace lash::cli
