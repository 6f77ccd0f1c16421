// lash demo: the main job of `make demo`.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "plot.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"
#include "lash/experiments/scenario.hpp"

namespace lash::cli {
namespace {

const char* const kParams[] = {"a1", "b1", "c", "d"};
double param(const SideParams& p, int i) { return i == 0 ? p.a1 : i == 1 ? p.b1 : i == 2 ? p.c : p.d; }

std::string pct(double x) { return std::isfinite(x) ? fmt::format("{:.4f}", x) : std::string("n/a"); }

/// E1 / E2 (docs/method.md §A7): parameter, truth, estimate, error % (seed 1), worst error % over all seeds.
void identification_tables(const std::string& dir) {
  for (const char* file : {"e1.toml", "e2.toml"}) {
    const ScenarioSpec s = load_scenario(dir + "/" + file);
    std::vector<ScenarioRun> runs;
    for (auto seed : s.seeds) runs.push_back(run_scenario(s, seed));
    fmt::print("\n{}: {}\n", s.name, s.description);
    fmt::print("{:<6} {:>10} {:>16} {:>10}", "param", "truth", "estimate", "error %");
    if (runs.size() > 1) fmt::print(" {:>22}", fmt::format("worst % seeds {}-{}", s.seeds.front(), s.seeds.back()));
    if (s.checkpoints_s.size() > 1) fmt::print(" {:>14}", fmt::format("error % @{}s", format_double(s.checkpoints_s[0])));
    fmt::print("\n");
    for (Side side : {Side::right, Side::left}) {
      for (int i = 0; i < 4; ++i) {
        const double truth = param(s.truth[side], i);
        const double est = param(runs[0].at.back()[side], i);
        fmt::print("{:<6} {:>10} {:>16.8g} {:>10}", fmt::format("{}_{}", kParams[i], side == Side::right ? 'r' : 'l'),
                   format_double(truth), est, pct(error_percent(est, truth)));
        if (runs.size() > 1) {
          double worst = 0;
          for (const auto& r : runs) {
            const double e = error_percent(param(r.at.back()[side], i), truth);
            worst = std::isfinite(e) ? std::max(worst, e) : e;
          }
          fmt::print(" {:>22}", pct(worst));
        }
        if (s.checkpoints_s.size() > 1)
          fmt::print(" {:>14}", pct(error_percent(param(runs[0].at[0][side], i), truth)));
        fmt::print("\n");
      }
    }
    if (s.noise_variance > 0) {
      std::string counts;
      for (const auto& r : runs) counts += fmt::format(" {:.1f}", r.outside_per_1000);
      fmt::print("samples with |y - y_sim| > 3 sigma per 1000 over {}-{} s (seeds {}-{}):{}  (thesis: 12)\n",
                 format_double(s.outside_t0_s), format_double(s.outside_t1_s), s.seeds.front(), s.seeds.back(), counts);
    }
    fmt::print("NRMSE of the free-run model over {}-{} s (seed {}): {:.5f}\n", format_double(s.nrmse_t0_s),
               format_double(s.nrmse_t1_s), s.seeds.front(), runs[0].nrmse);
  }
}

/// E2 with the thesis's settings, with consistent filtering, and lash's: worst error over the seeds.
void e2_comparison(const std::string& dir) {
  fmt::print("\nE2, worst error % over seeds 1-5 at 200 s, by method      a1       b1        c        d\n");
  const std::pair<const char*, const char*> rows[] = {
      {"e2_thesis.toml", "thesis: 4 RLS, lambda 0.99, MA20 on y"},
      {"e2_consistent.toml", "4 RLS, lambda 0.999, same MA20 on v and y"},
      {"e2.toml", "lash: pooled IV, lambda 1, same MA40 on v and y"}};
  for (const auto& [file, label] : rows) {
    const ScenarioSpec s = load_scenario(dir + "/" + file);
    double worst[4] = {0, 0, 0, 0};
    int unidentified = 0;  // sides not identified at 200 s (implausible c or d < 0): left out of the worst
    for (auto seed : s.seeds) {
      const ScenarioRun r = run_scenario(s, seed);
      for (Side side : {Side::right, Side::left}) {
        if (!r.at.back()[side].identified) {
          ++unidentified;
          continue;
        }
        for (int i = 0; i < 4; ++i)
          worst[i] = std::max(worst[i], error_percent(param(r.at.back()[side], i), param(s.truth[side], i)));
      }
    }
    fmt::print("  {:<54} {:>8} {:>8} {:>8} {:>8}", label, pct(worst[0]), pct(worst[1]), pct(worst[2]), pct(worst[3]));
    if (unidentified > 0)
      fmt::print("  ({} of {} sides not identified)", unidentified, 2 * s.seeds.size());
    fmt::print("\n");
  }
  fmt::print("  {:<54} {:>8} {:>8} {:>8} {:>8}\n", "thesis's reported envelope", "1", "15", "~1", "50");
  fmt::print("  {:<54} {:>8} {:>8} {:>8} {:>8}\n", "goal of lash", "", "3", "", "10");
}

struct DemoOptions {
  std::string out_dir = "demo-out";
};

int run(const DemoOptions& o) {
  std::filesystem::create_directories(o.out_dir);
  const std::string plant_file = source_dir() + "/config/plants/thesis_eq34.toml";
  Plant plant = load_plant(plant_file);
  SimulationSpec spec;
  spec.input.kind = Waveform::sine;
  spec.input.amplitude = 600.0;
  spec.input.frequency_rad_s = 1.0;
  spec.duration_s = 20.0;
  SimulationTrace tr = simulate(plant, spec);
  const std::string csv = o.out_dir + "/eq34.csv";
  const std::string png = o.out_dir + "/eq34.png";
  std::vector<const std::vector<double>*> cols;
  for (const auto& c : tr.cols) cols.push_back(&c);
  write_columns_csv(csv, tr.names, cols);
  plot_csv(csv, png, "Thesis eq. (34) plant: DZ(-300, 200) -> G_r/G_l -> DB(30/50), v = 600 sin(t)",
           {{"input v", "t [s]"}, {"signals", "t [s]"}},
           {{"t", "v", "v (input)", 0},
            {"t", "x1_deadzone", "u (deadzone out)", 1},
            {"t", "x2_linear", "w (linear out)", 1},
            {"t", "y", "y (deadband out)", 1}});

  fmt::print("lash demo — simulation of the thesis's eq. (34) plant (E1), v = 600 sin(t), T = {} s\n",
             format_double(plant.dt_s()));
  fmt::print("{:>8} {:>10} {:>12} {:>12} {:>12}\n", "t [s]", "v", "u=DZ(v)", "w=G(u)", "y=DB(w)");
  const auto& t = tr.col("t");
  for (std::size_t k = 0; k < tr.samples(); k += 400)
    fmt::print("{:8.2f} {:10.3f} {:12.4f} {:12.4f} {:12.4f}\n", t[k], tr.col("v")[k], tr.col("x1_deadzone")[k],
               tr.col("x2_linear")[k], tr.col("y")[k]);
  fmt::print("wrote {} and {}\n", csv, png);
  demo_e3_campaign(o.out_dir);
  identification_tables(source_dir() + "/config/scenarios");
  e2_comparison(source_dir() + "/config/scenarios");
  return kExitOk;
}

}  // namespace

Command add_demo(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  auto* sub = app.add_subcommand("demo", "Run the main demonstration (what `make demo` shows)");
  sub->add_option("--out-dir", o->out_dir, "Where CSV and PNG files go");
  return {sub, [o] { return run(*o); }};
}

}  // namespace lash::cli
