#pragma once
/// @file config_sources.hpp
/// The settings of one estimation, resolved in one place for `lash estimate` and Python's
/// `lash.estimate` / `lash.Estimator`. Lowest first: the preset's settings for the model
/// (EstimatorConfig(model) or EstimatorConfig::thesis(model)), those chosen from the record
/// (Preset::lash, when the record is given: tune_to_data), the keys of a config file, the keys
/// given as a table (Python's keyword arguments), then the options (the command line). Keys and
/// options a model does not read are refused (config_fields.hpp), never ignored; a config file
/// may hold other models' keys. Not real-time safe. Errors are InputError naming file, line, key.
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "lash/identify/auto.hpp"
#include "lash/identify/config_file.hpp"

namespace lash {

struct SettingsSources {
  std::optional<ModelKind> model;     ///< else the config file's `model` (one of them is needed)
  std::optional<Preset> preset;       ///< else the config file's `preset`, else Preset::lash
  std::string config_file;            ///< a TOML file of estimator keys (docs/identification.md); "" = none
  const toml::table* keys = nullptr;  ///< the same keys as a table (Python's **settings); refused when unused
  /// (flag without dashes, text) of the field table's options, applied last in order; refused when unused
  std::vector<std::pair<std::string, std::string>> options;
  std::optional<std::vector<std::string>> columns;           ///< names or 0-based indices of t, v, y
  std::optional<std::pair<double, double>> nrmse_window_s;   ///< NRMSE window [t0, t1] [s]
  /// The estimates follow a drift (lash monitor's periods): the output-error refinement, which fits
  /// one constant model to the whole window and so averages a drift in it, stays off unless the
  /// config file, the keys or an option turn it on (docs/monitor.md).
  bool follows_drift = false;
};

struct EstimateSettings {
  EstimatorConfig cfg;  ///< validated; fit_start_s = job.nrmse_t0_s (the verdict's fit window is the reported one)
  EstimationJob job;
  Preset preset = Preset::lash;
  /// What the record said (analyse_record), when the settings were tuned to it (preset lash with
  /// a record); estimate_arrays hands it on to the guess search (AutoOptions::traits).
  std::optional<DataTraits> traits;
};

/// Resolves and validates the settings. dt_s: the record's sample period [s] (<= 0: not known yet,
/// the settings are only checked); v, y: the record (empty: nothing is chosen from data).
EstimateSettings resolve_settings(const SettingsSources& src, double dt_s = 0.0, std::span<const double> v = {},
                                  std::span<const double> y = {});
/// The same with the record's columns (nullptr or empty: nothing is chosen from data).
EstimateSettings resolve_settings(const SettingsSources& src, double dt_s, const RecordColumns* record);

}  // namespace lash
