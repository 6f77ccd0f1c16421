#pragma once
/// @file report.hpp
/// What `lash hil run` reports from the nodes' logs: the emulated trace against the
/// simulation through the same step functions, and the step-response figures of the
/// thesis (paper 2 §2.7.2: 90 % rise, 10 % settling, overshoot). Not real-time code.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "lash/metrics/step_response.hpp"
#include "lash/hil/handover.hpp"
#include "lash/hil/node_run.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/hil/settings.hpp"
#include "lash/rt/periodic.hpp"

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
  /// One control step compared: the emulated and the simulated pressure [kPa] and current [mA].
  void add(std::int64_t control_step, double kPa_emulated, double kPa_simulated, double mA_emulated,
           double mA_simulated) noexcept {
    ++compared;
    const double dp = std::abs(kPa_emulated - kPa_simulated), di = std::abs(mA_emulated - mA_simulated);
    if ((dp > 0 || di > 0) && !first_diff_step) first_diff_step = control_step;
    max_abs_diff_kPa = std::max(max_abs_diff_kPa, dp);
    max_abs_diff_mA = std::max(max_abs_diff_mA, di);
  }
};
/// Compares emulated master rows (control_step ≥ 0) with the simulation's, by control step.
SimulationDiff compare_with_simulation(const std::vector<std::int64_t>& control_step,
                                       const std::vector<double>& measured_kPa, const std::vector<double>& current_mA,
                                       const std::vector<MasterStepLog>& simulated);
/// The same over the master's own log.
SimulationDiff compare_with_simulation(const std::vector<MasterStepLog>& emulated,
                                       const std::vector<MasterStepLog>& simulated);

/// Step-response figures of a trace sampled at dt_s (sample i at t = i·dt_s): the first
/// reference step (find_step) and lash::step_metrics of the plant pressure in its window,
/// and of the measured pressure when given. The one place both `hil run` and `hil simulate` get them.
struct StepResponse {
  StepWindow window;
  StepMetrics plant;                     ///< of the noise-free plant pressure
  std::optional<StepMetrics> measured;   ///< of the sensor reading
};
std::optional<StepResponse> step_response(const std::vector<double>& reference_kPa, double dt_s,
                                          const std::vector<double>& pressure_kPa,
                                          const std::vector<double>* measured_kPa = nullptr);

/// step_response() over a trace given sample by sample, in constant memory (it keeps only the
/// step's window, at most max_window_s): the same figures as step_response() on the whole trace.
class StepResponseStream {
 public:
  explicit StepResponseStream(double dt_s, bool with_measured = false, double min_hold_s = 0.5,
                              double max_window_s = 2.0);
  void add(double reference_kPa, double pressure_kPa, double measured_kPa = 0.0);
  std::optional<StepResponse> result() const;

 private:
  double dt_s_, min_hold_s_;
  bool with_measured_;
  std::size_t max_n_;
  std::size_t k_ = 0, level_start_ = 0;
  double prev_ = 0.0;
  bool found_ = false, open_ = false;
  StepWindow w_;
  std::vector<double> p_, y_;
};

/// Control steps that consumed another frame than the one meant for them: master step m must
/// use the sensor frame of slave step m (fresh, counter m modulo 2¹⁶), slave step s
/// (0 < s < control_steps) the command of master step s − 1 (fresh, unwrapped counter s − 1).
/// Late frames, lost frames or a node running late show up here.
std::size_t off_schedule_steps(const std::vector<MasterStepLog>& master, const std::vector<SlaveStepLog>& slave,
                               std::int64_t control_steps);

/// Tracking figures of a scenario run over a time window (`tracking.*` of report.json and of
/// `lash closed-loop --json`): sample m at t = m·dt_s counts when t0_s ≤ t ≤ t1_s.
struct Tracking {
  double t0_s = 0.0, t1_s = 0.0;
  std::size_t samples = 0;
  double rms_error = 0.0;      ///< RMS of r − y over the window [output unit]; NaN without samples
  double max_abs_error = 0.0;  ///< max |r − y| over the window [output unit]
};
Tracking tracking(const std::vector<double>& reference, const std::vector<double>& output, double dt_s, double t0_s,
                  double t1_s);

/// A scenario run on the bench, from the nodes' logs: control step m pairs the master's r(m)
/// with the plant pressure of slave step m (noise-free, the y(m) the master used).
struct ScenarioFigures {
  std::string file;
  CompensationMode mode = CompensationMode::none;
  Tracking window;                         ///< the scenario's score_window_s
  std::optional<Tracking> before_drift;    ///< [0, first drift)
  std::optional<Tracking> after_drift;     ///< [first drift, end]
  CompensationState compensation;          ///< the master's compensator at the end
};
ScenarioFigures scenario_figures(const BenchScenario& s, double dt_s, const std::vector<MasterStepLog>& master,
                                 const std::vector<SlaveStepLog>& slave, const CompensationState& compensation);

/// Tracking over a window, sample by sample in O(1) memory: the arithmetic of tracking() (the
/// same bits). add() is noexcept and allocation-free.
class TrackingAccumulator {
 public:
  TrackingAccumulator(double dt_s, double t0_s, double t1_s) noexcept : dt_s_(dt_s), w_{t0_s, t1_s, 0, 0.0, 0.0} {}
  void add(std::size_t m, double r, double y) noexcept;
  /// The figures so far (t1_s replaced when given: a window that ends with the run).
  Tracking result() const noexcept;

 private:
  double dt_s_;
  Tracking w_;
  double sum2_ = 0.0;
};

/// A scenario's figures (ScenarioFigures) accumulated sample by sample: add(m, r(m), y(m)) for
/// m = 0, 1, … (the window, and before/after the first drift), O(1) memory. scenario_figures()
/// above is this over the logs; `lash closed-loop --scenario` and `lash hil simulate --scenario`
/// use it on the rows as the run produces them.
class ScenarioScore {
 public:
  ScenarioScore(const BenchScenario& s, double dt_s) noexcept;
  void add(std::size_t m, double r, double y) noexcept;
  ScenarioFigures result(const CompensationState& compensation) const;

 private:
  std::string file_;
  CompensationMode mode_;
  double dt_s_, first_drift_s_;
  TrackingAccumulator window_, before_, after_;
  std::size_t samples_ = 0;
};

/// A node that handed nothing over (it was killed): what the session read back from its CSV log.
struct LogRecovery {
  std::string file;            ///< the log read
  std::size_t rows = 0;        ///< whole rows kept
  std::size_t cut_lines = 0;   ///< an unfinished last line, dropped
  double last_t_s = -1.0;      ///< t_s of the last row kept [s] (loop time of the node)
};

/// Loop figures of one node [µs] and its counters.
struct NodeFigures {
  std::optional<LogRecovery> recovered;  ///< set when the node was killed (figures from its log only)
  LogStats logs;                         ///< its log writer's counters (ring_full: items not written)
  long peak_rss_kB = -1;                 ///< its peak resident set [kB]; −1: not handed over
  rt::Summary tet_us, io_us, cycle_us, wake_latency_us;
  std::size_t steps = 0, overruns = 0;
  FrameStats frames;
  std::vector<std::string> warnings;
  bool dma_latency_held = false;
};
NodeFigures node_figures(const NodeStats& stats, const LoopTrace& loop);

/// How a node process ended, seen by the session.
struct NodeExit {
  bool exited = false;      ///< false: still running when the session ended (should not happen)
  int status = 0;           ///< exit code, or 128 + signal number
  int signal = 0;           ///< the signal that killed it (0 = exited normally)
  double t_s = 0.0;         ///< when, since the session started [s]
};

/// A slave that died and the watchdog restarted (--restart-slave).
struct SlaveRestart {
  NodeExit died;
  double restarted_s = -1.0;  ///< when the new slave was ready [s since start]; −1 = not restarted
  double gap_s() const { return restarted_s >= 0 ? restarted_s - died.t_s : -1.0; }
};

/// What `lash hil run` reports (report.json): computed from the nodes' runs in memory.
struct RunReport {
  // The session (filled by hil::Session).
  double duration_s = 0.0, step_s = 0.0;
  std::string reference, isolation, bus, out_dir;
  bool interrupted = false;
  int interrupt_signal = 0;
  NodeExit master_exit;
  std::vector<NodeExit> slave_exits;      ///< one per slave process, in start order
  std::vector<SlaveRestart> restarts;
  long session_peak_rss_kB = -1;          ///< the session process's own peak resident set [kB] (−1: not measured)
  // Computed by make_run_report.
  bool have_master = false, have_slave = false;
  NodeFigures master, slave;              ///< slave: the first slave process
  double handshake_s = -1.0;
  std::int64_t control_steps = 0;
  std::vector<NodeEvent> events;          ///< the master's
  std::vector<NodeEvent> slave_events;    ///< the first slave's
  NodeState master_state = NodeState::startup, slave_state = NodeState::startup;  ///< at the end of the run
  FrameStats frames;                      ///< sent/received/late/lost summed over master + every slave
  std::optional<StepResponse> step;
  SimulationDiff vs_simulation;           ///< against the ideal-schedule simulation
  /// Against the simulation of the schedule the nodes logged (schedule.hpp): 0 for every run,
  /// late frames or not. Empty when it was not replayed (why: observed_schedule_note).
  std::optional<SimulationDiff> vs_observed_schedule;
  std::string observed_schedule_note;
  std::size_t off_schedule = 0;
  std::optional<ScenarioFigures> scenario;  ///< --scenario runs
  std::optional<LogRecovery> master_recovered, slave_recovered;  ///< a node killed: what its log kept
};

/// The nodes' part of `report` shared by make_run_report and make_run_report_from_logs: which
/// nodes ran, the frame totals, and per node its figures (from `figures(stats, loop, is_master)`),
/// recovery, events and end state; for the master also the handshake and the control steps.
void report_nodes(RunReport& report, const MasterRun* master, const std::vector<SlaveRun>& slaves,
                  const std::function<NodeFigures(const NodeStats&, const LoopTrace&, bool is_master)>& figures);
/// Fills the computed part of `report` from the master's run, the slaves' runs (first = the one
/// started with the master) and the simulation of the same control steps (simulate_bench).
/// A run's `log` (and loop records) are what the session read back from the node's CSV log.
void make_run_report(RunReport& report, const MasterRun* master, const std::vector<SlaveRun>& slaves,
                     const std::vector<MasterStepLog>& simulated, const BenchScenario* scenario = nullptr);
/// The scenario part of report.json and of `lash closed-loop --json` on a valve scenario:
/// scenario, rig, compensation_mode, score_window_s, tracking{,_before_drift,_after_drift},
/// compensation.final, adaptation; one JSON object's text.
std::string scenario_json(const ScenarioFigures& f);
/// report.json text (fields documented in docs/hil.md).
std::string run_report_json(const RunReport& report);

}  // namespace lash::hil
