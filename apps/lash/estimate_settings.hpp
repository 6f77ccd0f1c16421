#pragma once
// `lash estimate`'s options and how they become an EstimatorConfig: the preset, the settings
// chosen from the record (lash preset), then --config, then the command-line options.
#include <optional>
#include <string>
#include <vector>

#include "lash/identify/auto.hpp"
#include "lash/identify/config_file.hpp"
#include "lash/identify/data.hpp"

namespace lash::cli {

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
  bool strict = false;  ///< a non-finite row is an error instead of skipped
  bool timing = false;
  std::string preset = "lash";
  bool preset_given = false;  // --preset on the command line (beats a `preset` key in --config)
  bool print_config = false;
  double outlier_gate = 12.0;
  std::vector<std::string> given;  // options given on the command line (without dashes)
};

std::vector<std::string> split_names(const std::string& text);

/// preset → settings chosen from `rec` (lash preset; none when rec is null) → --config → options.
/// Validated; throws InputError naming the option or file.
EstimatorConfig assemble(const EstimateOptions& o, ModelKind model, Preset preset, const Record* rec,
                         EstimationJob& job);

}  // namespace lash::cli
