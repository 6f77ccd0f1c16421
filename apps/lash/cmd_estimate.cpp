// lash estimate: run one of the switching estimators of docs/method.md §A4 over a recorded t,v,y file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>


#include <fmt/core.h>

#include "cli_common.hpp"
#include "estimate_plot.hpp"
#include "estimate_settings.hpp"
#include "plot.hpp"
#include "lash/identify/any_estimator.hpp"
#include "lash/identify/auto.hpp"
#include "lash/identify/estimate.hpp"
#include "lash/identify/estimate_report.hpp"
#include "lash/identify/data.hpp"

namespace lash::cli {
namespace {

/// The final 95 % intervals by trace column name ("a1_r", "c_l", "d", …) for the plot's bands.
std::map<std::string, std::pair<double, double>> ci95_columns(const EstimateReport& r) {
  std::map<std::string, std::pair<double, double>> m;
  const auto put = [&](const std::string& name, const Interval& iv) {
    if (iv.valid()) m[name] = {iv.lo, iv.hi};
  };
  if (r.model == ModelKind::linear) {
    put("a1", r.right.ci95.a1);
    put("b1", r.right.ci95.b1);
    return m;
  }
  for (const auto& [sfx, s] : {std::pair{"_r", &r.right}, std::pair{"_l", &r.left}}) {
    put(std::string("a1") + sfx, s->ci95.a1);
    put(std::string("b1") + sfx, s->ci95.b1);
    put(std::string("c") + sfx, s->ci95.c);
    put(std::string("d") + sfx, s->ci95.d);
  }
  return m;
}

int run(const CLI::App& sub, const EstimateOptions& o) {
  const SettingsSources src = settings_sources(sub, o);
  // settings are checked before the data is read, so a bad option never costs a file scan
  const EstimationJob job = resolve_settings(src).job;
  const Record rec = load_record(o.data, job.columns, o.strict);
  if (src.nrmse_window_s && !rec.t().empty() && job.nrmse_t0_s >= rec.t().back())
    throw InputError(o.data, 0, "--nrmse-window",
                     "T0 = " + format_double(job.nrmse_t0_s) + " s is not before the record's end (" +
                         format_double(rec.t().back()) + " s)");
  ArrayEstimateOptions eo;
  eo.trace = !o.out.empty() || !o.plot.empty();
  eo.outputs = eo.trace;  // ŷ and y_sim per sample only for the trace (the NRMSE is summed in the run)
  eo.outlier_gate = o.outlier_gate;
  eo.sampling = &rec.sampling;
  eo.rows_skipped = rec.skipped_rows();
  eo.first_skipped_line = rec.data.first_skipped_line;
  const ArrayEstimate e = estimate_arrays(src, rec.t(), rec.v(), rec.y(), eo);
  const EstimationRun& run = e.run.run;
  if (o.timing)
    fmt::print(stderr, "lash estimate: estimator ran {} samples in {} s ({:.3g} M samples/s; CPU time {} s)\n",
               rec.v().size(), format_double(e.estimator_s), static_cast<double>(rec.v().size()) / e.estimator_s * 1e-6,
               format_double(e.estimator_cpu_s));
  const auto& t = rec.t();
  if (o.print_config) {
    fmt::print("{}", config_to_toml(e.run.cfg, &e.job));
    return kExitOk;
  }
  // the result first: a failing -o or --plot never hides it
  if (o.json)
    fmt::print("{}\n", e.json);
  else
    fmt::print("{}", estimate_auto_text(e.run, e.result.dt_s, e.fit));
  std::fflush(stdout);
  // the trace: t, y, yhat, y_sim and every parameter per step
  std::vector<std::string> names{"t", "y", "yhat", "y_sim"};
  std::vector<const std::vector<double>*> cols{&t, &rec.y(), &run.yhat, &run.ysim};
  for (std::size_t p = 0; p < run.param_names.size(); ++p) {
    names.push_back(run.param_names[p]);
    cols.push_back(&run.params[p]);
  }
  if (!o.out.empty()) write_columns_csv(o.out, names, cols);
  if (!o.plot.empty()) {
    std::set<std::string> empty;  // columns without a finite value: a side never identified
    for (std::size_t p = 0; p < run.param_names.size(); ++p)
      if (std::none_of(run.params[p].begin(), run.params[p].end(), [](double x) { return std::isfinite(x); }))
        empty.insert(run.param_names[p]);
    std::string csv = o.out;
    std::optional<PrivateTempDir> tmp;  // without -o: the trace in a fresh private directory (mkdtemp)
    if (csv.empty()) {
      tmp.emplace(o.plot, "--plot");
      csv = (tmp->path() / "trace.csv").string();
      write_columns_csv(csv, names, cols);
    }
    plot_estimate(csv, o.plot,
                  fmt::format("lash estimate --model {} {}", to_string(e.run.cfg.model),
                              std::filesystem::path(o.data).filename().string()),
                  run.param_names, t.back(), ci95_columns(run.report), empty);
  }

  return kExitOk;
}

}  // namespace

Command add_estimate(CLI::App& app) {
  auto o = std::make_shared<EstimateOptions>();
  auto* sub = app.add_subcommand("estimate", "Identify a model online (switching RLS, docs/method.md §A4) from a t,v,y record");
  sub->add_option("data", o->data, "Record with a header line and columns t, v, y (CSV)")->required();
  sub->add_option("--model", o->model,
                  "linear | input-deadzone | output-deadzone | deadzone-deadband | coupled-carts");
  sub->add_option("--config", o->config, "Estimator settings (TOML, see docs/identification.md)");
  add_setting_options(*sub, *o);  // --lambda, --method, --pooled, … from the field table (config_fields.hpp)
  sub->add_option("--columns", o->columns, "The t,v,y columns by name or 0-based index, comma-separated (default t,v,y)");
  sub->add_flag("--strict", o->strict, "A row with a non-finite value (nan, inf, empty) is an error instead of skipped");
  sub->add_option("--nrmse-window", o->nrmse_window, "NRMSE window T0 T1 [s] (default 7.5 to the end)")
      ->expected(2);
  sub->add_option("-o,--output", o->out, "Trace CSV: t, y, yhat, y_sim and every parameter per step");
  sub->add_option("--plot", o->plot, "PNG of parameter convergence and measured vs simulated output");
  sub->add_option("--preset", o->preset, "lash (default: lash's best settings, tuned to the data) | thesis");
  sub->add_flag("--print-config", o->print_config,
                "Print the settings actually used (TOML, readable by --config) instead of the result");
  sub->add_option("--outlier-gate", o->outlier_gate,
                  "Replace isolated outliers of y beyond this many innovation scales (0 = off; default 12)");
  sub->add_flag("--json", o->json, "Print exactly one JSON object with the result on stdout");
  sub->add_flag("--timing", o->timing, "Print the estimator's own run time on stderr (settings from the data, guess search, final run; not the reading nor the intervals)");
  // a later option overrides an earlier one (handy for wrappers that append settings)
  for (auto* opt : sub->get_options())
    if (opt->get_expected_max() == 1 && opt->get_name() != "--nrmse-window")
      opt->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  return {sub, [o, sub] { return run(*sub, *o); }};
}

}  // namespace lash::cli
