#pragma once
/// @file nodes.hpp
/// The two ECUs of the hydraulic bench (SPEC B, thesis paper 2 §2.7.3):
///
/// - SlaveNode ("Slave and Plant Emulator", Figs 2.17–2.19): answers the master's CCP
///   CONNECT by replaying a recorded DTO (it does not interpret it); each step it
///   reads the newest current command, steps the pilot-valve plant of SPEC B1 and
///   sends the sensor frame (supply pressure sent as 0).
/// - MasterNode ("Master Emulator", Fig 2.16): sends CRO until a DTO arrives, then
///   each step runs the SPEC B2 controller (discrete PID → deadzone inverse →
///   saturation 0–2000 mA) on the newest sensor frame and sends the command frame.
///   Sensor frames missing for N periods (default 3) → 0 mA safe state, logged;
///   control resumes when frames return.
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
#include <span>
#include <vector>

#include "lash/can/bus.hpp"
#include "lash/control/controller.hpp"
#include "lash/hil/bench_layout.hpp"
#include "lash/rigs/pilot_valve_model.hpp"
#include "lash/signals/signal.hpp"

namespace lash::hil {

/// Most frames a node reads from the bus in one step; a babbling node cannot stretch a step further.
inline constexpr std::size_t kMaxDrain = 64;

/// Sequence-counter bookkeeping of one cyclic message (SPEC B3 heartbeat).
/// late: frames that arrived after the step that should have used them (more than one
/// new frame in a step); lost: counter values never seen; resyncs: counter jumps ≥ 1024
/// or backwards (a restarted peer).
struct SeqTracker {
  bool have = false;
  std::uint16_t last = 0;
  std::uint64_t received = 0, late = 0, lost = 0, duplicates = 0, resyncs = 0;
  std::uint32_t in_step = 0;

  /// Returns true when the frame is newer than the last one seen.
  bool on_frame(std::uint16_t counter) noexcept;
  void end_step() noexcept {
    if (in_step > 1) late += in_step - 1;
    in_step = 0;
  }
  void forget() noexcept { have = false; }
};

/// A frame as a node saw it, for the candump log.
struct LoggedFrame {
  can::Frame frame;
  bool sent = false;
};

// ----------------------------------------------------------------------------- slave

struct SlaveConfig {
  PilotValveParams plant;                 ///< SPEC B1 (dt_s = the step)
  std::vector<can::Frame> dto_reply;      ///< the recorded DTO frame(s), replayed on every CONNECT
  std::size_t log_capacity = 0;           ///< steps logged (preallocated)
};

/// One slave step.
struct SlaveStepLog {
  std::uint32_t step = 0;
  std::uint16_t command_counter = 0;
  bool command_fresh = false;             ///< a new command frame arrived for this step
  double current_mA = 0.0;                ///< applied current (decoded from the bus)
  double pressure_kPa = 0.0;              ///< noise-free plant pressure after apply
  double measured_kPa = 0.0;              ///< sensor reading (noise, sensor code)
  std::uint16_t pilot_raw = 0;            ///< bus value sent
};

class SlaveNode {
 public:
  /// Throws std::invalid_argument on an invalid plant or an empty DTO reply.
  SlaveNode(const BenchLayout& layout, SlaveConfig config);

  /// Handshake before the loop (not real-time): waits up to `timeout` for a CCP CONNECT,
  /// replays the DTO and returns true. timeout 0 polls what is queued.
  bool wait_connect(can::Bus& bus, std::chrono::nanoseconds timeout);
  /// One step at time now_s (log only). noexcept, allocation-free.
  void step(can::Bus& bus, double now_s) noexcept;

  std::span<const SlaveStepLog> log() const noexcept { return {log_.data(), n_log_}; }
  const SeqTracker& commands() const noexcept { return cmd_; }
  std::uint64_t frames_sent() const noexcept { return sent_; }
  std::uint64_t send_failures() const noexcept { return send_fail_; }
  std::uint64_t dto_replies() const noexcept { return dto_replies_; }
  std::uint64_t ignored_frames() const noexcept { return ignored_; }
  std::uint32_t steps() const noexcept { return step_; }

 private:
  void reply_dto(can::Bus& bus) noexcept;
  BenchLayout layout_;
  SlaveConfig cfg_;
  PilotValvePlant plant_;
  SeqTracker cmd_;
  double current_mA_ = 0.0;
  std::uint16_t cmd_counter_ = 0;
  std::uint32_t step_ = 0;
  std::uint64_t sent_ = 0, send_fail_ = 0, dto_replies_ = 0, ignored_ = 0;
  std::vector<SlaveStepLog> log_;
  std::size_t n_log_ = 0;
};

// ----------------------------------------------------------------------------- master

enum class MasterState : std::uint8_t { connecting, running, fault, failed };
const char* to_string(MasterState s) noexcept;

enum class MasterEventKind : std::uint8_t { connect_sent, connected, sensor_timeout, sensor_resumed, dto_timeout };
const char* to_string(MasterEventKind k) noexcept;

struct MasterEvent {
  std::uint32_t step = 0;   ///< loop step k
  double t_s = 0.0;         ///< time the step ran [s]
  MasterEventKind kind = MasterEventKind::connected;
};

struct MasterConfig {
  ControllerConfig controller;             ///< SPEC B2; controller.pid.dt_s = the step
  SignalSpec reference;                    ///< r(m), m = steps since the first CONNECT reply [kPa]
  double dto_timeout_s = 2.0;              ///< no DTO by then → failed (clear error)
  std::uint32_t fault_missed_periods = 3;  ///< steps without a sensor frame → 0 mA safe state
  std::uint32_t cro_retry_steps = 10;      ///< CRO repeat period while connecting / in fault [steps]
  std::size_t log_capacity = 0;            ///< steps logged (preallocated)
  std::size_t bus_log_capacity = 0;        ///< frames logged (preallocated); 0 → 4·log_capacity + 64
};

struct MasterStepLog {
  std::uint32_t step = 0;                  ///< loop step k
  std::int64_t control_step = -1;          ///< m (−1 before the first CONNECT reply)
  MasterState state = MasterState::connecting;
  double reference_kPa = 0.0;
  double measured_kPa = 0.0;               ///< decoded sensor (held when no fresh frame)
  std::uint16_t sensor_counter = 0;
  bool sensor_fresh = false;
  double current_mA = 0.0;                 ///< commanded (before bus quantisation)
  std::uint16_t command_counter = 0;
  bool command_sent = false;
};

class MasterNode {
 public:
  /// Throws std::invalid_argument on an invalid controller or reference.
  MasterNode(const BenchLayout& layout, MasterConfig config);

  /// One step at time now_s (log only). Returns false once the node has failed
  /// (no DTO within dto_timeout_s). noexcept, allocation-free.
  bool step(can::Bus& bus, double now_s) noexcept;

  MasterState state() const noexcept { return state_; }
  /// Control steps run so far (steps since the first CONNECT reply, fault steps included).
  std::int64_t control_steps() const noexcept { return m_ + 1; }
  std::span<const MasterStepLog> log() const noexcept { return {log_.data(), n_log_}; }
  std::span<const MasterEvent> events() const noexcept { return {events_.data(), n_events_}; }
  std::span<const LoggedFrame> bus_log() const noexcept { return {bus_log_.data(), n_bus_log_}; }
  std::uint64_t bus_log_dropped() const noexcept { return bus_log_dropped_; }
  const SeqTracker& sensors() const noexcept { return sens_; }
  std::uint64_t frames_sent() const noexcept { return sent_; }
  std::uint64_t send_failures() const noexcept { return send_fail_; }
  std::uint64_t ignored_frames() const noexcept { return ignored_; }
  double handshake_s() const noexcept { return handshake_s_; }  ///< first CRO → DTO [s]; −1 before

 private:
  void event(MasterEventKind kind, double now_s) noexcept;
  void send(can::Bus& bus, const can::Frame& f, double now_s) noexcept;
  void record(const can::Frame& f, bool sent) noexcept;
  BenchLayout layout_;
  MasterConfig cfg_;
  ClosedLoopDiscrete controller_;
  Signal reference_;
  MasterState state_ = MasterState::connecting;
  SeqTracker sens_;
  std::uint32_t k_ = 0;
  std::int64_t m_ = -1;
  std::uint32_t misses_ = 0;
  std::uint32_t last_cro_k_ = 0;
  bool cro_sent_ = false;
  std::uint8_t cro_ctr_ = 0;
  double first_cro_s_ = -1.0, handshake_s_ = -1.0;
  bool have_measurement_ = false;
  double measured_kPa_ = 0.0;
  std::uint16_t sensor_counter_ = 0;
  double current_mA_ = 0.0;
  std::uint16_t cmd_counter_ = 0;
  std::uint64_t sent_ = 0, send_fail_ = 0, ignored_ = 0;
  std::vector<MasterStepLog> log_;
  std::size_t n_log_ = 0;
  std::vector<MasterEvent> events_;
  std::size_t n_events_ = 0;
  std::vector<LoggedFrame> bus_log_;
  std::size_t n_bus_log_ = 0;
  std::uint64_t bus_log_dropped_ = 0;
};

}  // namespace lash::hil
