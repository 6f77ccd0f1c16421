#pragma once
/// @file config_file.hpp
/// Estimator settings from TOML (the `--config est.toml` of `lash estimate` and the
/// `[estimator]` table of scenario files), documented key by key in docs/identification.md.
/// Not real-time safe; errors are lash::InputError naming file, line and key.
#include <string>
#include <vector>

#include "lash/identify/config.hpp"
#include "lash/io/toml_util.hpp"

namespace lash {

/// Extra settings of a whole estimation job (not of the estimator itself).
struct EstimationJob {
  std::vector<std::string> columns{"t", "v", "y"};  ///< names of t, v, y in the data file
  double nrmse_t0_s = 7.5;                          ///< NRMSE window start [s] (thesis: 7.5 s)
  double nrmse_t1_s = -1.0;                         ///< NRMSE window end [s]; < 0 = end of record
};

/// Reads every estimator key present in `table` into `cfg` (keys absent keep their value).
/// `job` (optional) receives `columns` and `nrmse_window`. Calls table.finish().
/// The keys are those of the field table (config_fields.hpp); a file may hold keys of models other
/// than its own (they are read and unused).
void read_estimator_config(TomlTable& table, EstimatorConfig& cfg, EstimationJob* job = nullptr);

/// The settings as a TOML document that `read_estimator_config` (`lash estimate --config`) reads
/// back to the same estimator: every key the model reads (the others do not change its result),
/// non-finite values as commented lines (the default of every such key), and, with `job`, its
/// `columns` and `nrmse_window`.
std::string config_to_toml(const EstimatorConfig& cfg, const EstimationJob* job = nullptr);

}  // namespace lash
