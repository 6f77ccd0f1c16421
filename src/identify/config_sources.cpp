#include "lash/identify/config_sources.hpp"

#include <cmath>
#include <stdexcept>

#include "lash/identify/config_fields.hpp"
#include "lash/io/error.hpp"

namespace lash {

namespace {

/// The keys of `t` (and of its [rls], [noise]) that are fields `model` does not read.
void refuse_unused_keys(const toml::table& tbl, const std::string& origin, ModelKind model) {
  TomlTable t(tbl, origin);
  for (const ConfigField& f : estimator_fields()) {
    if (contains(f.models, model)) continue;
    const std::string table = f.table;
    if (table.empty()) {
      if (t.has(f.key)) t.fail(f.key, std::string("model ") + to_string(model) + " does not use this key");
    } else if (t.has(table)) {
      if (const auto* sub = tbl[table].as_table(); sub && sub->contains(f.key)) {
        TomlTable st(*sub, origin, table);
        st.fail(f.key, std::string("model ") + to_string(model) + " does not use this key");
      }
    }
  }
}

}  // namespace

EstimateSettings resolve_settings(const SettingsSources& src, double dt_s, std::span<const double> v,
                                  std::span<const double> y) {
  if (v.empty()) return resolve_settings(src, dt_s, nullptr);
  const std::size_t n = std::min(v.size(), y.size());
  const RecordColumns rec = RecordColumns::of(v.first(n), y.first(n));
  return resolve_settings(src, dt_s, &rec);
}

EstimateSettings resolve_settings(const SettingsSources& src, double dt_s, const RecordColumns* record) {
  EstimateSettings out;
  std::optional<toml::table> file;
  if (!src.config_file.empty()) file = parse_toml_file(src.config_file);

  std::optional<ModelKind> model = src.model;
  out.preset = src.preset.value_or(Preset::lash);
  if (file) {
    TomlTable t(*file, src.config_file);
    if (auto p = t.string_opt("preset"); p && !src.preset) {
      try {
        out.preset = parse_preset(*p);
      } catch (const std::invalid_argument& e) {
        t.fail("preset", e.what());
      }
    }
    if (auto m = t.string_opt("model"); m && !model) {
      try {
        model = parse_model_kind(*m);
      } catch (const std::invalid_argument& e) {
        t.fail("model", e.what());
      }
    }
  }
  if (!model) throw InputError("", 0, "--model", "give --model (or a --config with model = ...)");

  // an option the model does not read is refused, never ignored
  for (const auto& [flag, text] : src.options)
    if (!model_uses(*model, flag))
      throw InputError("", 0, "--" + flag, std::string("model ") + to_string(*model) + " does not use this option");
  if (src.keys) refuse_unused_keys(*src.keys, "", *model);

  EstimatorConfig& cfg = out.cfg;
  cfg = preset_config(*model, out.preset);
  if (dt_s > 0.0) {
    cfg.dt_s = dt_s;
    if (out.preset == Preset::lash && record && record->size() > 0) {
      out.traits = analyse_record(*record, dt_s);
      tune_to_data(cfg, *out.traits);
    }
  }
  if (src.follows_drift) cfg.output_error = cfg.output_error_check = false;
  if (file) {
    TomlTable t(*file, src.config_file);
    (void)t.string_opt("preset");
    read_estimator_config(t, cfg, &out.job);
  }
  if (src.keys) {
    TomlTable t(*src.keys, "");
    read_estimator_config(t, cfg, &out.job);
  }
  cfg.model = *model;
  for (const auto& [flag, text] : src.options) {
    const ConfigField* f = find_field_by_flag(flag);
    if (!f) throw InputError("", 0, "--" + flag, "not an estimator setting");
    try {
      parse_field(*f, text, cfg);
    } catch (const std::invalid_argument& e) {
      throw InputError("", 0, "--" + flag, e.what());
    }
  }
  if (src.columns) {
    if (src.columns->size() != 3) throw InputError("", 0, "--columns", "expected three columns t,v,y");
    out.job.columns = *src.columns;
  }
  if (src.nrmse_window_s) {
    const auto [t0, t1] = *src.nrmse_window_s;
    if (!(t0 >= 0) || !(t0 < t1) || !std::isfinite(t1))
      throw InputError("", 0, "--nrmse-window", "expected T0 T1 with 0 <= T0 < T1, finite [s]");
    out.job.nrmse_t0_s = src.nrmse_window_s->first;
    out.job.nrmse_t1_s = src.nrmse_window_s->second;
  }
  cfg.fit_start_s = out.job.nrmse_t0_s;  // the verdict's fit window starts where the reported NRMSE's does
  if (dt_s > 0.0) cfg.dt_s = dt_s;
  try {
    cfg.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(src.config_file, 0, "", e.what());
  }
  return out;
}

}  // namespace lash
