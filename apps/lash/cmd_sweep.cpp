// lash sweep: run a campaign of virtual-rig runs (docs/method.md §A7, E3–E5) in parallel and report NRMSE.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <set>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "csv_stream.hpp"
#include "lash/io/atomic_file.hpp"
#include "plot.hpp"
#include "lash/experiments/campaign.hpp"
#include "lash/experiments/sweep.hpp"

namespace lash::cli {
namespace {

struct SweepOptions {
  std::string campaign;
  unsigned jobs = 0;
  std::string out;
  std::string plot;
  bool json = false;
  bool quiet = false;
  std::vector<std::string> trace;  // RUN FILE
};

/// `--trace RUN FILE`: run RUN again (runs are deterministic) and write every sample.
void write_trace(const sweep::Campaign& c, const std::vector<std::string>& arg) {
  std::size_t idx = 0;
  try {
    std::size_t used = 0;
    const unsigned long long v = std::stoull(arg[0], &used);
    if (used != arg[0].size() || arg[0].find('-') != std::string::npos) throw std::invalid_argument(arg[0]);
    idx = static_cast<std::size_t>(v);
  } catch (const std::exception&) {
    throw InputError("", 0, "--trace", "RUN must be a run number (column 'run' of the results), got '" + arg[0] + "'");
  }
  if (idx >= c.runs.size())
    throw InputError("", 0, "--trace",
                     fmt::format("run {} does not exist: the campaign has runs 0..{}", idx, c.runs.size() - 1));
  // Rows go to the file as the run produces them: memory O(1) in the run's length.
  CsvStream csv(arg[1], {"t_s", "v", "y", "y_sim", "a1_r", "b1_r", "c_r", "a1_l", "b1_l", "c_l"});
  sweep::run_one(c, c.runs[idx], [&csv](const sweep::TraceRow& r) {
    const double vals[10] = {r.t_s,           r.v,           r.y,           r.y_sim,       r.side.right.a1,
                             r.side.right.b1, r.side.right.c, r.side.left.a1, r.side.left.b1, r.side.left.c};
    csv.row(vals);
  });
  csv.commit();
}

/// Progress bar on stderr: runs done/total, elapsed, ETA. Redrawn in place on a terminal,
/// one line per 10 % otherwise (logs stay short).
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled), tty_(isatty(fileno(stderr)) != 0) {}
  void operator()(std::size_t done, std::size_t total) {
    if (!enabled_ || total == 0) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = done > 0 ? elapsed * static_cast<double>(total - done) / static_cast<double>(done) : 0.0;
    const int width = 30;
    const int fill = static_cast<int>(static_cast<double>(width) * static_cast<double>(done) / static_cast<double>(total));
    const std::string bar = std::string(static_cast<std::size_t>(fill), '#') + std::string(static_cast<std::size_t>(width - fill), '.');
    const std::string text = fmt::format("[{}] {}/{} runs  elapsed {:.1f} s  ETA {:.1f} s", bar, done, total, elapsed, eta);
    if (tty_) {
      fmt::print(stderr, "\r{}", text);
      if (done == total) fmt::print(stderr, "\n");
    } else {
      const std::size_t decile = done * 10 / total;
      if (decile != last_decile_ || done == total) {
        if (done == total && printed_final_) return;
        fmt::print(stderr, "{}\n", text);
        last_decile_ = decile;
        printed_final_ = done == total;
      }
    }
    std::fflush(stderr);
  }

 private:
  bool enabled_, tty_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::size_t last_decile_ = static_cast<std::size_t>(-1);
  bool printed_final_ = false;
};

/// Fig. 1.34/1.39/1.44 analogue: NRMSE [%] against frequency, one line per amplitude, one panel
/// per waveform (randomized runs: NRMSE against run number).
void plot_sweep(const sweep::Campaign& c, const std::vector<sweep::RunResult>& results, const std::string& csv,
                const std::string& png) {
  std::vector<std::string> wfs;
  std::set<double> amps;
  for (const auto& r : results) {
    const std::string w = to_string(r.spec.waveform);
    if (std::find(wfs.begin(), wfs.end(), w) == wfs.end()) wfs.push_back(w);
    if (r.spec.waveform != Waveform::randomized) amps.insert(r.spec.amplitude);
  }
  std::string s;
  s += fmt::format("set terminal pngcairo size 900,{} font 'sans,9'\n", 260 * wfs.size() + 40);
  s += "set output '<OUTPUT>'\nset datafile separator ','\nset grid\nset key outside right\nset logscale y\n";
  s += fmt::format("set multiplot layout {},1 title \"{} (virtual rig): NRMSE {}–{} s\"\n", wfs.size(), c.name,
                   format_double(c.window_start_s), format_double(c.window_end_s));
  for (const auto& w : wfs) {
    s += "set ylabel 'NRMSE [%]'\n";
    const std::string limit = fmt::format("{} with lines dt 2 lc rgb 'red' title '{} %'", 100 * c.good_nrmse,
                                          format_double(100 * c.good_nrmse));
    if (w == "randomized") {
      s += "set xlabel 'randomized run'\nset title 'randomized'\n";
      s += fmt::format("plot '{}' using (strcol(2) eq 'randomized' ? $5 : NaN):(100*$7) every ::1 with points pt 7 title 'randomized', {}\n", csv, limit);
    } else {
      s += fmt::format("set xlabel 'frequency [rad/s]'\nset title '{}'\n", w);
      s += "plot ";
      int i = 0;
      for (double a : amps) {
        // Amplitudes side by side around each frequency so repeats do not hide each other.
        const double dx = 0.08 * (i - 0.5 * static_cast<double>(amps.size() - 1));
        s += fmt::format("'{}' using (strcol(2) eq '{}' && $3 == {} ? $4 + {} : NaN):(100*$7) every ::1 with points pt 7 ps 0.8 title 'A = {}', ",
                         csv, w, format_double(a), dx, format_double(a));
        ++i;
      }
      s += limit + "\n";
    }
  }
  s += "unset multiplot\n";
  run_gnuplot(s, png);
}

int run(const SweepOptions& o) {
  const sweep::Campaign c = sweep::load_campaign(o.campaign);
  // Every output is checked before any run.
  check_output_path(o.out, "--output");
  if (!o.plot.empty()) check_output_path(o.plot, "--plot");
  if (!o.trace.empty()) check_output_path(o.trace[1], "--trace");
  if (!o.trace.empty()) {
    write_trace(c, o.trace);
    if (!o.quiet) fmt::print(stderr, "trace of run {} -> {}\n", o.trace[0], o.trace[1]);
  }
  ProgressBar bar(!o.quiet);
  const auto t0 = std::chrono::steady_clock::now();
  const auto results = sweep::run_campaign(c, o.jobs, [&](std::size_t d, std::size_t n) { bar(d, n); });
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sweep::write_results_csv(o.out, c, results);
  if (!o.plot.empty()) plot_sweep(c, results, o.out, o.plot);
  const sweep::Summary s = sweep::summarize(c, results);
  if (o.json) {
    fmt::print("{}", sweep::summary_json(c, s, results));
  } else {
    fmt::print("{}", sweep::summary_text(c, s, results));
    fmt::print("wall time {:.2f} s ({:.1f} runs/s); results -> {}{}\n", wall,
               static_cast<double>(results.size()) / wall, o.out, o.plot.empty() ? "" : ", plot -> " + o.plot);
  }
  return kExitOk;
}

}  // namespace

int demo_e3_campaign(const std::string& out_dir) {
  for (const char* name : {"e3_motor_cart", "e3_motor_cart_lash"}) {
    const std::string file = source_dir() + "/config/campaigns/" + name + ".toml";
    const sweep::Campaign c = sweep::load_campaign(file);
    fmt::print("\n{}: {} runs on the virtual motor-cart rig ({})\n", c.name, c.runs.size(), file);
    std::fflush(stdout);
    ProgressBar bar(true);
    const auto t0 = std::chrono::steady_clock::now();
    const auto results = sweep::run_campaign(c, 0, [&](std::size_t d, std::size_t n) { bar(d, n); });
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::string csv = out_dir + "/" + name + ".csv";
    const std::string png = out_dir + "/" + name + ".png";
    sweep::write_results_csv(csv, c, results);
    plot_sweep(c, results, csv, png);
    fmt::print("{}", sweep::summary_text(c, sweep::summarize(c, results), results));
    fmt::print("wall time {:.2f} s ({:.1f} runs/s); wrote {} and {}\n", wall, static_cast<double>(results.size()) / wall,
               csv, png);
  }
  return kExitOk;
}

Command add_sweep(CLI::App& app) {
  auto o = std::make_shared<SweepOptions>();
  auto* sub = app.add_subcommand("sweep", "Run a campaign of virtual-rig runs (E3-E5) in parallel and report NRMSE");
  sub->add_option("campaign", o->campaign, "Campaign file (TOML, see docs/sweep.md)")->required();
  sub->add_option("-j,--jobs", o->jobs, "Worker threads, 0..1024 (0 = all cores)")
      ->check(CLI::Range(0u, 1024u));
  sub->add_option("-o,--output", o->out, "Results CSV, one row per run")->required();
  sub->add_option("--plot", o->plot, "Also draw NRMSE against amplitude/frequency per waveform (PNG, gnuplot)");
  sub->add_flag("--json", o->json, "Print the summary as JSON");
  sub->add_flag("-q,--quiet", o->quiet, "No progress bar");
  sub->add_option("--trace", o->trace,
                  "RUN FILE: also write every sample of run RUN (t_s, v, y, y_sim, a1/b1/c per side) as CSV")
      ->expected(2);
  return {sub, [o] { return run(*o); }};
}

}  // namespace lash::cli
