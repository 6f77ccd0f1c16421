#include "lash/identify/config_fields.hpp"

#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "lash/io/field_table.hpp"

namespace lash {

static_assert(std::is_same_v<std::size_t, std::uint64_t>, "min_updates is referenced as std::size_t*");

namespace {

using Ref = ConfigField::Ref;
using C = EstimatorConfig;
constexpr ModelSet kCommon = CommonSettings::models;
constexpr ModelSet kFilter = RegressionFilterSettings::models;
constexpr ModelSet kDeriv = DerivativeSwitchingSettings::models;
constexpr ModelSet kMethod = MethodSettings::models;
constexpr ModelSet kGuess = InputSwitchingSettings::models;
constexpr ModelSet kDzdb = DeadzoneDeadbandSettings::models;
constexpr ModelSet kOutDz = OutputDeadzoneSettings::models;
constexpr ModelSet kCarts = CoupledCartsSettings::models;

// clang-format off
const ConfigField kFields[] = {
  // CommonSettings
  {"", "model", "", "linear | input-deadzone | output-deadzone | deadzone-deadband | coupled-carts", kCommon,
   [](C& c) -> Ref { return &c.model; }},
  // MethodSettings
  {"", "method", "method", "ls (RLS, thesis) | iv (recursive instrumental variables)", kMethod,
   [](C& c) -> Ref { return &c.method; }},
  // InputSwitchingSettings
  {"", "guess_left", "guess-left", "c_l*: switching guess below the deadzone [v unit] (default: searched)", kGuess,
   [](C& c) -> Ref { return &c.guess_left; }},
  {"", "guess_right", "guess-right", "c_r*: switching guess above the deadzone [v unit] (default: searched)", kGuess,
   [](C& c) -> Ref { return &c.guess_right; }},
  // DeadzoneDeadbandSettings
  {"", "pooled", "pooled", "deadzone-deadband: one 4-parameter RLS per side (a1, b1 shared by + and -)", kDzdb,
   [](C& c) -> Ref { return &c.pooled; }},
  // InputSwitchingSettings
  {"", "sim_side_by_sign", "sim-side-by-sign",
   "Free run inside the deadzone: a1 of the side of sign v(k-1) (eq. 34) instead of the side last used", kGuess,
   [](C& c) -> Ref { return &c.sim_side_by_sign; }},
  // MethodSettings
  {"", "iv_delay", "iv-delay", "iv: instrument = y delayed this many more samples", kMethod,
   [](C& c) -> Ref { return &c.iv_delay; }, 1, 60},
  // DeadzoneDeadbandSettings
  {"", "direction_run", "direction-run", "Samples the direction must hold before a key updates (>= 2)", kDzdb,
   [](C& c) -> Ref { return &c.direction_run; }, 2, 1000000},
  // CommonSettings
  {"", "min_updates", "min-updates", "Updates a key needs before its side counts as identified", kCommon,
   [](C& c) -> Ref { return &c.min_updates; }, 1, 1000000000},
  // DeadzoneDeadbandSettings
  {"", "singular_tol", "singular-tol", "deadzone-deadband: |det| of eq. 31/32 below this (relative) is singular",
   kDzdb, [](C& c) -> Ref { return &c.singular_tol; }},
  {"", "settle_tol", "settle-tol", "deadzone-deadband: (c, d) settled when they move < this x (|c| + |d|) per update",
   kDzdb, [](C& c) -> Ref { return &c.settle_tol; }},
  {"", "settle_updates", "settle-updates", "deadzone-deadband: settled updates in a row before a side is identified",
   kDzdb, [](C& c) -> Ref { return &c.settle_updates; }, 0, 1000000},
  {"", "model_switching", "model-switching",
   "deadzone-deadband: switch on a switching model driven by v (iterated; default: when the dy/dt switching leaves a side unidentified)",
   kDzdb, [](C& c) -> Ref { return &c.model_switching; }},
  {"", "output_error", "output-error",
   "input-deadzone, output-deadzone, deadzone-deadband: refine the estimate by output error (free-run least squares over the NRMSE window)",
   static_cast<ModelSet>(kDzdb | model_bit(ModelKind::input_deadzone) | kOutDz),
   [](C& c) -> Ref { return &c.output_error; }},
  {"", "output_error_check", "output-error-check",
   "input-deadzone, output-deadzone, deadzone-deadband: without output-error, check the estimate by the same fit (a side it moves is poor_fit)",
   static_cast<ModelSet>(kDzdb | model_bit(ModelKind::input_deadzone) | kOutDz),
   [](C& c) -> Ref { return &c.output_error_check; }},
  {"", "switch_hold", "switch-hold", "Model switching: samples the model's deadband must stay engaged one way",
   kDzdb, [](C& c) -> Ref { return &c.switch_hold; }, 1, 1000},
  {"", "switch_margin", "switch-margin", "Model switching: v within this share of |c| of an edge updates nothing [-]",
   kDzdb, [](C& c) -> Ref { return &c.switch_margin; }},
  // OutputDeadzoneSettings
  {"", "zero_threshold", "zero-threshold", "output-deadzone: |y| at or below this counts as 0 [y unit]", kOutDz,
   [](C& c) -> Ref { return &c.zero_threshold; }},
  // CoupledCartsSettings
  {"", "accel_limit", "accel-limit", "coupled-carts: max |acceleration| for stage 1 [y unit/s^2]", kCarts,
   [](C& c) -> Ref { return &c.accel_limit; }},
  {"", "stage2_start", "stage2-start", "coupled-carts: start of the deadband estimation [s]", kCarts,
   [](C& c) -> Ref { return &c.stage2_start_s; }},
  // CommonSettings (the verdict's fit window starts with --nrmse-window, so fit_start has no option)
  {"", "fit_threshold", "fit-threshold", "Free-run NRMSE above this fraction is reported poor_fit (0.2 = 20 %)",
   kCommon, [](C& c) -> Ref { return &c.fit_threshold; }},
  {"", "fit_start", "", "Start of the verdict's fit window [s]", kCommon,
   [](C& c) -> Ref { return &c.fit_start_s; }},
  {"", "ci_tolerance", "ci-tolerance",
   "Identified only when each 95 % interval of K, tau, c, d lies within +-this fraction of its centre (0 = off)",
   kCommon, [](C& c) -> Ref { return &c.ci_tolerance; }},
  // CommonSettings::rls
  {"rls", "lambda", "lambda", "Forgetting factor in [0.9, 1] (thesis: 0.99)", kCommon,
   [](C& c) -> Ref { return &c.rls.lambda; }},
  {"rls", "p0", "p0", "Initial covariance P0 = p0 I (thesis: 1000)", kCommon,
   [](C& c) -> Ref { return &c.rls.p0; }},
  {"rls", "eta0", "eta0", "Initial parameters a1,b1,e (thesis: 1,1,1)", kCommon,
   [](C& c) -> Ref { return &c.rls.eta0; }},
  {"rls", "lower", "lower", "Projection box: lower bounds of a1,b1,e", kCommon,
   [](C& c) -> Ref { return &c.rls.lower; }},
  {"rls", "upper", "upper", "Projection box: upper bounds of a1,b1,e", kCommon,
   [](C& c) -> Ref { return &c.rls.upper; }},
  {"rls", "trace_max", "trace-max", "exponential forgetting: bound on trace(P)", kCommon,
   [](C& c) -> Ref { return &c.rls.trace_max; }},
  {"rls", "forgetting", "forgetting", "exponential (eq. 15, trace-bounded) | directional", kCommon,
   [](C& c) -> Ref { return &c.rls.forgetting; }},
  // CommonSettings::noise (RegressionFilterSettings)
  {"noise", "filter_length", "filter-length", "Moving average on y [samples] (1 = off)", kFilter,
   [](C& c) -> Ref { return &c.noise.filter_length; }, 1, 100000},
  {"noise", "filter_input", "filter-input", "Pass v through the same moving average as y", kFilter,
   [](C& c) -> Ref { return &c.noise.filter_input; }},
  {"noise", "input_delay", "input-delay", "Delay of v [samples] to keep it aligned with a filtered y", kFilter,
   [](C& c) -> Ref { return &c.noise.input_delay; }, 0, 100000},
  {"noise", "dead_time", "dead-time", "Plant dead time [samples]: y(k) responds to v(k-1-n); the free run too",
   kFilter, [](C& c) -> Ref { return &c.noise.dead_time; }, 0, 100000},
  // CommonSettings::noise (DerivativeSwitchingSettings)
  {"noise", "derivative_prefilter_length", "derivative-prefilter-length",
   "Moving average on y before differencing [samples] (0 = --filter-length)", kDeriv,
   [](C& c) -> Ref { return &c.noise.derivative_prefilter_length; }, 0, 100000},
  {"noise", "derivative_filter_length", "derivative-filter-length", "Moving average on the derivative of y [samples]",
   kDeriv, [](C& c) -> Ref { return &c.noise.derivative_filter_length; }, 1, 100000},
  {"noise", "derivative_threshold", "derivative-threshold",
   "|dy/dt| at or below this counts as not moving [y unit/s]", kDeriv,
   [](C& c) -> Ref { return &c.noise.derivative_threshold; }},
  {"noise", "align_delay", "align-delay", "Delay of the regression signals to line up with dy/dt [samples]", kDeriv,
   [](C& c) -> Ref { return &c.noise.align_delay; }, 0, 100000},
};
// clang-format on

void parse_enum(std::string_view s, ModelKind& m) { m = parse_model_kind(s); }
void parse_enum(std::string_view s, EstimationMethod& m) { m = parse_method(s); }
void parse_enum(std::string_view s, Forgetting& f) { f = parse_forgetting(s); }

double parse_number(std::string_view s) {
  double x = 0.0;
  const auto* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, x);
  if (s.empty() || r.ec != std::errc() || r.ptr != end || !std::isfinite(x))
    throw std::invalid_argument("expected a finite number, got '" + std::string(s) + "'");
  return x;
}

std::int64_t parse_integer(std::string_view s, const ConfigField& f) {
  std::int64_t x = 0;
  const auto* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, x);
  if (s.empty() || r.ec != std::errc() || r.ptr != end || x < f.lo || x > f.hi)
    throw std::invalid_argument("expected an integer in " + std::to_string(f.lo) + ".." + std::to_string(f.hi) +
                                ", got '" + std::string(s) + "'");
  return x;
}

std::string num(double x) { return toml_number(x); }

template <class Int>
void read_count(TomlTable& t, const ConfigField& f, Int& out) {
  const auto v = t.integer_opt(f.key);
  if (!v) return;
  if (*v < f.lo || *v > f.hi)
    t.fail(f.key, "must be an integer in " + std::to_string(f.lo) + ".." + std::to_string(f.hi));
  out = static_cast<Int>(*v);
}

}  // namespace

std::string toml_number(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s.precision(17);
  s << x;
  std::string t = s.str();
  if (t.find_first_of(".eEn") == std::string::npos) t += ".0";
  return t;
}

std::string toml_string(std::string_view s) {
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + "\"";
}

std::span<const ConfigField> estimator_fields() noexcept { return kFields; }

const ConfigField* find_field_by_flag(std::string_view flag) noexcept {
  return find_by_flag<ConfigField>(kFields, flag);
}

bool model_uses(ModelKind model, std::string_view flag) noexcept {
  const ConfigField* f = find_field_by_flag(flag);
  return f == nullptr || contains(f->models, model);
}

void read_field(TomlTable& t, const ConfigField& f, EstimatorConfig& cfg) {
  std::visit(Overload{
                 [&](double* p) { *p = t.number_or(f.key, *p); },
                 [&](bool* p) {
                   if (auto b = t.boolean_opt(f.key)) *p = *b;
                 },
                 [&](std::size_t* p) { read_count(t, f, *p); },
                 [&](std::uint32_t* p) { read_count(t, f, *p); },
                 [&](std::array<double, 3>* p) {
                   const auto v = t.numbers_opt(f.key);
                   if (!v) return;
                   if (v->size() != 3) t.fail(f.key, "expected 3 numbers [a1, b1, e]");
                   *p = {(*v)[0], (*v)[1], (*v)[2]};
                 },
                 [&](auto* p) {  // the enumerations, by name
                   const auto s = t.string_opt(f.key);
                   if (!s) return;
                   try {
                     parse_enum(*s, *p);
                   } catch (const std::invalid_argument& e) {
                     t.fail(f.key, e.what());
                   }
                 },
             },
             f.at(cfg));
}

void parse_field(const ConfigField& f, std::string_view text, EstimatorConfig& cfg) {
  std::visit(Overload{
                 [&](double* p) { *p = parse_number(text); },
                 [&](bool* p) {
                   if (text == "true" || text == "1") *p = true;
                   else if (text == "false" || text == "0") *p = false;
                   else throw std::invalid_argument("expected true or false, got '" + std::string(text) + "'");
                 },
                 [&](std::size_t* p) { *p = static_cast<std::size_t>(parse_integer(text, f)); },
                 [&](std::uint32_t* p) { *p = static_cast<std::uint32_t>(parse_integer(text, f)); },
                 [&](std::array<double, 3>* p) {
                   std::array<double, 3> a{};
                   std::size_t start = 0, i = 0;
                   for (; i < 3; ++i) {
                     const auto end = text.find(',', start);
                     if ((end == std::string_view::npos) != (i == 2))
                       throw std::invalid_argument("expected three numbers a1,b1,e, got '" + std::string(text) + "'");
                     a[i] = parse_number(text.substr(start, end == std::string_view::npos ? end : end - start));
                     start = end + 1;
                   }
                   *p = a;
                 },
                 [&](auto* p) { parse_enum(text, *p); },
             },
             f.at(cfg));
}

std::string field_toml_value(const ConfigField& f, const EstimatorConfig& cfg) {
  return std::visit(Overload{
                        [](double* p) { return num(*p); },
                        [](bool* p) { return std::string(*p ? "true" : "false"); },
                        [](std::size_t* p) { return std::to_string(*p); },
                        [](std::uint32_t* p) { return std::to_string(*p); },
                        [](std::array<double, 3>* p) {
                          return "[" + num((*p)[0]) + ", " + num((*p)[1]) + ", " + num((*p)[2]) + "]";
                        },
                        [](auto* p) { return "\"" + std::string(to_string(*p)) + "\""; },
                    },
                    f.at(const_cast<EstimatorConfig&>(cfg)));  // at() only takes the member's address
}

bool field_finite(const ConfigField& f, const EstimatorConfig& cfg) {
  return std::visit(Overload{
                        [](double* p) { return std::isfinite(*p); },
                        [](std::array<double, 3>* p) {
                          return std::isfinite((*p)[0]) && std::isfinite((*p)[1]) && std::isfinite((*p)[2]);
                        },
                        [](auto*) { return true; },
                    },
                    f.at(const_cast<EstimatorConfig&>(cfg)));
}

}  // namespace lash
