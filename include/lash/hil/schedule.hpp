#pragma once
/// @file schedule.hpp
/// Which frame each node used at each step, and the closed-loop simulation that replays it
/// (`lash hil simulate --schedule master.csv`, and report.json's
/// `max_abs_diff_vs_observed_schedule_kPa`).
///
/// The ideal schedule is the one of simulate_bench (simulate.hpp): master control step m uses
/// the sensor frame of slave step m, slave step s the command of master control step s − 1.
/// A real run departs from it when a frame is late (a node stalled, the host was busy): the
/// master then holds the last value for that step and catches up with a newer frame later,
/// skipping one; a stalled slave runs its late steps back to back, the first taking the newest
/// of the queued commands, the next ones none. The nodes log what they used (master.csv
/// `sensor_seq`, slave.csv `command_counter` where `command_fresh` = 1), and the replay feeds
/// each simulated node exactly those frames at those steps, through the nodes' own step
/// functions, so that the replay equals the emulation sample for sample, late frames or not.
#include <cstddef>
#include <cstdint>
#include <algorithm>
#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "lash/hil/nodes.hpp"
#include "lash/hil/report.hpp"
#include "lash/hil/simulate.hpp"

namespace lash::hil {

/// What one node applied at one step.
struct FrameUse {
  /// The frame applied at this step, named by the step of its sender that sent it (master:
  /// the slave step of the sensor frame; slave: the control step of the command); −1 = no new
  /// frame this step (the node held the previous value or ran its safe-state machine).
  std::int64_t seq = -1;
  bool dropped = false;  ///< an implausible frame was dropped in this step (drives degraded)
};

/// The frames both nodes used, step by step.
struct FrameSchedule {
  std::vector<FrameUse> master;  ///< by control step m = 0, 1, …
  std::vector<FrameUse> slave;   ///< by slave step s = 0, 1, …
  /// The master's calibration page where it changed (XCP writes, calibration.hpp): the page of
  /// the first control step and of every control step whose page differs from the one before.
  /// simulate_bench applies them through MasterConfig::calibration_schedule. Empty for logs
  /// without calibration columns.
  std::vector<MasterConfig::CalibrationChange> calibration;
  /// > 0: the ideal schedule of this many control steps, not stored (master and slave empty):
  /// lazy_ideal_schedule(), for simulations whose memory must not grow with their duration.
  std::size_t ideal_steps = 0;
  std::size_t master_steps() const noexcept { return ideal_steps ? ideal_steps : master.size(); }
  std::size_t slave_steps() const noexcept { return ideal_steps ? ideal_steps : slave.size(); }
  FrameUse master_use(std::size_t m) const noexcept {
    return ideal_steps ? FrameUse{static_cast<std::int64_t>(m), false} : master[m];
  }
  FrameUse slave_use(std::size_t s) const noexcept {
    return ideal_steps ? FrameUse{static_cast<std::int64_t>(s) - 1, false} : slave[s];
  }
};

/// A schedule given step by step, for a replay whose schedule is not kept in memory (the session
/// reads its nodes' logs as the replay goes, report_logs.hpp). simulate_bench asks for master
/// steps m = 0, 1, … and slave steps s = 0, 1, …, each maybe more than once, never backwards.
class ScheduleSource {
 public:
  virtual ~ScheduleSource() = default;
  virtual std::size_t master_steps() const = 0;
  virtual std::size_t slave_steps() const = 0;
  virtual FrameUse master_use(std::size_t m) = 0;
  virtual FrameUse slave_use(std::size_t s) = 0;
};

/// What simulate_bench's streaming form hands on, row by row, as the nodes' steps produce them.
struct SimulationSink {
  std::function<void(const MasterStepLog&)> master;  ///< every master step (the connecting step included)
  std::function<void(const SlaveStepLog&)> slave;    ///< every slave step
};

/// The schedule of simulate_bench: master m uses slave frame m, slave s uses command s − 1.
FrameSchedule ideal_schedule(std::size_t control_steps);
/// The same schedule in O(1) memory (FrameSchedule::ideal_steps).
FrameSchedule lazy_ideal_schedule(std::size_t control_steps);

/// The schedule the nodes logged in a run (control steps of the master log, every slave step).
/// The master's `sensor_seq` is the sensor frame's alive counter unwrapped (= the slave step
/// that sent it), the slave's `command_counter` the command's counter unwrapped (= the control step).
FrameSchedule observed_schedule(const std::vector<MasterStepLog>& master, const std::vector<SlaveStepLog>& slave);

/// Control steps of `s` that the slave's schedule can serve: the master's schedule up to the
/// first control step that uses a sensor frame of a slave step past its end (a killed slave's
/// log ends earlier than the master's). simulate_bench replays that many without refusing.
std::size_t replayable_control_steps(const FrameSchedule& s) noexcept;

/// Reads the schedule of a run from its logs: master.csv (columns control_step, sensor_seq,
/// dropped) and slave.csv (command_counter, command_fresh, dropped). Throws InputError naming
/// the file, line and column of a missing column or a value that is not a step number.
FrameSchedule read_schedule(const std::filesystem::path& master_csv, const std::filesystem::path& slave_csv);

/// read_schedule() in constant memory: the logs are checked in a first pass (the errors of
/// read_schedule, naming file, line and column; a last line cut short, of a killed node, is
/// left out), then read again step by step as simulate_bench asks for them.
class ScheduleFiles final : public ScheduleSource {
 public:
  ScheduleFiles(const std::filesystem::path& master_csv, const std::filesystem::path& slave_csv);
  ~ScheduleFiles() override;
  ScheduleFiles(const ScheduleFiles&) = delete;
  ScheduleFiles& operator=(const ScheduleFiles&) = delete;
  /// The control steps master.csv holds.
  std::size_t logged_control_steps() const noexcept { return logged_; }
  /// replayable_control_steps() of the schedule.
  std::size_t replayable() const noexcept { return replayable_; }
  /// Replays only the first `control_steps` (at most the logged ones).
  void limit(std::size_t control_steps) noexcept { steps_ = std::min(control_steps, logged_); }
  /// FrameSchedule::calibration of the schedule.
  const std::vector<MasterConfig::CalibrationChange>& calibration() const noexcept { return calibration_; }

  std::size_t master_steps() const override { return steps_; }
  std::size_t slave_steps() const override { return slave_steps_; }
  FrameUse master_use(std::size_t m) override;
  FrameUse slave_use(std::size_t s) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::size_t logged_ = 0, replayable_ = 0, steps_ = 0, slave_steps_ = 0;
  std::vector<MasterConfig::CalibrationChange> calibration_;
};

/// compare_with_simulation() of a master.csv's control rows (read_master_trace: control_step,
/// measured_kPa, current_mA) with simulated master rows given one at a time in ascending control
/// step, reading the log as they come (constant memory). Throws InputError as read_master_trace.
class TraceCompare {
 public:
  explicit TraceCompare(const std::filesystem::path& master_csv);
  ~TraceCompare();
  TraceCompare(const TraceCompare&) = delete;
  TraceCompare& operator=(const TraceCompare&) = delete;
  void add(const MasterStepLog& simulated);
  const SimulationDiff& result() const noexcept { return d_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  SimulationDiff d_;
};

/// The control steps of a master.csv as a master log (control_step, measured_kPa, current_mA
/// filled; the rows before the handshake skipped), to compare with a simulation. Throws InputError.
std::vector<MasterStepLog> read_master_trace(const std::filesystem::path& master_csv);

class FeedBus;
class FrameHistory;

/// simulate_bench one control step at a time (the engine of both simulate_bench forms and of
/// `lash closed-loop --scenario` on the valve): the constructor runs the CCP handshake;
/// advance() runs the next control step — the slave steps whose frames it needs, then the
/// master's — handing each row to the sink as its node's step produced it. Memory is O(1) in
/// the run's length (with a lazy schedule; frames are kept only until the step that uses them).
/// Not real-time code.
class BenchSimulation {
 public:
  /// Throws std::invalid_argument when the nodes refuse their configurations or the slave did
  /// not see the CONNECT. `schedule` and `sink` must outlive the simulation.
  BenchSimulation(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                  const FrameSchedule& schedule, const SimulationSink& sink);
  /// The same on a schedule read as the replay goes (ScheduleFiles) and its calibration changes;
  /// `schedule` and `calibration` must outlive the simulation.
  BenchSimulation(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                  ScheduleSource& schedule, const std::vector<MasterConfig::CalibrationChange>& calibration,
                  const SimulationSink& sink);
  ~BenchSimulation();
  BenchSimulation(const BenchSimulation&) = delete;
  BenchSimulation& operator=(const BenchSimulation&) = delete;
  /// Runs control step m = control_steps(): true when it ran, false at the schedule's end or
  /// once the master has failed. Throws std::invalid_argument when the schedule is not causal.
  bool advance();
  /// Runs the slave steps that pair with the control steps run (s < control_steps()) and are
  /// still due, then checks the master's end state and returns the events and compensation
  /// (master and slave empty: the rows went to the sink). Throws std::invalid_argument when the
  /// master never connected.
  SimulationResult finish();
  std::size_t control_steps() const noexcept { return static_cast<std::size_t>(m_); }
  const MasterNode& master() const noexcept { return master_; }

 private:
  BenchSimulation(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                  std::unique_ptr<ScheduleSource> owned, const std::vector<MasterConfig::CalibrationChange>& calibration,
                  const SimulationSink& sink, ScheduleSource* borrowed = nullptr);
  void master_step(can::Bus& bus, double t);
  bool slave_ready();
  void slave_step();
  const BenchLayout& layout_;
  std::unique_ptr<ScheduleSource> owned_;  // a FrameSchedule's adapter
  ScheduleSource& schedule_;
  const SimulationSink& sink_;
  MasterNode master_;
  SlaveNode slave_;
  double T_;
  std::unique_ptr<FeedBus> mb_, sb_;
  std::unique_ptr<FrameHistory> sensors_, commands_;
  can::Frame bad_sensor_, bad_command_;
  std::int64_t m_ = 0, s_ = 0, m_used_ = -1, s_used_ = -1;
  bool ok_ = true;
};

/// The closed loop of simulate_bench, with each node fed at each step exactly the frames of
/// `schedule` (every frame of its sender newer than the last one it used, up to the one it
/// used — what it received — and, where the log says a frame was dropped, one implausible
/// frame (wrong DLC) besides). Runs schedule.master.size() control steps and the slave steps
/// they need. Throws std::invalid_argument when the schedule is not causal (a node uses a frame
/// its sender has not sent yet, or an older one than before), naming the step.
SimulationResult simulate_bench(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                                const FrameSchedule& schedule);
/// The same simulation in memory independent of its length: each row goes to `sink` when its
/// node's step produced it (the result's master and slave vectors stay empty; events and the
/// compensation are filled), and frames are kept only until the step that uses them.
/// The rows are those of the form above, bit for bit, in the same order per node.
SimulationResult simulate_bench(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                                const FrameSchedule& schedule, const SimulationSink& sink);
/// The same with the schedule read step by step from `schedule` and the master's calibration
/// changes given apart (FrameSchedule::calibration).
SimulationResult simulate_bench(const BenchLayout& layout, const MasterConfig& master, const SlaveConfig& slave,
                                ScheduleSource& schedule,
                                const std::vector<MasterConfig::CalibrationChange>& calibration,
                                const SimulationSink& sink);

}  // namespace lash::hil
