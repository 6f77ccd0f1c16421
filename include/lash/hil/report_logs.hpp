#pragma once
/// @file report_logs.hpp
/// `lash hil run`'s report computed from the nodes' CSV logs on disk, streaming: the logs are
/// read row by row (a bounded number of passes), never held in memory, so the session's memory
/// does not grow with the run's length. The figures are those of make_run_report() (report.hpp)
/// over the same logs read back whole, value for value. Not real-time code.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "lash/hil/handover.hpp"
#include "lash/hil/report.hpp"
#include "lash/hil/schedule.hpp"

namespace lash::hil {

/// What a node's CSV log holds, from two passes over it in constant memory (the loop figures
/// need the mean before the deviations, and the row count before the 99th percentile's tail).
struct NodeLogScan {
  std::filesystem::path file;
  LogReadBack read;                            ///< rows, an unfinished last line, the last row's t_s
  NodeState last_state = NodeState::startup;   ///< the state of the last row
  std::int64_t last_control_step = -1;         ///< master: the largest control step (−1: none)
  std::size_t control_rows = 0;                ///< master: the rows of a control step (control_step ≥ 0)
  /// Loop figures of the rows [µs], equal to rt::tet_us() … of the rows' records read back whole.
  rt::Summary tet_us, io_us, cycle_us, wake_latency_us;
  /// master: the calibration page of the first control step and where it changed (= observed_schedule()'s).
  std::vector<MasterConfig::CalibrationChange> calibration;
};
NodeLogScan scan_master_log(const std::filesystem::path& path);
NodeLogScan scan_slave_log(const std::filesystem::path& path);

/// The logs a session reports from: the master's and the first slave's (each scanned), if any.
struct RunLogs {
  std::optional<NodeLogScan> master, slave;
};

/// Fills the computed part of `report` as make_run_report() does for the runs with their logs
/// read back (master and slaves: the statistics and events handed over, their `log` and loop
/// records empty), and the comparisons with the simulation of the ideal schedule (with the
/// calibration changes the master logged) and of the schedule the nodes logged (report.hpp
/// vs_simulation, vs_observed_schedule, observed_schedule_note), reading the logs again as it
/// goes. `master` null: no master run (nothing compared). Throws InputError for a log that
/// cannot be read, std::invalid_argument when the ideal schedule cannot be simulated.
void make_run_report_from_logs(RunReport& report, const MasterRun* master, const std::vector<SlaveRun>& slaves,
                               const RunLogs& logs, const BenchLayout& layout, const MasterConfig& master_config,
                               const SlaveConfig& slave_config, const BenchScenario* scenario = nullptr);

}  // namespace lash::hil
