// lash monitor: identify a running machine from its CAN bus or a log, live (docs/monitor.md).
// Parse, call lash::monitor, print.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "cmd_can.hpp"
#include "console_options.hpp"
#include "estimate_settings.hpp"
#include "lash/monitor/monitor.hpp"
#include "plot.hpp"

namespace lash::cli {
namespace {

constexpr int kExitAlarm = 3;

struct MonitorOptions {
  EstimateOptions est;  // --model, --config, --preset and the estimator's field-table options
  monitor::MonitorSettings s;
  std::string report;
  std::string report_png;
  bool quiet = false;
  std::string mode = "window";
  bool no_reguess = false;
  ConsoleArgs console;
};

std::string num(double x) { return std::isfinite(x) ? fmt::format("{:.4g}", x) : "-"; }

/// One line per period on a terminal: per side c, d, K, τ with their 95 % intervals.
void status_line(const monitor::Period& p, const monitor::MonitorCounts& c, double wall_s) {
  std::string line = fmt::format("\r\033[2Kt={:.1f}s {} ", p.t, p.status);
  for (const auto& v : p.params) {
    line += fmt::format("{}={}", v.name, v.identified ? num(v.value) : "?");
    if (v.identified && std::isfinite(v.lo)) line += fmt::format("[{},{}]", num(v.lo), num(v.hi));
    line += " ";
  }
  line += fmt::format("| {:.0f} samples/s, {} dropped, {} events, {} re-guesses",
                      wall_s > 0 ? double(c.samples) / wall_s : 0.0, c.dropped(), c.events, c.reguesses);
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
}

void print_summary(const monitor::MonitorResult& r) {
  const auto& c = r.counts;
  fmt::print(stderr,
             "lash monitor: {} frames, {} samples over {} s, {} periods, {} events{}\n"
             "lash monitor: dropped {}: garbage {}, bad_dlc {}, out_of_range {}, time_back {}, bus {}; "
             "counter_jumps {}, stale {}, gaps {}, restarts {}, reguesses {}; {:.3g} frames/s\n",
             c.frames, c.samples, format_double(r.t_end), c.periods, c.events,
             r.interrupted ? " (interrupted)" : (r.alarm ? " (stopped at the first alarm)" : ""), c.dropped(),
             c.garbage, c.bad_dlc, c.out_of_range, c.time_back, c.bus_dropped, c.counter_jumps, c.stale, c.gaps,
             c.restarts, c.reguesses, r.wall_s > 0 ? double(c.frames) / r.wall_s : 0.0);
}

/// lash monitor --report DB -o PNG: every parameter over time with its 95 % band, events as lines.
int run_report(const MonitorOptions& o) {
  if (o.report_png.empty()) throw InputError("", 0, "-o", "give the PNG to write (-o trend.png)");
  const monitor::History h = monitor::read_history(o.report);
  std::vector<std::string> params;
  for (const auto& r : h.estimates)
    if (std::find(params.begin(), params.end(), r.param) == params.end()) params.push_back(r.param);
  if (params.empty()) throw InputError(o.report, 0, "--report", "the database holds no estimates");
  const auto tmp = std::filesystem::temp_directory_path() / ("lash-monitor-" + std::to_string(::getpid()) + ".dat");
  {
    std::ofstream f(tmp);
    for (const auto& p : params) {  // one gnuplot data block per parameter (index i)
      f << "# " << p << "\n";
      for (const auto& r : h.estimates)
        if (r.param == p && r.identified)
          f << format_double(r.t) << ' ' << format_double(r.value) << ' '
            << (std::isfinite(r.lo) ? format_double(r.lo) : "NaN") << ' '
            << (std::isfinite(r.hi) ? format_double(r.hi) : "NaN") << '\n';
      f << "\n\n";
    }
  }
  std::string gp = fmt::format(
      "set terminal pngcairo size 1000,{} noenhanced\nset output '<OUTPUT>'\nset multiplot layout {},1 title '{}'\n"
      "set grid\nset key left top\n",
      220 * params.size() + 80, params.size(),
      "lash monitor " + (h.meta.count("source") ? h.meta.at("source") : o.report));
  for (const auto& e : h.events)
    if (e.alarm())
      gp += fmt::format("set arrow from {},graph 0 to {},graph 1 nohead lc rgb 'red' dt 2\n", format_double(e.t),
                        format_double(e.t));
  for (std::size_t i = 0; i < params.size(); ++i) {
    gp += fmt::format("set ylabel '{}'\n", params[i]);
    if (i + 1 == params.size()) gp += "set xlabel 't [s] (red: drift/threshold events)'\n";
    gp += fmt::format(
        "plot '{0}' index {1} using 1:3:4 with filledcurves lc rgb '#c8d8f0' title '95 %', "
        "'{0}' index {1} using 1:2 with linespoints pt 7 ps 0.5 lc rgb '#1f4e9a' title '{2}'\n",
        tmp.string(), i, params[i]);
  }
  gp += "unset multiplot\n";
  try {
    run_gnuplot(gp, o.report_png);
  } catch (...) {
    std::filesystem::remove(tmp);
    throw;
  }
  std::filesystem::remove(tmp);
  fmt::print(stderr, "lash monitor: {} parameters, {} periods' rows, {} events -> {}\n", params.size(),
             h.estimates.size(), h.events.size(), o.report_png);
  return kExitOk;
}

int run(const CLI::App& sub, MonitorOptions& o) {
  if (!o.report.empty()) return run_report(o);
  auto& s = o.s;
  if (s.source.empty()) throw InputError("", 0, "SOURCE", "give a bus address or a log file (or --report DB)");
  for (const auto& [value, name] : {std::pair{&s.dbc, "--dbc"}, std::pair{&s.v, "--v"}, std::pair{&s.y, "--y"}})
    if (value->empty()) throw InputError("", 0, name, "is required");
  const std::string config = o.est.config;
  o.est.config.clear();
  s.estimator = settings_sources(sub, o.est);
  try {
    s.mode = monitor::parse_estimate_mode(o.mode);
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, "--estimate", e.what());
  }
  s.online.reguess.enabled = !o.no_reguess;
  if (!config.empty()) monitor::apply_monitor_config(config, s);
  monitor::check_settings(s);  // exit 2 before anything is read or written
  can_cmd::install_stop_handler();
  const bool tty = !o.quiet && ::isatty(2) == 1;
  const auto wall0 = std::chrono::steady_clock::now();
  std::unique_ptr<MonitorConsole> con;  // --console: the page of v, y, the estimates and events
  if (o.console.enabled()) con = std::make_unique<MonitorConsole>(o.console, s);
  const auto result = monitor::run_monitor(s, &can_cmd::g_stop, [&](const monitor::Period& p, const auto& c) {
    if (con) con->period(p, c);
    if (tty)
      status_line(p, c, std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  });
  if (con) con->stop();
  if (tty) std::fputs("\n", stderr);
  if (!o.quiet) print_summary(result);
  return result.alarm ? kExitAlarm : kExitOk;
}

}  // namespace

Command add_monitor(CLI::App& app) {
  auto o = std::make_shared<MonitorOptions>();
  auto* sub = app.add_subcommand("monitor", "Identify a running machine from its CAN bus or a log, live, with a "
                                            "SQLite history and alarms (docs/monitor.md)");
  auto& s = o->s;
  sub->add_option("source", s.source, "Bus address (udp:GROUP:PORT, socketcan:IFACE, mem:NAME) or log file "
                                      "(candump -L, .asc, .blf, .trc)");
  sub->add_option("--dbc", s.dbc, "DBC file of the bus");
  sub->add_option("--v", s.v, "Input: MSG.SIG or MSG.SIG-MSG.SIG (physical values)");
  sub->add_option("--y", s.y, "Output: MSG.SIG or MSG.SIG-MSG.SIG; each frame of its message is one sample");
  sub->add_option("--model", o->est.model, "linear | input-deadzone | output-deadzone | deadzone-deadband | coupled-carts");
  sub->add_option("--config", o->est.config, "Estimator keys (as lash estimate --config) plus [alarms] and [drift]");
  sub->add_option("--preset", o->est.preset, "lash (default) | thesis");
  add_setting_options(*sub, o->est);
  sub->add_option("--every", s.every_s, "Period of the estimates [s of frame time] (default 1)");
  sub->add_option("--dt", s.dt_s, "Resample at this fixed period, zero-order hold [s] (default: one sample per y frame)");
  sub->add_option("--stale-timeout", s.stale_timeout_s, "No watched frame for this long = stale [s] (default 0.5)");
  sub->add_option("--window", s.window_s,
                  "Each estimate covers the samples of the last S seconds; memory and cost per period bounded "
                  "(default 120; 0: every sample since the start, unbounded)");
  sub->add_option("--estimate", o->mode,
                  "window (default): each period re-estimates its --window from scratch, O(window) per period; "
                  "online: one persistent estimator, O(1) per period (a log at > 2 M frames/s; its drift "
                  "events come later, docs/monitor.md)");
  sub->add_option("--init", s.online.init_s,
                  "online: the data-tuned settings and switching guesses are chosen from the first S seconds "
                  "[s] (default 10)");
  sub->add_flag("--no-reguess", o->no_reguess, "online: keep the switching guesses chosen at the start");
  sub->add_option("--record", s.record_csv, "Write the t,v,y samples exactly as fed to the estimator (CSV)");
  sub->add_option("--jsonl", s.jsonl, "One JSON object per period and per event; - = stdout");
  sub->add_option("--db", s.db, "SQLite history (WAL, one transaction per period)");
  sub->add_option("--duration", s.duration_s, "Stop after S seconds [s] (default: end of the log, or a signal)");
  sub->add_flag("--until-alarm", s.until_alarm, "Exit 3 after the period with the first drift or threshold event");
  sub->add_flag("--realtime", s.realtime, "Read a log at its recorded pace");
  sub->add_flag("--quiet", o->quiet, "No status line and no summary on stderr");
  sub->add_option("--report", o->report, "Plot the history of this database instead (with -o)");
  sub->add_option("-o,--output", o->report_png, "PNG of --report");
  add_console_options(sub, o->console);
  return {sub, [o, sub] { return run(*sub, *o); }};
}

}  // namespace lash::cli
