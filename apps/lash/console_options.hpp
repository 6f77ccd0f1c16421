#pragma once
// --console [PORT], --console-bind ADDR, --console-read-only: the live console of a run
// (docs/console.md). Parsing and wiring only; the console is lash::console.
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "lash/console/server.hpp"
#include "lash/hil/settings.hpp"
#include "lash/monitor/monitor.hpp"

namespace lash::cli {

struct ConsoleArgs {
  std::string port;  // "" with the flag given: 0 (any free port)
  std::string bind = "127.0.0.1";
  bool read_only = false;
  CLI::Option* opt = nullptr;
  bool enabled() const { return opt && opt->count() > 0; }
};

void add_console_options(CLI::App* app, ConsoleArgs& a);
/// The server's options from the command line: address, port, read-only, uPlot's directory.
console::ConsoleOptions console_options(const ConsoleArgs& a, std::string title);

/// The console of `lash hil run`: its server is bound at construction (in the caller's network
/// namespace, so the browser reaches it from the host), prints the URL; start() joins the bench's
/// bus through XCP (call it inside the session's namespace, once the master was started) and
/// follows out_dir/slave.csv as the slave writes it (the slave_log_* signals).
class HilConsole {
 public:
  HilConsole(const ConsoleArgs& a, const hil::BenchSettings& s, const std::filesystem::path& out_dir);
  ~HilConsole();
  void start();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The console of `lash monitor` (read-only page: v, y, the estimates with their 95 % bands and
/// verdicts, events, samples/s and stale status). The constructor binds, prints the URL, starts
/// the server and sets `s.on_sample` (the monitor's thread pushes into the console's ring only);
/// period() is the monitor's period callback.
class MonitorConsole {
 public:
  MonitorConsole(const ConsoleArgs& a, monitor::MonitorSettings& s);
  ~MonitorConsole();
  void period(const monitor::Period& p, const monitor::MonitorCounts& c);
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lash::cli
