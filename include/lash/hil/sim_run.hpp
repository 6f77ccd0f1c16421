#pragma once
/// @file sim_run.hpp
/// `lash hil simulate`: the closed loop of the bench through the nodes' step functions
/// (schedule.hpp: simulate_bench), streamed row by row to a CSV file, so that its memory does not
/// grow with the duration (a scenario's tracking figures are accumulated row by row; a
/// --schedule replay reads the run's logs as it goes). Not real-time code.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <vector>

#include "lash/hil/report.hpp"
#include "lash/hil/schedule.hpp"

namespace lash::hil {

struct SimulationFileRun {
  std::size_t rows = 0;                    ///< control steps written (each with its slave step)
  std::optional<StepResponse> step;        ///< of the noise-free plant pressure (runs without a scenario)
  std::optional<ScenarioFigures> scenario; ///< scenario runs
  std::optional<SimulationDiff> vs_log;    ///< against `compare_with` (the replayed run's master.csv)
  CompensationState compensation;          ///< the master's compensator at the end
};

/// Simulates `schedule` (lazy_ideal_schedule(N) for a plain run) and writes `out` atomically:
/// `control_step,t_s,reference_kPa,measured_kPa,current_mA,pressure_kPa`, one row per control
/// step m (t = m·dt) with the plant pressure of slave step m. compare_with: control-step rows
/// of a run's master.csv (read_master_trace) to compare the simulation with. Throws
/// std::invalid_argument for a schedule that is not causal, InputError when `out` cannot be written.
SimulationFileRun simulate_to_csv(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                                  const FrameSchedule& schedule, double dt_s, const std::filesystem::path& out,
                                  const BenchScenario* scenario = nullptr,
                                  const std::vector<MasterStepLog>* compare_with = nullptr);
/// The same for the replay of a run's logs (`lash hil simulate --schedule`) in constant memory:
/// the schedule read from the logs as the simulation goes (ScheduleFiles), compared with the
/// control rows of `compare_with` (the run's master.csv) as they come (TraceCompare).
SimulationFileRun simulate_to_csv(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                                  ScheduleFiles& schedule, double dt_s, const std::filesystem::path& out,
                                  const BenchScenario* scenario, const std::filesystem::path& compare_with);

}  // namespace lash::hil
