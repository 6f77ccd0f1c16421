#pragma once
/// @file scenario.hpp
/// Named identification scenarios (docs/method.md §A7: E1, E2): a plant file, an input, measurement
/// noise, seeds, estimator settings and the true parameters. Files live in config/scenarios/.
/// Not real-time safe.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "lash/blocks/side.hpp"
#include "lash/identify/estimators.hpp"
#include "lash/metrics/error.hpp"  // error_percent (was declared here)
#include "lash/signals/signal.hpp"

namespace lash {

struct ScenarioSpec {
  std::string file;
  std::string name;
  std::string description;
  std::filesystem::path plant_file;  ///< resolved against the scenario file's folder
  SignalSpec input;
  double duration_s = 200.0;
  double noise_variance = 0.0;        ///< [y unit²]
  std::vector<std::uint64_t> seeds{1};
  std::vector<double> checkpoints_s;  ///< times at which estimates are reported (last = duration)
  EstimatorConfig estimator;          ///< the [estimator] keys over the thesis's settings; dt_s comes from the plant
  PerSide<SideParams> truth;          ///< NaN = parameter not part of the model
  double outside_t0_s = 50.0, outside_t1_s = 200.0;  ///< window of the ±3σ count
  double nrmse_t0_s = 7.5, nrmse_t1_s = 200.0;
};

/// Reads a scenario file (InputError naming file, line and key).
ScenarioSpec load_scenario(const std::filesystem::path& path);

struct ScenarioRun {
  std::uint64_t seed = 1;
  std::vector<PerSide<SideParams>> at;  ///< estimates at each checkpoint
  double outside_per_1000 = 0.0;        ///< |y − y_sim| > 3σ per 1000 samples over the window (NaN if σ = 0)
  double nrmse = 0.0;                   ///< NRMSE of y_sim over the window
  bool identified = false;
};

/// Simulates the plant with the scenario's input and noise for `seed` and runs the estimator.
ScenarioRun run_scenario(const ScenarioSpec& s, std::uint64_t seed);

}  // namespace lash
