// lash estimate: run one of the switching estimators of SPEC A4 over a recorded t,v,y file.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>

#include <unistd.h>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "plot.hpp"
#include "lash/identify/any_estimator.hpp"
#include "lash/identify/estimate_report.hpp"
#include "lash/identify/config_file.hpp"
#include "lash/identify/data.hpp"

namespace lash::cli {
namespace {

struct EstimateOptions {
  std::string data;
  std::string model;
  std::string config;
  std::optional<double> guess_left, guess_right, lambda, p0, derivative_threshold;
  std::optional<std::size_t> filter_length, derivative_filter_length, derivative_prefilter_length, input_delay,
      align_delay, direction_run, min_updates, iv_delay;
  std::optional<std::string> method, forgetting;
  bool filter_input = false, pooled = false;
  std::optional<double> accel_limit, stage2_start, zero_threshold;
  std::string columns;
  std::vector<double> nrmse_window;
  std::string out;
  std::string plot;
  bool json = false;
  bool strict = false;
  bool timing = false;
};

std::vector<std::string> split_names(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto end = text.find(',', start);
    out.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  for (const auto& n : out)
    if (n.empty()) throw InputError("", 0, "--columns", "empty column name in '" + text + "'");
  if (out.size() != 3) throw InputError("", 0, "--columns", "expected three names t,v,y, got '" + text + "'");
  return out;
}

int run(const EstimateOptions& o) {
  EstimatorConfig cfg;
  EstimationJob job;
  if (!o.config.empty()) {
    const toml::table root = parse_toml_file(o.config);
    TomlTable t(root, o.config);
    read_estimator_config(t, cfg, &job);
  }
  if (!o.model.empty()) {
    try {
      cfg.model = parse_model_kind(o.model);
    } catch (const std::invalid_argument& e) {
      throw InputError("", 0, "--model", e.what());
    }
  } else if (o.config.empty()) {
    throw InputError("", 0, "--model", "give --model (or a --config with model = ...)");
  }
  if (o.guess_left) cfg.guess_left = *o.guess_left;
  if (o.guess_right) cfg.guess_right = *o.guess_right;
  if (o.lambda) cfg.rls.lambda = *o.lambda;
  if (o.p0) cfg.rls.p0 = *o.p0;
  if (o.filter_length) cfg.noise.filter_length = *o.filter_length;
  if (o.filter_input) cfg.noise.filter_input = true;
  if (o.derivative_filter_length) cfg.noise.derivative_filter_length = *o.derivative_filter_length;
  if (o.derivative_prefilter_length) cfg.noise.derivative_prefilter_length = *o.derivative_prefilter_length;
  if (o.derivative_threshold) cfg.noise.derivative_threshold = *o.derivative_threshold;
  if (o.input_delay) cfg.noise.input_delay = *o.input_delay;
  if (o.align_delay) cfg.noise.align_delay = *o.align_delay;
  if (o.direction_run) cfg.direction_run = static_cast<std::uint32_t>(*o.direction_run);
  if (o.min_updates) cfg.min_updates = *o.min_updates;
  if (o.iv_delay) cfg.iv_delay = *o.iv_delay;
  if (o.pooled) cfg.pooled = true;
  if (o.accel_limit) cfg.accel_limit = *o.accel_limit;
  if (o.stage2_start) cfg.stage2_start_s = *o.stage2_start;
  if (o.zero_threshold) cfg.zero_threshold = *o.zero_threshold;
  if (o.method) {
    try {
      cfg.method = parse_method(*o.method);
    } catch (const std::invalid_argument& e) {
      throw InputError("", 0, "--method", e.what());
    }
  }
  if (o.forgetting) {
    if (*o.forgetting == "exponential") cfg.rls.forgetting = Forgetting::exponential;
    else if (*o.forgetting == "directional") cfg.rls.forgetting = Forgetting::directional;
    else throw InputError("", 0, "--forgetting", "expected exponential or directional");
  }
  if (!o.columns.empty()) job.columns = split_names(o.columns);
  if (!o.nrmse_window.empty()) {
    if (o.nrmse_window.size() != 2 || !(o.nrmse_window[0] < o.nrmse_window[1]))
      throw InputError("", 0, "--nrmse-window", "expected T0 T1 with T0 < T1 [s]");
    job.nrmse_t0_s = o.nrmse_window[0];
    job.nrmse_t1_s = o.nrmse_window[1];
  }
  // settings are checked before the data is read, so a bad option never costs a file scan
  cfg.dt_s = 1.0;
  try {
    cfg.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(o.config, 0, "", e.what());
  }

  const Record rec = load_record(o.data, job.columns, o.strict);
  cfg.dt_s = rec.dt_s;
  cfg.fit_start_s = job.nrmse_t0_s;  // the verdict's fit window starts where the reported NRMSE's does
  const bool keep = !o.out.empty() || !o.plot.empty();
  const auto t_start = std::chrono::steady_clock::now();
  EstimationRun run = run_estimator(cfg, rec.v(), rec.y(), keep);
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  if (o.timing)
    fmt::print(stderr, "lash estimate: estimator ran {} samples in {} s ({:.3g} M samples/s)\n", rec.v().size(),
               format_double(elapsed_s), static_cast<double>(rec.v().size()) / elapsed_s * 1e-6);
  add_intervals(run, cfg, rec.v(), rec.y());
  const auto& t = rec.t();
  const double t1 = job.nrmse_t1_s < 0 ? t.back() : job.nrmse_t1_s;
  const double fit = nrmse(t, rec.y(), run.ysim, job.nrmse_t0_s, t1);

  if (!o.out.empty()) {
    std::vector<std::string> names{"t", "y", "yhat", "y_sim"};
    std::vector<const std::vector<double>*> cols{&t, &rec.y(), &run.yhat, &run.ysim};
    for (std::size_t p = 0; p < run.param_names.size(); ++p) {
      names.push_back(run.param_names[p]);
      cols.push_back(&run.params[p]);
    }
    write_columns_csv(o.out, names, cols);
  }
  if (!o.plot.empty()) {
    std::string csv = o.out;
    std::filesystem::path tmp;
    if (csv.empty()) {
      tmp = std::filesystem::temp_directory_path() / ("lash-estimate-" + std::to_string(::getpid()) + ".csv");
      csv = tmp.string();
      std::vector<std::string> names{"t", "y", "yhat", "y_sim"};
      std::vector<const std::vector<double>*> cols{&t, &rec.y(), &run.yhat, &run.ysim};
      for (std::size_t p = 0; p < run.param_names.size(); ++p) {
        names.push_back(run.param_names[p]);
        cols.push_back(&run.params[p]);
      }
      write_columns_csv(csv, names, cols);
    }
    std::vector<PlotPanel> panels{{"output", "t [s]"}, {"a1, b1", "t [s]"}};
    std::vector<PlotSeries> series{{"t", "y", "y measured", 0}, {"t", "y_sim", "y simulated", 0}};
    bool cd_panel = false;
    for (const auto& n : run.param_names) {
      const bool lin = n.rfind("a1", 0) == 0 || n.rfind("b1", 0) == 0;
      if (!lin) cd_panel = true;
      series.push_back({"t", n, n, lin ? 1 : 2});
    }
    if (cd_panel) panels.push_back({"c, d", "t [s]"});
    try {
      plot_csv(csv, o.plot, fmt::format("lash estimate --model {} {}", to_string(cfg.model),
                                        std::filesystem::path(o.data).filename().string()),
               panels, series);
    } catch (...) {
      if (!tmp.empty()) std::filesystem::remove(tmp);
      throw;
    }
    if (!tmp.empty()) std::filesystem::remove(tmp);
  }

  const ReportFit rf{fit, job.nrmse_t0_s, t1, rec.skipped_rows(), rec.data.first_skipped_line, rec.gap_rows().size(),
                     rec.sampling.median_dt};
  if (o.json) fmt::print("{}\n", estimate_json(run.report, rf));
  else fmt::print("{}", estimate_text(run.report, rec.dt_s, rf));
  return kExitOk;
}

}  // namespace

Command add_estimate(CLI::App& app) {
  auto o = std::make_shared<EstimateOptions>();
  auto* sub = app.add_subcommand("estimate", "Identify a model online (switching RLS, SPEC A4) from a t,v,y record");
  sub->add_option("data", o->data, "Record with a header line and columns t, v, y (CSV)")->required();
  sub->add_option("--model", o->model,
                  "linear | input-deadzone | output-deadzone | deadzone-deadband | coupled-carts");
  sub->add_option("--config", o->config, "Estimator settings (TOML, see docs/identification.md)");
  sub->add_option("--guess-left", o->guess_left, "c_l*: switching guess below the deadzone [v unit]");
  sub->add_option("--guess-right", o->guess_right, "c_r*: switching guess above the deadzone [v unit]");
  sub->add_option("--lambda", o->lambda, "Forgetting factor in (0, 1] (thesis: 0.99)");
  sub->add_option("--p0", o->p0, "Initial covariance P0 = p0 I (thesis: 1000)");
  sub->add_option("--forgetting", o->forgetting, "exponential (eq. 15, trace-bounded) | directional");
  sub->add_option("--method", o->method, "ls (RLS, thesis) | iv (recursive instrumental variables)");
  sub->add_flag("--pooled", o->pooled, "deadzone-deadband: one 4-parameter RLS per side (a1, b1 shared by + and -)");
  sub->add_option("--filter-length", o->filter_length, "Moving average on y [samples] (1 = off)");
  sub->add_flag("--filter-input", o->filter_input, "Pass v through the same moving average as y");
  sub->add_option("--input-delay", o->input_delay, "Delay of v [samples] to keep it aligned with a filtered y");
  sub->add_option("--derivative-prefilter-length", o->derivative_prefilter_length,
                  "Moving average on y before differencing [samples] (0 = --filter-length)");
  sub->add_option("--derivative-filter-length", o->derivative_filter_length,
                  "Moving average on the derivative of y [samples]");
  sub->add_option("--derivative-threshold", o->derivative_threshold,
                  "|dy/dt| at or below this counts as not moving [y unit/s]");
  sub->add_option("--align-delay", o->align_delay, "Delay of the regression signals to line up with dy/dt [samples]");
  sub->add_option("--direction-run", o->direction_run, "Samples the direction must hold before a key updates (>= 2)");
  sub->add_option("--min-updates", o->min_updates, "Updates a key needs before its side counts as identified");
  sub->add_option("--iv-delay", o->iv_delay, "iv: instrument = y delayed this many more samples");
  sub->add_option("--accel-limit", o->accel_limit, "coupled-carts: max |acceleration| for stage 1 [y unit/s^2]");
  sub->add_option("--stage2-start", o->stage2_start, "coupled-carts: start of the deadband estimation [s]");
  sub->add_option("--zero-threshold", o->zero_threshold, "output-deadzone: |y| at or below this counts as 0");
  sub->add_option("--columns", o->columns, "The t,v,y columns by name or 0-based index, comma-separated (default t,v,y)");
  sub->add_flag("--strict", o->strict, "A row with a non-finite value (nan, inf, empty) is an error instead of skipped");
  sub->add_option("--nrmse-window", o->nrmse_window, "NRMSE window T0 T1 [s] (default 7.5 to the end)")
      ->expected(2);
  sub->add_option("-o,--output", o->out, "Trace CSV: t, y, yhat, y_sim and every parameter per step");
  sub->add_option("--plot", o->plot, "PNG of parameter convergence and measured vs simulated output");
  sub->add_flag("--json", o->json, "Print exactly one JSON object with the result on stdout");
  sub->add_flag("--timing", o->timing, "Print the estimator's own run time (without file I/O) on stderr");
  // a later option overrides an earlier one (handy for wrappers that append settings)
  for (auto* opt : sub->get_options())
    if (opt->get_expected_max() == 1 && opt->get_name() != "--nrmse-window")
      opt->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  return {sub, [o] { return run(*o); }};
}

}  // namespace lash::cli
