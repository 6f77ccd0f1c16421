#pragma once
/// @file nodes.hpp
/// The two ECUs of the hydraulic bench (docs/method.md §B, thesis paper 2 §2.7.3):
///
/// - SlaveNode ("Slave and Plant Emulator", Figs 2.17–2.19): answers the master's CCP
///   CONNECT by replaying a recorded DTO (it does not interpret it); each step it
///   reads the newest current command, steps the pilot-valve plant of docs/method.md §B1 and
///   sends the sensor frame (supply pressure sent as 0).
/// - MasterNode ("Master Emulator", Fig 2.16): sends CRO until a DTO arrives, then
///   each step runs the controller of docs/method.md §B2 (discrete PID → deadzone inverse →
///   saturation 0–2000 mA) on the newest sensor frame and sends the command frame.
///
/// Both check every frame they receive before acting on it (hil/e2e.hpp: DLC, CRC-8 SAE
/// J1850, DBC range, alive counter): an implausible frame is counted per reason and dropped,
/// never applied. Implausible or stale input drives the safe-state machine (NodeState below):
/// the master freezes its PID and ramps to 0 mA, at N missed periods it commands 0 mA; the
/// slave ramps the valve current to 0 mA and never drives outside 0–2000 mA.
///
/// step() is the whole per-sample work of a node on the bus it is given. It is noexcept,
/// allocation-free (logs are preallocated) and O(1) apart from draining at most
/// kMaxDrain frames. In the emulation that bus is an emulated CAN controller
/// (can/controller_bus.hpp), so step() makes no system call: the socket I/O runs before and
/// after it, timed apart. The real-time loop (rt::PeriodicLoop) and the closed-loop
/// simulation (hil/simulate.hpp) call exactly this function, which is why their
/// traces agree sample for sample.
///
/// Step order and timing (emulation): the slave's step s runs half a period after
/// the master's step boundary (the slave starts its grid T/2 after it sees CONNECT),
///   slave s : i = newest command (sent by master step s−1) → plant.apply(i) → y(s) = plant.measure() → send
///   master m: y = newest sensor (sent by slave step s = m) → i(m) = controller(r(m), y) → send
/// so the command of master step m acts at slave step m+1 (the one-step bus delay) and
/// the loop equals the discrete closed loop y(k) = measure(); i(k) = C(r(k), y(k)); apply(i(k)).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "lash/can/bus.hpp"
#include "lash/control/adaptive_compensator.hpp"
#include "lash/control/controller.hpp"
#include "lash/hil/bench_layout.hpp"
#include "lash/hil/calibration.hpp"
#include "lash/hil/e2e.hpp"
#include "lash/identify/verdict.hpp"
#include "lash/rigs/drift.hpp"
#include "lash/rigs/pilot_valve_model.hpp"
#include "lash/rigs/pilot_valve_rig.hpp"
#include "lash/signals/signal.hpp"

namespace lash::hil {

/// Most frames a node reads from the bus in one step; a babbling node cannot stretch a step further.
inline constexpr std::size_t kMaxDrain = 64;

/// Most frames a master logs in one step: kMaxDrain received, a CRO and a command sent, margin.
inline constexpr std::size_t kStepFrames = kMaxDrain + 8;

/// A frame as a node saw it, for the candump log.
struct LoggedFrame {
  can::Frame frame;
  bool sent = false;
};

/// The safe-state machine both nodes run (docs/hil.md has the diagram). Numbers are the
/// `state` column of master.csv / slave.csv.
///   startup   (0) master: CCP CONNECT sent, no reply yet (the slave waits before its loop)
///   connected (1) handshake done, no plausible input yet: 0 mA
///   running   (2) plausible, fresh input is applied
///   degraded  (3) implausible input (or, slave: stale input): the master freezes its PID
///                 (integrator included) and ramps its command to 0 mA; the slave ramps the
///                 valve current to 0 mA — at E2EConfig::ramp_mA_per_s
///   safe      (4) 0 mA: the ramp reached 0, or (master) no plausible sensor frame for
///                 fault_missed_periods periods
///   failed    (5) master: no CCP reply within dto_timeout_s
/// degraded/safe → running after E2EConfig::recovery_frames good steps in a row (a step
/// with a plausible new frame and no implausible one).
enum class NodeState : std::uint8_t { startup, connected, running, degraded, safe, failed };
const char* to_string(NodeState s) noexcept;
using MasterState = NodeState;
using SlaveState = NodeState;

/// Every state transition (and the CCP handshake) is an event, logged with its step and time.
enum class NodeEventKind : std::uint8_t {
  connect_sent,          ///< master: first CCP CONNECT (startup)
  connected,             ///< startup → connected (master: positive DTO; slave: CONNECT answered)
  input_valid,           ///< connected → running: first plausible input
  input_implausible,     ///< running → degraded: an implausible frame
  input_stale,           ///< slave: running → degraded, no command for fault_missed_periods
  ramp_done,             ///< degraded → safe: the current reached 0 mA
  sensor_timeout,        ///< master: connected/running/degraded → safe, no sensor frame for N periods
  input_recovered,       ///< degraded → running after recovery_frames good steps
  input_resumed,         ///< safe → running after recovery_frames good steps
  dto_timeout,           ///< master: startup → failed
};
const char* to_string(NodeEventKind k) noexcept;
using MasterEventKind = NodeEventKind;

struct NodeEvent {
  std::uint32_t step = 0;   ///< loop step k
  double t_s = 0.0;         ///< time the step ran [s] (slave's CONNECT: 0, before its first step)
  NodeEventKind kind = NodeEventKind::connected;
  NodeState from = NodeState::startup, to = NodeState::startup;
};
using MasterEvent = NodeEvent;

/// Per-step bookkeeping of the safe-state machine's input, shared by both nodes.
struct InputWatch {
  std::uint32_t misses = 0;    ///< steps since the last plausible new frame
  std::uint32_t good_run = 0;  ///< good steps in a row
  void end_step(bool fresh, bool bad) noexcept {
    misses = fresh ? 0 : misses + 1;
    good_run = (fresh && !bad) ? good_run + 1 : 0;
  }
};

/// Preallocated event log (no allocation in the step; overflow is counted).
class EventLog {
 public:
  explicit EventLog(std::size_t capacity = 256) : events_(capacity) {}
  void add(const NodeEvent& e) noexcept {
    if (n_ < events_.size())
      events_[n_++] = e;
    else
      ++dropped_;
  }
  std::span<const NodeEvent> events() const noexcept { return {events_.data(), n_}; }
  std::uint64_t dropped() const noexcept { return dropped_; }

 private:
  std::vector<NodeEvent> events_;
  std::size_t n_ = 0;
  std::uint64_t dropped_ = 0;
};

// ----------------------------------------------------------------------------- scenario
// `lash hil run|simulate --scenario FILE --compensation MODE` (docs/compensation.md): the slave
// emulates the E4 valve rig with the scenario's drifts, the master runs the scenario's
// compensated law. `lash closed-loop --scenario` on a valve scenario runs these very nodes
// (hil::BenchSimulation, schedule.hpp), so its figures and the emulation's agree bit for bit.

/// Under a scenario the valve is driven both ways and its output is a pressure difference
/// (rigs/pilot_valve_rig.hpp): the master sends a positive current as SolenoidA_Current and a
/// negative one as SolenoidB_Current (the slave applies A − B), and the slave's sensor sends the
/// rig's bias-corrected pressure difference plus this zero offset as PilotPressure_Duty (the
/// DBC's 5..95 % carries −48..4346 kPa: the difference fits as −2048..2346 kPa).
inline constexpr double kScenarioPressureZero_kPa = 2000.0;

/// The slave's plant under a scenario: the E4 valve rig (rigs/pilot_valve_rig.hpp) and its drifts.
struct RigPlant {
  rigs::PilotValveRigParams params;   ///< the rig at t = 0
  std::uint64_t seed = 1;             ///< the rig's noise seed
  /// Steps and ramps in master control steps (rigs/drift.hpp: a ramp is one segment, interpolated
  /// at each step): the command of control step m meets the rig of step m. In time order; every
  /// `before`/`after` valid.
  std::vector<rigs::DriftSegment<rigs::PilotValveRigParams>> drift;
};

/// The master's law under a scenario:
///   u(m) = PID(r − y)(m) + feedforward·r(m);  i(m) = clamp(DI(u(m)), command_min, command_max)
/// with DI the deadzone compensator (none/fixed/adaptive, control/adaptive_compensator.hpp),
/// whose estimator then observes (i(m), y(m)).
struct CompensatedLaw {
  PidConfig pid;                      ///< dt_s = the step
  double feedforward = 0.0;           ///< [mA/kPa]
  double command_min = -2000.0, command_max = 2000.0;  ///< [mA], inside ±the bench's current range
  DeadzoneCompensationConfig compensation;
  /// compensation.mode = oracle: the plant the slave runs (its parameters and drifts; the seed is
  /// not used). Before its step's command the master sets the rig's true edges of control step m
  /// on the inverse as magnitudes [mA] (Compensator::set_oracle): at the first law step and
  /// whenever the drifts change them. Unset in the other modes.
  std::optional<RigPlant> oracle;
};

/// The compensator's state at the end of a run (trivially copyable: it crosses the hand-over).
struct CompensationState {
  bool on = false;                    ///< a scenario law ran
  CompensationMode mode = CompensationMode::none;
  double right = 0.0, left = 0.0;     ///< the inverse's edges in use (left as a negative current; 0 for none) [mA]
  std::uint64_t updates = 0;          ///< samples on which the inverse's parameters changed
  std::uint64_t reguesses_right = 0, reguesses_left = 0;  ///< the estimator's guesses moved (identify/reguess.hpp)
  double guess_right = 0.0, guess_left = 0.0;  ///< the estimator's switching guesses at the end [mA]
  AdaptationEvents events;            ///< re-guesses and drift events (sample = the law's control step)
  AdaptationReason reason = AdaptationReason::nominal;
  bool estimator_identified = false;  ///< both sides identified by the estimator's verdict
  char estimator_reason[320] = {};    ///< "right: …; left: …" (truncated to fit)
};

/// The end state of any adaptive compensator (control/adaptive_compensator.hpp: the master's
/// DeadzoneCompensator, the carts' BacklashCompensator of the scenario runner): one reading for
/// every report. right/left are Compensator::in_use() (0 for mode none).
template <class Comp>
CompensationState compensation_state(const Comp& comp) noexcept {
  CompensationState c;
  c.on = true;
  c.mode = comp.config().mode;  // as calibrated (docs/xcp.md)
  const PerSide<double> used = comp.in_use();
  c.right = used.right;
  c.left = used.left;
  c.updates = comp.updates();
  c.reguesses_right = comp.adapter().reguesses(Side::right);
  c.reguesses_left = comp.adapter().reguesses(Side::left);
  c.guess_right = comp.adapter().guess(Side::right);
  c.guess_left = comp.adapter().guess(Side::left);
  c.events = comp.events();
  c.reason = comp.reason();
  c.estimator_identified = comp.adapter().identified(Side::right) && comp.adapter().identified(Side::left);
  both_sides_reason(c.estimator_reason, comp.estimator_reason(Side::right), comp.estimator_reason(Side::left));
  return c;
}

// ----------------------------------------------------------------------------- slave

struct SlaveConfig {
  PilotValveParams plant;                 ///< docs/method.md §B1 (dt_s = the step)
  std::vector<can::Frame> dto_reply;      ///< the recorded DTO frame(s), replayed on every CONNECT
  std::size_t log_capacity = 0;           ///< steps logged (preallocated; 1 with clear_step_log() per step)
  E2EConfig e2e;                          ///< plausibility, recovery and ramp settings
  std::uint32_t stale_periods = 3;        ///< steps without a plausible command → degraded
  double current_min_mA = 0.0;            ///< the current driver's range: the output is clamped to it [mA]
  double current_max_mA = 2000.0;
  std::optional<RigPlant> rig;            ///< a scenario's rig instead of `plant` (scenario section above)
};

/// One slave step.
struct SlaveStepLog {
  std::uint32_t step = 0;
  SlaveState state = SlaveState::startup;
  std::uint64_t command_counter = 0;      ///< the last accepted command's counter, unwrapped
  bool command_fresh = false;             ///< a plausible new command frame arrived for this step
  std::uint16_t dropped = 0;              ///< implausible command frames dropped in this step
  double current_mA = 0.0;                ///< applied current (after ramp and clamp)
  double pressure_kPa = 0.0;              ///< noise-free plant pressure after apply
  double measured_kPa = 0.0;              ///< sensor reading (noise, sensor code)
  std::uint16_t pilot_raw = 0;            ///< bus value sent
};

class SlaveNode {
 public:
  /// Throws std::invalid_argument on an invalid plant, an empty DTO reply or invalid E2E settings.
  SlaveNode(const BenchLayout& layout, SlaveConfig config);

  /// Handshake before the loop (not real-time): waits up to `timeout` for a CCP CONNECT,
  /// replays the DTO and returns true. timeout 0 polls what is queued.
  bool wait_connect(can::Bus& bus, std::chrono::nanoseconds timeout);
  /// One step at time now_s (log and events only). noexcept, allocation-free.
  void step(can::Bus& bus, double now_s) noexcept;

  SlaveState state() const noexcept { return state_; }
  std::span<const SlaveStepLog> log() const noexcept { return {log_.data(), n_log_}; }
  std::span<const NodeEvent> events() const noexcept { return events_.events(); }
  const SeqTracker& commands() const noexcept { return cmd_; }
  std::uint64_t frames_sent() const noexcept { return sent_; }
  std::uint64_t send_failures() const noexcept { return send_fail_; }
  std::uint64_t dto_replies() const noexcept { return dto_replies_; }
  std::uint64_t ignored_frames() const noexcept { return ignored_; }
  std::uint32_t steps() const noexcept { return step_; }
  /// Empties the step log for the next step. A node run with log_capacity = 1 calls it after
  /// handing each step's row to its log writer (node_run.hpp): constant memory. noexcept.
  void clear_step_log() noexcept { n_log_ = 0; }

 private:
  void reply_dto(can::Bus& bus) noexcept;
  void go(SlaveState to, NodeEventKind why, double now_s) noexcept;
  BenchLayout layout_;
  SlaveConfig cfg_;
  PilotValvePlant plant_;
  SeqTracker cmd_;
  InputWatch watch_;
  EventLog events_;
  SlaveState state_ = SlaveState::startup;
  double command_mA_ = 0.0;   ///< last plausible command
  double current_mA_ = 0.0;   ///< driven current
  double ramp_step_mA_ = 0.0;
  std::uint32_t step_ = 0;
  std::uint64_t sent_ = 0, send_fail_ = 0, dto_replies_ = 0, ignored_ = 0;
  std::optional<rigs::PilotValveRig> rig_;
  rigs::DriftCursor<rigs::PilotValveRigParams> drift_;
  std::vector<SlaveStepLog> log_;
  std::size_t n_log_ = 0;
};

// ----------------------------------------------------------------------------- master

struct MasterConfig {
  ControllerConfig controller;             ///< docs/method.md §B2; controller.pid.dt_s = the step
  SignalSpec reference;                    ///< r(m), m = steps since the first CONNECT reply [kPa]
  double dto_timeout_s = 2.0;              ///< no DTO by then → failed (clear error)
  std::uint32_t fault_missed_periods = 3;  ///< steps without a plausible sensor frame → safe (0 mA)
  std::uint32_t cro_retry_steps = 10;      ///< CRO repeat period while connecting / stale in safe [steps]
  std::size_t log_capacity = 0;            ///< steps logged (preallocated; 1 with clear_step_logs() per step)
  std::size_t bus_log_capacity = 0;        ///< frames logged (preallocated); 0 → 4·log_capacity + 64
  E2EConfig e2e;                           ///< plausibility, recovery and ramp settings
  std::optional<CompensatedLaw> law;       ///< a scenario's law instead of `controller`'s PID + fixed offset
  /// Calibration pages to apply (the replay of a run with XCP writes, schedule.hpp): page p of
  /// control step m takes effect at the start of the step that runs control step m. In time order.
  struct CalibrationChange {
    std::int64_t control_step = 0;
    CalibrationPage page;
  };
  std::vector<CalibrationChange> calibration_schedule;
};

/// The calibration page of a master configuration before any write (the law's gains, the bench
/// controller's inverse edges, no reference offset).
CalibrationPage initial_calibration(const MasterConfig& c) noexcept;

struct MasterStepLog {
  std::uint32_t step = 0;                  ///< loop step k
  std::int64_t control_step = -1;          ///< m (−1 before the first CONNECT reply)
  MasterState state = MasterState::startup;
  double reference_kPa = 0.0;
  double measured_kPa = 0.0;               ///< decoded sensor (held when no fresh frame)
  std::uint16_t sensor_counter = 0;
  bool sensor_fresh = false;               ///< a plausible new sensor frame arrived for this step
  std::int64_t sensor_seq = -1;            ///< the sensor frame used: its counter unwrapped (= the slave step
                                           ///< that sent it); −1 = none new, the value is held (schedule.hpp)
  std::uint16_t dropped = 0;               ///< implausible sensor frames dropped in this step
  double current_mA = 0.0;                 ///< commanded (before bus quantisation)
  double integrator_mA = 0.0;              ///< the PID's integrator state after the step [mA]
  std::uint16_t command_counter = 0;
  bool command_sent = false;
  double inverse_right_mA = 0.0;           ///< scenario law: the deadzone inverse's edges after the step [mA]
  double inverse_left_mA = 0.0;            ///< (left as a negative current; 0 without a scenario or for none)
  CalibrationPage calibration;             ///< the calibration page the step ran with (calibration.hpp)
};

class MasterNode {
 public:
  /// Throws std::invalid_argument on an invalid controller, reference or E2E settings.
  MasterNode(const BenchLayout& layout, MasterConfig config);

  /// One step at time now_s (log only). Returns false once the node has failed
  /// (no DTO within dto_timeout_s). noexcept, allocation-free.
  bool step(can::Bus& bus, double now_s) noexcept;

  MasterState state() const noexcept { return state_; }
  /// Control steps run so far (steps since the first CONNECT reply, fault steps included).
  std::int64_t control_steps() const noexcept { return m_ + 1; }
  std::span<const MasterStepLog> log() const noexcept { return {log_.data(), n_log_}; }
  std::span<const NodeEvent> events() const noexcept { return events_.events(); }
  std::span<const LoggedFrame> bus_log() const noexcept { return {bus_log_.data(), n_bus_log_}; }
  std::uint64_t bus_log_dropped() const noexcept { return bus_log_dropped_; }
  const SeqTracker& sensors() const noexcept { return sens_; }
  std::uint64_t frames_sent() const noexcept { return sent_; }
  std::uint64_t send_failures() const noexcept { return send_fail_; }
  std::uint64_t ignored_frames() const noexcept { return ignored_; }
  double handshake_s() const noexcept { return handshake_s_; }  ///< first CRO → DTO [s]; −1 before
  /// The scenario law's compensator at this point (on = false without a scenario).
  CompensationState compensation() const noexcept;
  /// Connects the step to an XCP thread (hil/xcp_server.hpp): each step first takes the newest
  /// calibration page the thread handed over, and ends by pushing its measurements. nullptr
  /// detaches. Not real-time safe (call before the loop).
  void attach(XcpLink* link) noexcept { link_ = link; }
  /// The loop's figures for the XCP measurements (console status): TET of the previous step,
  /// wake-up latency of this one [µs], overruns so far. Real-time safe (three stores).
  void set_loop_figures(double tet_prev_us, double wake_us, double overruns) noexcept {
    loop_tet_us_ = tet_prev_us, loop_wake_us_ = wake_us, loop_overruns_ = overruns;
  }
  const CalibrationPage& calibration() const noexcept { return cal_; }
  /// Empties the step log and the bus log for the next step. A node run with log_capacity = 1
  /// and bus_log_capacity = kStepFrames calls it after handing each step's row and frames to
  /// its log writer (node_run.hpp): constant memory. noexcept.
  void clear_step_logs() noexcept {
    n_log_ = 0;
    n_bus_log_ = 0;
  }
  /// Calibration writes that took effect, one event per changed object.
  std::span<const CalibrationEvent> calibration_events() const noexcept { return {cal_events_.data(), n_cal_events_}; }

 private:
  void go(MasterState to, NodeEventKind why, double now_s) noexcept;
  void send(can::Bus& bus, const can::Frame& f, double now_s) noexcept;
  void record(const can::Frame& f, bool sent) noexcept;
  void control(can::Bus& bus, double r, double now_s) noexcept;
  void control_states(can::Bus& bus, double r, double now_s) noexcept;
  double law(double r, double y) noexcept;
  void reset_law() noexcept;
  void apply_calibration(const CalibrationPage& p, double now_s) noexcept;
  BenchLayout layout_;
  MasterConfig cfg_;
  ClosedLoopDiscrete controller_;
  std::optional<Pid> pid_;                     ///< scenario law
  std::optional<DeadzoneCompensator> comp_;    ///< scenario law
  Signal reference_;
  MasterState state_ = MasterState::startup;
  SeqTracker sens_;
  InputWatch watch_;
  EventLog events_;
  bool fresh_ = false, bad_ = false;
  bool law_ran_ = false;  ///< the scenario law ran in this control step (else: a gap for the compensator)
  std::uint32_t k_ = 0;
  std::int64_t m_ = -1;
  std::uint32_t last_cro_k_ = 0;
  bool cro_sent_ = false;
  std::uint8_t cro_ctr_ = 0;
  double first_cro_s_ = -1.0, handshake_s_ = -1.0;
  double measured_kPa_ = 0.0;
  std::uint16_t sensor_counter_ = 0;
  double current_mA_ = 0.0;
  double ramp_step_mA_ = 0.0;
  std::uint16_t cmd_counter_ = 0;
  std::uint64_t sent_ = 0, send_fail_ = 0, ignored_ = 0;
  std::vector<MasterStepLog> log_;
  std::size_t n_log_ = 0;
  std::vector<LoggedFrame> bus_log_;
  std::size_t n_bus_log_ = 0;
  std::uint64_t bus_log_dropped_ = 0;
  CalibrationPage cal_;
  XcpLink* link_ = nullptr;
  double loop_tet_us_ = 0.0, loop_wake_us_ = 0.0, loop_overruns_ = 0.0;  ///< set_loop_figures (console)
  std::size_t next_change_ = 0;
  rigs::DriftCursor<rigs::PilotValveRigParams> oracle_;  ///< scenario law, oracle: the plant's drifts
  bool oracle_started_ = false;  ///< the initial edges were set
  std::vector<CalibrationEvent> cal_events_;
  std::size_t n_cal_events_ = 0;
};

}  // namespace lash::hil
