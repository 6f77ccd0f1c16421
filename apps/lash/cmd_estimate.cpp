// lash estimate: run one of the switching estimators of SPEC A4 over a recorded t,v,y file.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>

#include <unistd.h>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "estimate_plot.hpp"
#include "estimate_settings.hpp"
#include "lash/identify/any_estimator.hpp"
#include "lash/identify/auto.hpp"
#include "lash/identify/estimate_report.hpp"
#include "lash/identify/config_file.hpp"
#include "lash/identify/data.hpp"

namespace lash::cli {
namespace {

nlohmann::ordered_json num(double x) { return std::isfinite(x) ? nlohmann::ordered_json(x) : nlohmann::ordered_json(); }

/// What estimate_auto adds to a side: the guess it used, and wrong_guess when it lay inside the deadzone.
void put_guess(nlohmann::ordered_json& j, const GuessReport& g) {
  if (g.source == GuessSource::unused) return;
  if (g.wrong_side) j["reason"] = "wrong_guess";
  j["guess"] = {{"value", num(g.guess)}, {"source", to_string(g.source)}, {"edge_seen", num(g.edge)}};
}

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

int run(const EstimateOptions& o) {
  Preset preset{};
  try {
    preset = parse_preset(o.preset);
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, "--preset", e.what());
  }
  ModelKind model{};
  if (!o.model.empty()) {
    try {
      model = parse_model_kind(o.model);
    } catch (const std::invalid_argument& e) {
      throw InputError("", 0, "--model", e.what());
    }
  } else if (!o.config.empty()) {
    EstimatorConfig probe;
    EstimationJob j;
    const toml::table root = parse_toml_file(o.config);
    TomlTable t(root, o.config);
    (void)t.string_opt("preset");
    read_estimator_config(t, probe, &j);
    model = probe.model;
  } else {
    throw InputError("", 0, "--model", "give --model (or a --config with model = ...)");
  }
  // an option the model does not read is refused, never ignored
  for (const auto& name : o.given)
    if (!model_uses(model, name))
      throw InputError("", 0, "--" + name, std::string("model ") + to_string(model) + " does not use this option");
  // settings are checked before the data is read, so a bad option never costs a file scan
  EstimationJob job;
  (void)assemble(o, model, preset, nullptr, job);

  const Record rec = load_record(o.data, job.columns, o.strict);
  if (!o.nrmse_window.empty() && !rec.t().empty() && job.nrmse_t0_s >= rec.t().back())
    throw InputError(o.data, 0, "--nrmse-window",
                     "T0 = " + format_double(job.nrmse_t0_s) + " s is not before the record's end (" +
                         format_double(rec.t().back()) + " s)");
  EstimatorConfig cfg = assemble(o, model, preset, &rec, job);
  cfg.fit_start_s = job.nrmse_t0_s;  // the verdict's fit window starts where the reported NRMSE's does
  const bool keep = !o.out.empty() || !o.plot.empty();
  const auto t_start = std::chrono::steady_clock::now();
  AutoRun ar = estimate_auto(cfg, rec.v(), rec.y(), keep, o.outlier_gate);
  EstimationRun& run = ar.run;
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  if (o.timing)
    fmt::print(stderr, "lash estimate: estimator ran {} samples in {} s ({:.3g} M samples/s)\n", rec.v().size(),
               format_double(elapsed_s), static_cast<double>(rec.v().size()) / elapsed_s * 1e-6);
  add_intervals(run, ar.cfg, rec.v(), rec.y());
  const auto& t = rec.t();
  const double t1 = job.nrmse_t1_s < 0 ? t.back() : job.nrmse_t1_s;
  const double fit = nrmse(t, rec.y(), run.ysim, job.nrmse_t0_s, t1);

  if (o.print_config) {
    fmt::print("{}", config_to_toml(ar.cfg));
    return kExitOk;
  }
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
    try {
      plot_estimate(csv, o.plot,
                    fmt::format("lash estimate --model {} {}", to_string(cfg.model),
                                std::filesystem::path(o.data).filename().string()),
                    run.param_names, t.back(), ci95_columns(run.report));
    } catch (...) {
      if (!tmp.empty()) std::filesystem::remove(tmp);
      throw;
    }
    if (!tmp.empty()) std::filesystem::remove(tmp);
  }

  const ReportFit rf{fit, job.nrmse_t0_s, t1, rec.skipped_rows(), rec.data.first_skipped_line, rec.gap_rows().size(),
                     rec.sampling.median_dt};
  if (o.json) {
    auto j = nlohmann::ordered_json::parse(estimate_json(run.report, rf));
    if (j.contains("right")) put_guess(j["right"], ar.right);
    if (j.contains("left")) put_guess(j["left"], ar.left);
    j["outliers"] = ar.outliers;
    j["preset"] = to_string(preset);
    fmt::print("{}\n", j.dump());
  } else {
    fmt::print("{}", estimate_text(run.report, rec.dt_s, rf));
    for (const auto& [name, g] : {std::pair{"right", ar.right}, std::pair{"left", ar.left}}) {
      if (g.wrong_side)
        fmt::print("wrong_guess: the {} guess {:.6g} lies inside the deadzone (edge seen at {:.6g})\n", name, g.guess,
                   g.edge);
      else if (g.source != GuessSource::unused)
        fmt::print("{} guess: {:.6g} ({})\n", name, g.guess, to_string(g.source));
    }
    if (ar.outliers > 0) fmt::print("outliers: {} samples of y replaced by the outlier gate\n", ar.outliers);
  }
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
  sub->add_option("--preset", o->preset, "lash (default: lash's best settings, tuned to the data) | thesis");
  sub->add_flag("--print-config", o->print_config,
                "Print the settings actually used (TOML, readable by --config) instead of the result");
  sub->add_option("--outlier-gate", o->outlier_gate,
                  "Replace isolated outliers of y beyond this many innovation scales (0 = off; default 12)");
  sub->add_flag("--json", o->json, "Print exactly one JSON object with the result on stdout");
  sub->add_flag("--timing", o->timing, "Print the estimator's own run time (without file I/O) on stderr");
  // a later option overrides an earlier one (handy for wrappers that append settings)
  for (auto* opt : sub->get_options())
    if (opt->get_expected_max() == 1 && opt->get_name() != "--nrmse-window")
      opt->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  return {sub, [o, sub] {
            o->given.clear();
            o->preset_given = sub->get_option("--preset")->count() > 0;
            for (const char* n : {"guess-left", "guess-right", "pooled", "direction-run", "method", "iv-delay",
                                  "accel-limit", "stage2-start", "zero-threshold", "derivative-threshold",
                                  "derivative-filter-length", "derivative-prefilter-length", "align-delay"})
              if (sub->get_option(std::string("--") + n)->count() > 0) o->given.emplace_back(n);
            return run(*o);
          }};
}

}  // namespace lash::cli
