// The estimator settings: the common + per-model split, the defaults (lash's for a default-constructed
// config, the thesis's by name), the field table that drives the TOML reader/writer and the CLI
// options, and the one settings path (resolve_settings) of `lash estimate` and Python.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "lash/identify/auto.hpp"
#include "lash/identify/config_fields.hpp"
#include "lash/identify/config_file.hpp"
#include "lash/identify/config_sources.hpp"
#include "lash/io/error.hpp"

using namespace lash;

namespace {
constexpr ModelKind kModels[] = {ModelKind::linear, ModelKind::input_deadzone, ModelKind::output_deadzone,
                                 ModelKind::deadzone_deadband, ModelKind::coupled_carts};
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Every field's value as its TOML text: two configs are equal when all of these are.
std::string all_values(const EstimatorConfig& c) {
  std::string s;
  for (const auto& f : estimator_fields()) s += std::string(f.table) + "." + f.key + "=" + field_toml_value(f, c) + "\n";
  return s + "dt=" + toml_number(c.dt_s);
}
}  // namespace

TEST(IdentifyConfig, DefaultConstructedIsLashDeadzoneDeadband) {
  // the numbers of docs/identification.md "Settings per model" (E2's method), written out by hand
  const EstimatorConfig c;
  EXPECT_EQ(c.model, ModelKind::deadzone_deadband);
  EXPECT_EQ(c.method, EstimationMethod::iv);
  EXPECT_EQ(c.iv_delay, 45u);
  EXPECT_TRUE(c.pooled);
  EXPECT_EQ(c.direction_run, 41u);
  EXPECT_EQ(c.rls.lambda, 1.0);
  EXPECT_EQ(c.noise.filter_length, 40u);
  EXPECT_TRUE(c.noise.filter_input);
  EXPECT_EQ(c.noise.derivative_filter_length, 20u);
  EXPECT_EQ(c.noise.derivative_threshold, 150.0);
  EXPECT_EQ(c.noise.align_delay, 10u);
  EXPECT_EQ(c.guess_right, kInf);  // searched by estimate_auto
  EXPECT_EQ(all_values(c), all_values(preset_config(ModelKind::deadzone_deadband)));
}

TEST(IdentifyConfig, PerModelLashDefaults) {
  const EstimatorConfig in(ModelKind::input_deadzone), out(ModelKind::output_deadzone), lin(ModelKind::linear),
      carts(ModelKind::coupled_carts);
  EXPECT_EQ(in.rls.lambda, 0.995);
  EXPECT_EQ(in.rls.lower[0], -1.0);
  EXPECT_EQ(in.rls.upper[0], 0.0);
  EXPECT_EQ(in.rls.lower[1], 0.0);
  EXPECT_EQ(in.method, EstimationMethod::ls);
  EXPECT_EQ(out.rls.lambda, 0.9995);
  EXPECT_EQ(out.rls.forgetting, Forgetting::directional);
  EXPECT_EQ(lin.rls.lambda, 0.9995);
  EXPECT_EQ(carts.rls.lambda, 0.995);
  EXPECT_EQ(carts.stage2_start_s, 5.0);
  EXPECT_EQ(carts.accel_limit, 1.0);
  for (ModelKind m : kModels) EXPECT_EQ(all_values(EstimatorConfig(m)), all_values(preset_config(m, Preset::lash)));
}

// The output-deadzone rule of docs/identification.md "Defaults chosen from the data": λ from the
// sample time (a 2 s memory), and a quantised output (an encoder velocity) through a 4-point
// moving average on y and v; an output that is not quantised keeps the unfiltered default.
TEST(IdentifyConfig, OutputDeadzoneTunedToQuantisedOutput) {
  DataTraits d;
  d.dt_s = 0.001;
  d.samples = 30000;
  EstimatorConfig plain(ModelKind::output_deadzone, 0.001);
  tune_to_data(plain, d);
  EXPECT_DOUBLE_EQ(plain.rls.lambda, 1.0 - 0.001 / 2.0);
  EXPECT_EQ(plain.noise.filter_length, 1u);
  EXPECT_FALSE(plain.noise.filter_input);
  d.quantum = 0.00196;  // the cart's encoder velocity step [m/s]
  EstimatorConfig quantised(ModelKind::output_deadzone, 0.001);
  tune_to_data(quantised, d);
  EXPECT_DOUBLE_EQ(quantised.rls.lambda, 0.9995);
  EXPECT_EQ(quantised.noise.filter_length, 4u);
  EXPECT_TRUE(quantised.noise.filter_input);
  d.dt_s = 0.5;  // a slow record: λ clamped at 0.99
  tune_to_data(quantised, d);
  EXPECT_EQ(quantised.rls.lambda, 0.99);
}

TEST(IdentifyConfig, ThesisSettingsByName) {
  for (ModelKind m : kModels) {
    const EstimatorConfig t = EstimatorConfig::thesis(m, 0.01);
    EXPECT_EQ(t.model, m);
    EXPECT_EQ(t.dt_s, 0.01);
    EXPECT_EQ(t.rls.lambda, 0.99);  // thesis §1.5.1
    EXPECT_EQ(t.rls.p0, 1000.0);
    EXPECT_EQ(t.rls.eta0[0], 1.0);
    EXPECT_EQ(t.rls.eta0[2], 1.0);
    EXPECT_EQ(t.rls.lower[0], -kInf);
    EXPECT_EQ(t.method, EstimationMethod::ls);
    EXPECT_FALSE(t.pooled);
    EXPECT_EQ(t.direction_run, 2u);
    EXPECT_EQ(t.noise.filter_length, 1u);
    EXPECT_EQ(t.noise.derivative_threshold, 0.0);
    EXPECT_EQ(t.accel_limit, 1.0);  // §1.6.3
    EXPECT_EQ(t.stage2_start_s, 7.5);
    EXPECT_EQ(all_values(t), all_values(preset_config(m, Preset::thesis, 0.01)));
  }
}

TEST(IdentifyConfig, EachPartValidatesOnlyForItsModels) {
  EstimatorConfig c(ModelKind::linear);
  c.direction_run = 1;  // a deadzone-deadband setting: not read by linear, not checked
  c.zero_threshold = -1.0;
  EXPECT_NO_THROW(c.validate());
  c.model = ModelKind::deadzone_deadband;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.direction_run = 41;
  c.model = ModelKind::output_deadzone;
  try {
    c.validate();
    FAIL() << "zero-threshold < 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("zero-threshold"), std::string::npos);
  }
}

TEST(IdentifyConfig, FieldTableMasksComeFromTheStructs) {
  std::set<std::string> keys, flags;
  for (const auto& f : estimator_fields()) {
    EXPECT_TRUE(keys.insert(std::string(f.table) + "." + f.key).second) << f.key;
    if (*f.flag) {
      EXPECT_TRUE(flags.insert(f.flag).second) << f.flag;
    }
  }
  EXPECT_TRUE(model_uses(ModelKind::deadzone_deadband, "pooled"));
  EXPECT_FALSE(model_uses(ModelKind::input_deadzone, "pooled"));
  EXPECT_TRUE(model_uses(ModelKind::input_deadzone, "guess-left"));
  EXPECT_FALSE(model_uses(ModelKind::output_deadzone, "guess-left"));
  EXPECT_FALSE(model_uses(ModelKind::coupled_carts, "method"));
  EXPECT_TRUE(model_uses(ModelKind::coupled_carts, "derivative-threshold"));
  EXPECT_FALSE(model_uses(ModelKind::linear, "align-delay"));
  EXPECT_TRUE(model_uses(ModelKind::linear, "lambda"));
  EXPECT_FALSE(model_uses(ModelKind::linear, "accel-limit"));
  EXPECT_TRUE(model_uses(ModelKind::linear, "no-such-option"));
}

TEST(IdentifyConfig, TomlWriterAndReaderRoundTripEveryModel) {
  for (ModelKind m : kModels) {
    EstimatorConfig c(m, 0.001);
    // change every field the model reads away from its default, through the table's own parser
    for (const auto& f : estimator_fields()) {
      if (!contains(f.models, m) || std::string(f.key) == "model") continue;
      const std::string v = field_toml_value(f, c);
      if (v == "true" || v == "false") parse_field(f, v == "true" ? "false" : "true", c);
      else if (v == "\"ls\"") parse_field(f, "iv", c);
      else if (v == "\"iv\"") parse_field(f, "ls", c);
      else if (v.front() == '"') continue;  // forgetting: iv needs exponential
      else if (v.front() == '[') parse_field(f, "-0.5,0.25,3", c);
      else if (f.hi > 0) parse_field(f, std::to_string(f.lo + 3), c);
      else parse_field(f, "0.123456789012345678", c);
    }
    c.rls.upper = {2.0, 3.0, 4.0};  // >= lower
    const std::string text = config_to_toml(c);
    const toml::table tbl = toml::parse(text);
    TomlTable t(tbl, "rt.toml");
    EstimatorConfig back(m, 0.001);
    read_estimator_config(t, back);
    for (const auto& f : estimator_fields()) {
      if (contains(f.models, m)) {
        EXPECT_EQ(field_toml_value(f, back), field_toml_value(f, c)) << f.key << "\n" << text;
      }
    }
  }
}

TEST(IdentifyConfig, ResolveSettingsLayersAndRefusals) {
  // preset → file keys → options; an option of another model is refused naming it
  SettingsSources s;
  s.model = ModelKind::input_deadzone;
  s.preset = Preset::thesis;
  s.options = {{"lambda", "0.98"}, {"guess-left", "-400"}, {"guess-right", "400"}};
  const EstimateSettings r = resolve_settings(s, 0.002);
  EXPECT_EQ(r.cfg.rls.lambda, 0.98);
  EXPECT_EQ(r.cfg.rls.p0, 1000.0);
  EXPECT_EQ(r.cfg.guess_left, -400.0);
  EXPECT_EQ(r.cfg.dt_s, 0.002);
  EXPECT_EQ(r.cfg.fit_start_s, 7.5);
  s.options.push_back({"pooled", "true"});
  try {
    resolve_settings(s, 0.002);
    FAIL() << "--pooled accepted for input-deadzone";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "--pooled");
  }
  const toml::table keys = toml::parse("zero_threshold = 1.0\n");
  SettingsSources k;
  k.model = ModelKind::linear;
  k.keys = &keys;
  try {
    resolve_settings(k);
    FAIL() << "zero_threshold accepted for linear";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "zero_threshold");
  }
  SettingsSources none;
  EXPECT_THROW(resolve_settings(none), InputError);  // no model anywhere
}
