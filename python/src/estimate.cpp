// lash.estimate, lash.Estimator, lash.Result, lash.read_record: conversion only; the work is
// lash::estimate_arrays (lash.estimate) and lash::run_estimator / add_intervals / score_estimate /
// to_json (lash.Estimator), the calls `lash estimate` makes.
#include <cmath>
#include <memory>
#include <optional>

#include "convert.hpp"
#include "lash/identify/any_estimator.hpp"
#include "lash/identify/auto.hpp"
#include "lash/identify/config_sources.hpp"
#include "lash/identify/data.hpp"
#include "lash/identify/estimate.hpp"
#include "lash/identify/estimate_report.hpp"
#include "lash/identify/reguess.hpp"
#include "lash/io/error.hpp"
#include "lash/io/table.hpp"

namespace lash::py {

namespace {

/// The sources of the settings as `lash estimate` resolves them (lash::resolve_settings): the
/// preset's, those chosen from the record (preset lash, when v and y are given), then the keyword
/// arguments `tbl` as the keys of an estimator config file (docs/identification.md); a key the
/// model does not read is refused.
SettingsSources sources(const std::string& model, const std::string& preset, const toml::table& tbl) {
  SettingsSources src;
  src.model = checked("model", [&] { return parse_model_kind(model); });
  src.preset = checked("preset", [&] { return parse_preset(preset); });
  src.keys = &tbl;
  return src;
}

struct Result {
  EstimateResult res;
  std::string json;         // estimate_json: the report without what estimate_auto adds
  std::string cli_json;     // lash.estimate: what `lash estimate --json` prints (estimate_auto_json)
  pyb::object yhat = pyb::none(), ysim = pyb::none(), params = pyb::none();

  explicit Result(EstimateResult r) : res(std::move(r)), json(to_json(res)) {}
  Result(EstimateResult r, std::string cli) : res(std::move(r)), json(to_json(res)), cli_json(std::move(cli)) {}
  pyb::dict to_dict() const {
    return pyb::module_::import("json").attr("loads")(cli_json.empty() ? json : cli_json);
  }
};

class Estimator {
 public:
  Estimator(const std::string& model, double dt_s, const std::string& preset, const pyb::kwargs& settings) {
    if (!(dt_s > 0) || !std::isfinite(dt_s)) throw InputError("", 0, "dt", "must be a finite number > 0 [s]");
    // reguess=True: online re-guessing of the switching guesses (identify/reguess.hpp); not a
    // config-file key, so taken out before the settings are read
    pyb::dict rest;
    for (const auto& kv : settings) {
      if (pyb::str(kv.first).cast<std::string>() == "reguess") reguess_ = kv.second.cast<bool>();
      else rest[kv.first] = kv.second;
    }
    const toml::table tbl = to_toml(rest);
    EstimateSettings set = resolve_settings(sources(model, preset, tbl), dt_s);
    cfg_ = set.cfg;
    job_ = set.job;
    refuse_output_error_online(cfg_, "lash.estimate (a whole record)");
    est_ = std::make_unique<AnyEstimator>(cfg_);
    gaps_.emplace(cfg_.dt_s);
    make_reguesser();
  }

  double update(double v, double y, std::optional<double> t_s) {
    step(v, y, t_s ? *t_s : next_t());
    return yhat_;
  }

  pyb::array_t<double> update_many(const pyb::handle& v_obj, const pyb::handle& y_obj, const pyb::handle& t_obj) {
    const Doubles va(v_obj, "v"), ya(y_obj, "y");
    ya.require_length_of(va);
    const Doubles ta = t_obj.is_none() ? Doubles() : Doubles(t_obj, "t");
    if (!t_obj.is_none()) ta.require_length_of(va);
    const auto v = va.span(), y = ya.span(), t = ta.span();
    std::vector<double> yhat(v.size());
    {
      pyb::gil_scoped_release nogil;
      reserve(v.size());
      for (std::size_t k = 0; k < v.size(); ++k) {
        step(v[k], y[k], t.empty() ? next_t() : t[k]);
        yhat[k] = yhat_;
      }
    }
    return to_numpy(std::move(yhat));
  }

  Result result(bool intervals) const {
    std::optional<EstimateResult> res;
    {
      pyb::gil_scoped_release nogil;  // the intervals run the estimator once more over the samples
      EstimationRun run;
      run.report = est_->report();
      if (intervals) add_intervals(run, cfg_, v_, y_);
      res.emplace(score_estimate(run.report, cfg_.dt_s, job_, t_, y_, ysim_));
    }
    return Result(std::move(*res));
  }

  void reset() {
    est_ = std::make_unique<AnyEstimator>(cfg_);
    make_reguesser();
    gaps_->reset();
    t_.clear();
    v_.clear();
    y_.clear();
    ysim_.clear();
  }

  std::uint64_t samples() const noexcept { return t_.size(); }
  double dt_s() const noexcept { return cfg_.dt_s; }
  pyb::dict params() const {
    pyb::dict d;
    const auto names = est_->param_names();
    std::vector<double> values(names.size());
    est_->param_values(values);
    for (std::size_t i = 0; i < names.size(); ++i) d[pyb::str(names[i])] = values[i];
    return d;
  }
  bool identified() const noexcept { return est_->identified(); }
  pyb::dict reguesses() const {
    pyb::dict d;
    d["right"] = rg_ ? rg_->count(Side::right) : 0;
    d["left"] = rg_ ? rg_->count(Side::left) : 0;
    return d;
  }
  pyb::dict guesses() const {
    pyb::dict d;
    d["right"] = rg_ ? rg_->guess(Side::right) : cfg_.guess_right;
    d["left"] = rg_ ? rg_->guess(Side::left) : cfg_.guess_left;
    return d;
  }

 private:
  void make_reguesser() {
    rg_.reset();
    vprev_ = 0.0;
    if (reguess_) rg_.emplace(cfg_.guess_right, cfg_.guess_left, ReguessSettings{}, cfg_.dt_s);
  }
  void reserve(std::size_t more) {
    t_.reserve(t_.size() + more);
    v_.reserve(v_.size() + more);
    y_.reserve(y_.size() + more);
    ysim_.reserve(ysim_.size() + more);
  }
  double next_t() const noexcept { return static_cast<double>(t_.size()) * cfg_.dt_s; }
  void step(double v, double y, double t) {
    // the library's gap rule for streams (io/table.hpp StreamGaps): restart the regressors there
    if (gaps_->gap_before(t)) est_->restart();
    t_.push_back(t);
    v_.push_back(v);
    y_.push_back(y);
    yhat_ = est_->step(v, y);
    if (rg_) {  // the input-side models only (set_guess); the others have no guesses
      est_->visit_steps(0, [&](auto& e) {
        if constexpr (requires { e.set_guess(Side::right, 0.0); }) rg_->follow(e, vprev_);
      });
    }
    vprev_ = v;
    ysim_.push_back(est_->simulated());
  }

  EstimatorConfig cfg_;
  EstimationJob job_;
  std::unique_ptr<AnyEstimator> est_;
  bool reguess_ = false;
  std::optional<Reguesser> rg_;
  double vprev_ = 0.0;
  std::optional<StreamGaps> gaps_;  // set with cfg_ (its nominal period)
  std::vector<double> t_, v_, y_, ysim_;
  double yhat_ = 0.0;
};

Result estimate(const pyb::handle& t_obj, const pyb::handle& v_obj, const pyb::handle& y_obj, const std::string& model,
                const std::string& preset, double outlier_gate, bool trace, bool intervals,
                const pyb::kwargs& settings) {
  const toml::table tbl = to_toml(settings);
  const SettingsSources src = sources(model, preset, tbl);
  resolve_settings(src);  // settings are checked before the data is converted
  const Doubles ta(t_obj, "t"), va(v_obj, "v"), ya(y_obj, "y");
  va.require_length_of(ta);
  ya.require_length_of(ta);
  ArrayEstimateOptions o;
  o.trace = trace;
  o.outlier_gate = outlier_gate;
  o.intervals = intervals;
  std::optional<ArrayEstimate> e;
  {
    pyb::gil_scoped_release nogil;  // the whole library call: no Python object is touched
    e.emplace(estimate_arrays(src, ta.span(), va.span(), ya.span(), o));
  }
  EstimationRun& run = e->run.run;
  Result r(std::move(e->result), std::move(e->json));
  r.yhat = to_numpy(std::move(run.yhat));
  r.ysim = to_numpy(std::move(run.ysim));
  if (trace) {
    pyb::dict p;
    for (std::size_t i = 0; i < run.param_names.size(); ++i)
      p[pyb::str(run.param_names[i])] = to_numpy(std::move(run.params[i]));
    r.params = p;
  }
  return r;
}

pyb::dict read_record(const std::string& path, const std::vector<std::string>& columns) {
  std::optional<Record> loaded;
  {
    pyb::gil_scoped_release nogil;  // reading and parsing the file touches no Python object
    loaded.emplace(load_record(path, columns));
  }
  Record& rec = *loaded;
  pyb::dict d;
  d["file"] = rec.data.file;
  d["dt_s"] = rec.dt_s;
  const char* keys[] = {"t", "v", "y"};
  for (std::size_t i = 0; i < 3; ++i) d[keys[i]] = to_numpy(std::move(rec.data.cols[i]));
  return d;
}

}  // namespace

void bind_estimate(pyb::module_& m) {
  pyb::class_<Result>(m, "Result", "What `lash estimate` reports about one record (see to_dict()).")
      .def("to_dict", &Result::to_dict,
           "The object `lash estimate --json` prints for the same data and settings (the same library function).")
      .def_property_readonly("json", [](const Result& r) { return r.json; }, "The report as JSON text (one line): to_dict() without guess, outliers and preset.")
      .def_property_readonly("model", [](const Result& r) { return std::string(to_string(r.res.report.model)); })
      .def_property_readonly("samples", [](const Result& r) { return r.res.report.samples; },
                             "Samples stepped, including skipped ones.")
      .def_property_readonly("skipped", [](const Result& r) { return r.res.report.skipped; },
                             "Samples skipped because v or y was not finite (NaN, inf).")
      .def_property_readonly("identified", [](const Result& r) { return r.res.report.identified; },
                             "True when the whole model is identified (the estimator's verdict).")
      .def_property_readonly("dt_s", [](const Result& r) { return r.res.dt_s; },
                             "Sample period used: mean step of t [s].")
      .def_property_readonly("nrmse", [](const Result& r) { return r.res.nrmse; },
                             "NRMSE of the free-run simulation over the window (fraction; NaN if empty).")
      .def_property_readonly("nrmse_window_s", [](const Result& r) {
        return pyb::make_tuple(r.res.nrmse_t0_s, r.res.nrmse_t1_s);
      }, "NRMSE window (t0, t1) [s].")
      .def_readonly("yhat", &Result::yhat, "One-step prediction per sample (lash.estimate only, else None).")
      .def_readonly("ysim", &Result::ysim, "Free-run simulated output per sample (lash.estimate only, else None).")
      .def_readonly("params", &Result::params,
                    "With trace=True: dict name -> array of each parameter per sample (NaN while not identified).")
      .def("__getitem__", [](const Result& r, const pyb::str& k) { return r.to_dict()[k]; })
      .def("__repr__", [](const Result& r) { return "lash.Result(" + r.json + ")"; });

  m.def("estimate", &estimate, pyb::arg("t"), pyb::arg("v"), pyb::arg("y"), pyb::kw_only(),
        pyb::arg("model") = "deadzone-deadband", pyb::arg("preset") = "lash", pyb::arg("outlier_gate") = 12.0,
        pyb::arg("trace") = false, pyb::arg("intervals") = true,
        "estimate(t, v, y, *, model='deadzone-deadband', preset='lash', outlier_gate=12.0, trace=False,\n"
        "         intervals=True, **settings) -> Result\n\n"
        "As `lash estimate`: preset 'lash' (settings tuned to the data, guesses searched when not given) or\n"
        "'thesis'; outlier_gate: isolated outliers of y beyond this many innovation scales are replaced (0 = off).\n"
        "Runs one of lash's switching estimators (docs/method.md §A4) over a whole record, as `lash estimate` does.\n"
        "t [s] (strictly increasing, >= 3 samples; dt = mean step), v [input unit], y [output unit]: 1-D arrays\n"
        "of equal length (converted to contiguous float64 if needed). NaN samples of v or y are skipped and\n"
        "counted (Result.skipped). settings: the keys of an estimator config file (docs/identification.md),\n"
        "e.g. guess_left=-350, guess_right=350, rls={'lambda': 0.99, 'p0': 1000}, noise={'filter_length': 5},\n"
        "nrmse_window=(7.5, 30.0). intervals: the 95 % intervals (ci95, batch means: runs the estimator once\n"
        "more over sections of the record), as `lash estimate`. Raises lash.InputError (a ValueError) naming the key.");

  pyb::class_<Estimator>(m, "Estimator",
                         "Estimator(model, dt_s, *, preset='lash', **settings): one estimator fed sample by sample\n"
                         "(streaming): the preset's static settings (nothing is chosen from data not seen yet: give\n"
                         "the data-dependent ones, e.g. noise={'derivative_threshold': ...}, from `lash estimate\n"
                         "REC --print-config` of a like record), no guess search, no outlier gate. preset: 'lash'\n"
                         "(the default, as lash.estimate and `lash estimate`) or 'thesis'. dt_s: sample period [s];\n"
                         "settings as for lash.estimate.\n"
                         "The k-th sample is at t = k*dt_s. reguess=True: the switching guesses follow the\n"
                         "evidence online (docs/method.md A4.8; input-deadzone and deadzone-deadband).")
      .def(pyb::init<const std::string&, double, const std::string&, const pyb::kwargs&>(), pyb::arg("model"),
           pyb::arg("dt_s"), pyb::kw_only(), pyb::arg("preset") = "lash")
      .def("update", &Estimator::update, pyb::arg("v"), pyb::arg("y"), pyb::arg("t_s") = pyb::none(),
           "update(v, y, t_s=None) -> yhat: one sample v [input unit], y [output unit] at time t_s [s]\n"
           "(default k*dt_s; the NRMSE window uses it, and a step of t longer than 5 dt_s is a gap: the\n"
           "estimator restarts its regressors there). Returns the one-step prediction [output unit].")
      .def("update_many", &Estimator::update_many, pyb::arg("v"), pyb::arg("y"), pyb::arg("t") = pyb::none(),
           "update_many(v, y, t=None) -> yhat array: 1-D arrays of equal length (t [s] optional, as in update).\n"
           "Same bits as update() sample by sample.")
      .def("result", &Estimator::result, pyb::kw_only(), pyb::arg("intervals") = true,
           "The Result after the samples so far (as lash.estimate would report; intervals as there).")
      .def("reset", &Estimator::reset, "Back to the state before the first sample (same settings).")
      .def_property_readonly("samples", &Estimator::samples, "Samples fed so far.")
      .def_property_readonly("dt_s", &Estimator::dt_s, "Sample period [s].")
      .def_property_readonly("identified", &Estimator::identified, "The estimator's verdict now.")
      .def_property_readonly("reguesses", &Estimator::reguesses, "Moves of each side's guess so far (reguess=True).")
      .def_property_readonly("guesses", &Estimator::guesses, "Each side's switching guess now [input unit].")
      .def("params", &Estimator::params, "Current parameters by name (a1_r, b1_r, c_r, d_r, ...; NaN = not identified).");

  m.def("read_record", &read_record, pyb::arg("path"), pyb::arg("columns") = std::vector<std::string>{"t", "v", "y"},
        "read_record(path, columns=['t','v','y']) -> dict(t, v, y, dt_s, file)\n\n"
        "Loads a record (CSV or MAT) as `lash estimate` does: t [s] strictly increasing, dt_s = its mean step.");
}

}  // namespace lash::py
