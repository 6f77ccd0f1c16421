// lash estimate: run one of the switching estimators of docs/method.md §A4 over a recorded t,v,y file.
#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>


#include <fmt/core.h>

#include "cli_common.hpp"
#include "column_cursor.hpp"
#include "csv_stream.hpp"
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

/// Rows of a record `lash estimate` holds in memory; a longer record is read into a temporary
/// file and estimated from there in chunks (docs/memory.md). LASH_SPILL_ROWS overrides it.
std::size_t spill_after_rows() {
  constexpr std::size_t kDefault = std::size_t{1} << 16;  // 1.5 MiB of t, v, y
  const char* env = std::getenv("LASH_SPILL_ROWS");
  if (!env || !*env) return kDefault;
  char* end = nullptr;
  errno = 0;
  const unsigned long long n = std::strtoull(env, &end, 10);
  if (errno != 0 || *end != '\0' || n == 0 || env[0] == '-')
    throw InputError("", 0, "LASH_SPILL_ROWS", std::string("expected a positive number of rows, got '") +
                                                   std::string(env).substr(0, 40) + "'");
  return static_cast<std::size_t>(n);
}

/// The trace (t, y, ŷ, y_sim and every parameter per step) written to a CSV as the final run goes:
/// nothing per sample is kept in memory. Remembers which parameters never had a finite value.
class TraceWriter {
 public:
  TraceWriter(const std::string& path, std::vector<std::string> names, const ColumnStore& store)
      : csv_(path, names), t_(store, 0), row_(names.size()), finite_(names.size() - 4, false) {}
  void operator()(const TraceRow& r) {
    row_[0] = t_.at(r.k);
    row_[1] = r.y;
    row_[2] = r.yhat;
    row_[3] = r.ysim;
    for (std::size_t p = 0; p < r.params.size() && p + 4 < row_.size(); ++p) {
      row_[p + 4] = r.params[p];
      if (std::isfinite(r.params[p])) finite_[p] = true;
    }
    csv_.row(row_);
  }
  void commit() { csv_.commit(); }
  bool ever_finite(std::size_t p) const { return finite_[p]; }

 private:
  CsvStream csv_;
  ColumnCursor t_;  ///< t, read along with the run's rows
  std::vector<double> row_;
  std::vector<bool> finite_;
};

int run(const CLI::App& sub, const EstimateOptions& o) {
  const SettingsSources src = settings_sources(sub, o);
  // settings are checked before the data is read, so a bad option never costs a file scan
  const EstimationJob job = resolve_settings(src).job;
  const std::size_t spill_rows = spill_after_rows();
  const Record rec = load_record(o.data, job.columns, o.strict, spill_rows);
  const RecordColumns cols = rec.columns();
  const double t_last = cols.store.back(0);
  if (src.nrmse_window_s && job.nrmse_t0_s >= t_last)
    throw InputError(o.data, 0, "--nrmse-window",
                     "T0 = " + format_double(job.nrmse_t0_s) + " s is not before the record's end (" +
                         format_double(t_last) + " s)");
  ArrayEstimateOptions eo;
  eo.trace = false;    // the trace is streamed to its file (TraceWriter), never held
  eo.outputs = false;  // ŷ and y_sim per sample: in the streamed trace (the NRMSE is summed in the run)
  eo.outlier_gate = o.outlier_gate;
  eo.sampling = &rec.sampling;
  eo.rows_skipped = rec.skipped_rows();
  eo.first_skipped_line = rec.data.first_skipped_line;
  // The trace file: -o, or (for --plot alone) one in a fresh private directory (mkdtemp). A trace
  // that cannot be opened does not stop the estimate: the result is printed first, the error after.
  std::optional<PrivateTempDir> tmp;
  std::optional<TraceWriter> trace;
  std::optional<InputError> trace_error;
  std::string csv = o.out;
  if (!o.out.empty() || !o.plot.empty()) {
    try {
      if (csv.empty()) {
        tmp.emplace(o.plot, "--plot");
        csv = (tmp->path() / "trace.csv").string();
      }
      std::vector<std::string> names{"t", "y", "yhat", "y_sim"};
      for (const auto& n : param_names(model_traits(resolve_settings(src).cfg.model))) names.push_back(n);
      trace.emplace(csv, std::move(names), cols.store);
      eo.on_step = [&trace](const TraceRow& r) { (*trace)(r); };
    } catch (const InputError& e) {
      trace_error = e;
    }
  }
  const ArrayEstimate e = estimate_record(src, cols, eo);
  const EstimationRun& run = e.run.run;
  if (o.timing)
    fmt::print(stderr, "lash estimate: estimator ran {} samples in {} s ({:.3g} M samples/s; CPU time {} s)\n",
               rec.rows(), format_double(e.estimator_s), static_cast<double>(rec.rows()) / e.estimator_s * 1e-6,
               format_double(e.estimator_cpu_s));
  if (o.print_config) {
    fmt::print("{}", config_to_toml(e.run.settings, &e.job));
    return kExitOk;
  }
  // the result first: a failing -o or --plot never hides it
  if (o.json)
    fmt::print("{}\n", e.json);
  else
    fmt::print("{}", estimate_auto_text(e.run, e.result.dt_s, e.fit, e.traits ? &*e.traits : nullptr));
  std::fflush(stdout);
  if (trace_error) throw *trace_error;
  if (!trace) return kExitOk;
  trace->commit();
  if (!o.plot.empty()) {
    std::set<std::string> empty;  // columns without a finite value: a side never identified
    for (std::size_t p = 0; p < run.param_names.size(); ++p)
      if (!trace->ever_finite(p)) empty.insert(run.param_names[p]);
    plot_estimate(csv, o.plot,
                  fmt::format("lash estimate --model {} {}", to_string(e.run.cfg.model),
                              std::filesystem::path(o.data).filename().string()),
                  run.param_names, t_last, ci95_columns(run.report), empty);
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
