#pragma once
// `lash estimate`'s options. The estimator settings are registered from the library's field table
// (lash/identify/config_fields.hpp) and handed, as given, to lash::resolve_settings
// (lash/identify/config_sources.hpp), the same path Python's lash.estimate takes.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lash/identify/config_sources.hpp"

namespace lash::cli {

struct EstimateOptions {
  std::string data;
  std::string model;
  std::string config;
  std::map<std::string, std::string> texts;  // field-table options with a value, by flag
  std::map<std::string, bool> switches;      // field-table options without a value (--pooled), by flag
  std::string columns;
  std::vector<double> nrmse_window;
  std::string out;
  std::string plot;
  bool json = false;
  bool strict = false;  ///< a non-finite row is an error instead of skipped
  bool timing = false;
  std::string preset = "lash";
  bool print_config = false;
  double outlier_gate = 12.0;
};

/// Registers one option per field of the table that has a flag (`--lambda`, `--pooled`, …).
void add_setting_options(CLI::App& sub, EstimateOptions& o);

/// What the command line says about the settings (options given, in the table's order).
/// Throws InputError naming the option.
SettingsSources settings_sources(const CLI::App& sub, const EstimateOptions& o);

}  // namespace lash::cli
