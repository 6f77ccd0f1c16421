#include "estimate_settings.hpp"

#include <cmath>
#include <stdexcept>

#include "cli_common.hpp"
#include "lash/io/toml_util.hpp"

namespace lash::cli {

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

/// preset → data-dependent settings (lash preset, when the record is known) → --config → options.
EstimatorConfig assemble(const EstimateOptions& o, ModelKind model, Preset preset, const Record* rec,
                         EstimationJob& job) {
  if (!o.config.empty() && !o.preset_given) {  // a `preset` key in the file applies unless --preset is given
    const toml::table root = parse_toml_file(o.config);
    TomlTable t(root, o.config);
    if (auto p = t.string_opt("preset")) {
      try {
        preset = parse_preset(*p);
      } catch (const std::invalid_argument& e) {
        t.fail("preset", e.what());
      }
    }
  }
  EstimatorConfig cfg = preset_config(model, preset);
  if (rec) {
    cfg.dt_s = rec->dt_s;
    if (preset == Preset::lash) tune_to_data(cfg, analyse_record(rec->v(), rec->y(), rec->dt_s));
  }
  if (!o.config.empty()) {
    const toml::table root = parse_toml_file(o.config);
    TomlTable t(root, o.config);
    (void)t.string_opt("preset");
    read_estimator_config(t, cfg, &job);
  }
  cfg.model = model;
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
    try {
      cfg.rls.forgetting = parse_forgetting(*o.forgetting);
    } catch (const std::invalid_argument& e) {
      throw InputError("", 0, "--forgetting", e.what());
    }
  }
  if (!o.columns.empty()) job.columns = split_names(o.columns);
  if (!o.nrmse_window.empty()) {
    if (o.nrmse_window.size() != 2 || !(o.nrmse_window[0] >= 0) || !(o.nrmse_window[0] < o.nrmse_window[1]) ||
        !std::isfinite(o.nrmse_window[1]))
      throw InputError("", 0, "--nrmse-window", "expected T0 T1 with 0 <= T0 < T1, finite [s]");
    job.nrmse_t0_s = o.nrmse_window[0];
    job.nrmse_t1_s = o.nrmse_window[1];
  }
  try {
    cfg.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(o.config, 0, "", e.what());
  }
  return cfg;
}

}  // namespace lash::cli
