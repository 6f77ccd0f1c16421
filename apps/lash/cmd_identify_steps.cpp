// lash identify-steps: the offline step-test fit of docs/method.md §B6 (bias, deadzone, gain, τ, σ) of open-loop
// stepped-current pilot-valve data.
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "plot.hpp"
#include "lash/io/atomic_file.hpp"
#include "lash/identify/step_fit.hpp"

namespace lash::cli {
namespace {

struct Options {
  std::string data;
  std::string t_col = "t", i_col = "current_mA", p_col = "pressure_kPa";
  double settle_taus = 8.0;
  double tolerance = 0.5;
  bool json = false;
  std::string plot;
};

int run(const Options& o) {
  // Options before any work.
  if (!(o.settle_taus > 0 && o.settle_taus <= 100))
    throw InputError("", 0, "--settle-taus", "must be in (0, 100] [time constants]");
  if (!(o.tolerance > 0 && o.tolerance <= 1e4))
    throw InputError("", 0, "--current-tolerance", "must be in (0, 10000] [mA]");
  if (!o.plot.empty()) check_output_path(o.plot, "--plot");
  const Table tab = read_csv(o.data);
  const auto& t = tab[o.t_col];
  const auto& cur = tab[o.i_col];
  const auto& p = tab[o.p_col];
  require_increasing(tab, o.t_col);
  StepFitOptions so;
  so.settle_taus = o.settle_taus;
  so.current_tolerance_mA = o.tolerance;
  StepFit f;
  try {
    f = fit_steps(t, cur, p, so);
  } catch (const std::invalid_argument& e) {
    throw InputError(o.data, 0, o.p_col, e.what());
  }
  if (o.json) {
    nlohmann::json j{{"bias_kPa", f.bias_kPa},
                     {"deadzone_mA", f.deadzone_mA},
                     {"gain_kPa_per_mA", f.gain_kPa_per_mA},
                     {"tau_s", f.tau_s},
                     {"noise_sigma_kPa", f.noise_sigma_kPa},
                     {"segments", f.segments.size()},
                     {"line_points", f.line_points},
                     {"transients", f.transients}};
    fmt::print("{}\n", j.dump());
  } else {
    fmt::print("{:>10} {:>10} {:>12} {:>10} {:>6} {:>6}\n", "t0 [s]", "i [mA]", "p ss [kPa]", "sd [kPa]", "line",
               "tau");
    for (const auto& s : f.segments)
      fmt::print("{:>10.3f} {:>10.2f} {:>12.2f} {:>10.3f} {:>6} {:>6}\n", t[s.begin], s.current_mA, s.mean_kPa,
                 s.std_kPa, s.on_line ? "yes" : "", s.transient_used ? "yes" : "");
    fmt::print("bias        {:>12.4f} kPa\n", f.bias_kPa);
    fmt::print("deadzone    {:>12.4f} mA   (x-intercept, {} points)\n", f.deadzone_mA, f.line_points);
    fmt::print("gain        {:>12.5f} kPa/mA (slope)\n", f.gain_kPa_per_mA);
    fmt::print("tau         {:>12.5f} s    ({} transients)\n", f.tau_s, f.transients);
    fmt::print("noise sigma {:>12.4f} kPa\n", f.noise_sigma_kPa);
  }
  if (!o.plot.empty()) {
    std::string steady = "$steady << EOD\n";
    for (const auto& s : f.segments)
      if (s.end - s.steady_begin >= so.min_steady_samples)
        steady += format_double(s.current_mA) + " " + format_double(s.mean_kPa - f.bias_kPa) + "\n";
    steady += "EOD\n";
    const std::string script = steady + fmt::format(
        "set terminal pngcairo size 1000,900\nset output '<OUTPUT>'\nset datafile separator ','\n"
        "set multiplot layout 2,1 title 'lash identify-steps (thesis Fig 2.8 / 2.9 analogues)'\n"
        "set xlabel 't [s]'\nset ylabel 'pressure [kPa]'\nset y2label 'current [mA]'\nset y2tics\n"
        "plot '{0}' using (column('{1}')):(column('{3}')) with lines title 'pressure', "
        "'{0}' using (column('{1}')):(column('{2}')) axes x1y2 with lines title 'current'\n"
        "unset y2tics\nunset y2label\nset datafile separator whitespace\n"
        "set xlabel 'current [mA]'\nset ylabel 'steady pressure - bias [kPa]'\n"
        "plot $steady using 1:2 with points pt 7 title 'steady segments', "
        "({4})*(x-({5})) title 'fit: gain {4:.4g} kPa/mA, deadzone {5:.4g} mA'\nunset multiplot\n",
        o.data, o.t_col, o.i_col, o.p_col, f.gain_kPa_per_mA, f.deadzone_mA);
    run_gnuplot(script, o.plot);
  }
  return kExitOk;
}

}  // namespace

Command add_identify_steps(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* sub = app.add_subcommand("identify-steps",
                                 "Fit bias, deadzone, gain, time constant and noise to stepped-current data (docs/method.md §B6)");
  sub->add_option("data", o->data, "CSV with time, current and pressure columns")->required();
  sub->add_option("--time-column", o->t_col, "Time column [s]");
  sub->add_option("--current-column", o->i_col, "Current column [mA]");
  sub->add_option("--pressure-column", o->p_col, "Pressure column [kPa]");
  sub->option_defaults()->always_capture_default();
  sub->add_option("--settle-taus", o->settle_taus, "Steady part starts this many tau after a step, (0, 100]");
  sub->add_option("--current-tolerance", o->tolerance, "Current change that starts a new segment [mA], (0, 10000]");
  sub->add_flag("--json", o->json, "Print one JSON object");
  sub->add_option("--plot", o->plot, "Render time history and steady pressure vs current to a PNG");
  return {sub, [o] { return run(*o); }};
}

}  // namespace lash::cli
