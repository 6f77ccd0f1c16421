#pragma once
/// @file report.hpp
/// What `lash hil run` reports from the nodes' logs: the emulated trace against the
/// simulation through the same step functions, and the step-response figures of the
/// thesis (paper 2 §2.7.2: 90 % rise, 10 % settling, overshoot). Not real-time code.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "lash/hil/nodes.hpp"

namespace lash::hil {

/// The first reference step (a jump between two samples) whose previous level was held
/// for at least min_hold_s; the window ends at the next jump, after max_window_s, or at
/// the end of the trace. Its figures come from lash::step_metrics (control/step_metrics.hpp).
struct StepWindow {
  std::size_t begin = 0;  ///< first sample at the new level
  std::size_t end = 0;    ///< one past the last sample of the window
  double t_step_s = 0.0;
  double y0 = 0.0;        ///< reference level before the step
  double y1 = 0.0;        ///< reference level after the step
};
std::optional<StepWindow> find_step(const std::vector<double>& reference, double dt_s, double min_hold_s = 0.5,
                                    double max_window_s = 2.0);

struct SimulationDiff {
  std::size_t compared = 0;               ///< control steps compared
  double max_abs_diff_kPa = 0.0;          ///< max |measured_emulated − measured_simulated|
  double max_abs_diff_mA = 0.0;           ///< max |current_emulated − current_simulated|
  std::optional<std::int64_t> first_diff_step;  ///< first control step where they differ
};
/// Compares emulated master rows (control_step ≥ 0) with the simulation's, by control step.
SimulationDiff compare_with_simulation(const std::vector<std::int64_t>& control_step,
                                       const std::vector<double>& measured_kPa, const std::vector<double>& current_mA,
                                       const std::vector<MasterStepLog>& simulated);

}  // namespace lash::hil
