#include "lash/identify/config.hpp"

#include "lash/identify/estimators.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace lash {

ModelKind parse_model_kind(std::string_view n) {
  std::string names;
  for (const ModelTraits& t : EstimatorModels::traits) {
    if (n == t.name) return t.kind;
    names += (names.empty() ? "" : ", ") + std::string(t.name);
  }
  throw std::invalid_argument("unknown model '" + std::string(n) + "' (" + names + ")");
}

const char* to_string(ModelKind m) noexcept {
  return static_cast<std::size_t>(m) < kModelCount ? model_traits(m).name.data() : "?";
}

EstimationMethod parse_method(std::string_view n) {
  if (n == "ls" || n == "rls") return EstimationMethod::ls;
  if (n == "iv") return EstimationMethod::iv;
  throw std::invalid_argument("unknown method '" + std::string(n) + "' (ls, iv)");
}

const char* to_string(EstimationMethod m) noexcept { return m == EstimationMethod::iv ? "iv" : "ls"; }

Forgetting parse_forgetting(std::string_view n) {
  if (n == "exponential") return Forgetting::exponential;
  if (n == "directional") return Forgetting::directional;
  throw std::invalid_argument("expected \"exponential\" or \"directional\", got '" + std::string(n) + "'");
}

const char* to_string(Forgetting f) noexcept { return f == Forgetting::directional ? "directional" : "exponential"; }

namespace {
void require(bool ok, const char* field, const std::string& msg) {
  if (!ok) throw std::invalid_argument(std::string(field) + ": " + msg);
}
}  // namespace

void CommonSettings::validate() const {
  require(std::isfinite(dt_s) && dt_s > 0, "dt", "sample period must be > 0 [s]");
  // λ < 0.9 remembers fewer than 1/(1 − λ) = 10 samples: too few to separate a side's 3–4
  // parameters from noise, and a forgetting factor like 1e-300 makes the RLS denominators vanish
  require(rls.lambda >= kMinLambda && rls.lambda <= 1, "lambda",
          "forgetting factor must be in [0.9, 1] (a memory 1/(1 - lambda) of at least 10 samples)");
  require(std::isfinite(rls.p0) && rls.p0 > 0, "p0", "initial covariance must be > 0");
  require(rls.trace_max > 0, "trace-max", "must be > 0");
  for (std::size_t i = 0; i < 3; ++i) {
    require(std::isfinite(rls.eta0[i]), "eta0", "must be finite");
    require(!std::isnan(rls.lower[i]) && !std::isnan(rls.upper[i]) && rls.lower[i] <= rls.upper[i], "bounds",
            "need lower <= upper");
  }
  noise.RegressionFilterSettings::validate();
  require(min_updates >= 1, "min-updates", "must be >= 1");
  require(std::isfinite(fit_threshold) && fit_threshold > 0, "fit-threshold", "must be > 0 (a fraction: 0.2 = 20 %)");
  require(std::isfinite(fit_start_s) && fit_start_s >= 0, "fit-start", "must be >= 0 [s]");
  require(std::isfinite(ci_tolerance) && ci_tolerance >= 0, "ci-tolerance",
          "must be >= 0 (a fraction: 0.05 = 5 %; 0 = off)");
}

void RegressionFilterSettings::validate() const {
  require(filter_length >= 1 && filter_length <= 100000, "filter-length", "must be in 1..100000");
  require(input_delay <= 100000, "input-delay", "must be <= 100000 samples");
  require(dead_time <= 100000, "dead-time", "must be <= 100000 samples");
}

void DerivativeSwitchingSettings::validate() const {
  require(derivative_filter_length >= 1 && derivative_filter_length <= 100000, "derivative-filter-length",
          "must be in 1..100000");
  require(derivative_prefilter_length <= 100000, "derivative-prefilter-length", "must be in 0..100000");
  require(align_delay <= 100000, "align-delay", "must be <= 100000 samples");
  require(std::isfinite(derivative_threshold) && derivative_threshold >= 0, "derivative-threshold",
          "must be >= 0 [y unit/s]");
}

void MethodSettings::validate() const {
  require(iv_delay >= 1 && iv_delay <= 60, "iv-delay", "must be in 1..60 samples");
}

void InputSwitchingSettings::validate() const {
  require(!std::isnan(guess_left) && !std::isnan(guess_right), "guess", "guesses must be numbers");
  // an infinite guess means "not given": lash::estimate_auto searches it (auto.hpp); a bare
  // estimator never updates that side
  require(guess_left < guess_right, "guess-left",
          "guess-left must be < guess-right (the guesses lie outside the deadzone: c_l* < c_l <= c_r < c_r*)");
}

void DeadzoneDeadbandSettings::validate() const {
  require(direction_run >= 2 && direction_run <= 1000000, "direction-run", "must be in 2..1000000 samples");
  require(std::isfinite(settle_tol) && settle_tol > 0, "settle-tol", "must be > 0");
  require(settle_updates <= 1000000, "settle-updates", "must be <= 1000000");
  require(std::isfinite(singular_tol) && singular_tol > 0, "singular-tol", "must be > 0");
  require(!model_switching || pooled, "model-switching", "needs pooled = true");
  require(switch_hold >= 1 && switch_hold <= 1000, "switch-hold", "must be in 1..1000 samples");
  require(std::isfinite(switch_margin) && switch_margin >= 0 && switch_margin < 1, "switch-margin",
          "must be in [0, 1)");
}

bool DeadzoneDeadbandSettings::SwitchSide::usable() const noexcept {
  return std::isfinite(a1) && std::isfinite(b1) && std::isfinite(c) && std::isfinite(d) && std::fabs(a1) < 1.0 &&
         b1 != 0.0 && d >= 0.0;
}

void OutputDeadzoneSettings::validate() const {
  require(std::isfinite(zero_threshold) && zero_threshold >= 0, "zero-threshold", "must be >= 0");
}

void CoupledCartsSettings::validate() const {
  require(accel_limit > 0, "accel-limit", "must be > 0");
  require(std::isfinite(stage2_start_s) && stage2_start_s >= 0, "stage2-start", "must be >= 0 [s]");
}

EstimatorConfig::EstimatorConfig(ModelKind m, double dt) {
  model = m;
  dt_s = dt;
  // lash's data-independent settings per model (docs/identification.md "Defaults chosen from the
  // data"), from each model's policy (identify/models/); the settings that depend on the record
  // come on top (tune_to_data, auto.hpp).
  with_model(m, [this]<class Model>() { Model::defaults(*this); });
}

EstimatorConfig EstimatorConfig::thesis(ModelKind m, double dt) {
  EstimatorConfig c(m, dt);
  c.rls = RlsSettings{};                              // λ = 0.99, P0 = 1000·I, η0 = [1 1 1]
  c.noise = NoiseSettings{};
  static_cast<MethodSettings&>(c) = MethodSettings{};
  c.pooled = false;
  c.direction_run = 2;  // y(k) > y(k−1) > y(k−2)
  c.stage2_start_s = 7.5;
  // the thesis's estimate is not refined; where lash's refinement would move it, it is not
  // presented as identified (issue 30 item 2, docs/method.md §A4.4c)
  c.output_error_check = m == ModelKind::deadzone_deadband;
  return c;
}

void EstimatorConfig::validate() const {
  CommonSettings::validate();
  if (contains(DerivativeSwitchingSettings::models, model)) noise.DerivativeSwitchingSettings::validate();
  if (contains(MethodSettings::models, model)) MethodSettings::validate();
  if (contains(InputSwitchingSettings::models, model)) InputSwitchingSettings::validate();
  if (contains(DeadzoneDeadbandSettings::models, model)) DeadzoneDeadbandSettings::validate();
  if (contains(OutputDeadzoneSettings::models, model)) OutputDeadzoneSettings::validate();
  if (contains(CoupledCartsSettings::models, model)) CoupledCartsSettings::validate();
  if (method == EstimationMethod::iv)
    require(rls.forgetting == Forgetting::exponential, "forgetting", "iv supports exponential forgetting only");
}

RlsConfig<3> EstimatorConfig::rls3() const {
  RlsConfig<3> c;
  c.lambda = rls.lambda;
  c.p0 = rls.p0;
  c.eta0 = rls.eta0;
  c.forgetting = rls.forgetting;
  c.trace_max = rls.trace_max;
  c.lower = rls.lower;
  c.upper = rls.upper;
  return c;
}

RlsConfig<2> EstimatorConfig::rls2() const {
  RlsConfig<2> c;
  c.lambda = rls.lambda;
  c.p0 = rls.p0;
  c.eta0 = {rls.eta0[0], rls.eta0[1]};
  c.forgetting = rls.forgetting;
  c.trace_max = rls.trace_max;
  c.lower = {rls.lower[0], rls.lower[1]};
  c.upper = {rls.upper[0], rls.upper[1]};
  return c;
}

RlsConfig<4> EstimatorConfig::rls4() const {
  RlsConfig<4> c;
  c.lambda = rls.lambda;
  c.p0 = rls.p0;
  c.eta0 = {rls.eta0[0], rls.eta0[1], rls.eta0[2], 0.0};
  c.forgetting = rls.forgetting;
  c.trace_max = rls.trace_max;
  c.lower = {rls.lower[0], rls.lower[1], rls.lower[2], -std::numeric_limits<double>::infinity()};
  c.upper = {rls.upper[0], rls.upper[1], rls.upper[2], std::numeric_limits<double>::infinity()};
  return c;
}

}  // namespace lash
