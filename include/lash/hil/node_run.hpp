#pragma once
/// @file node_run.hpp
/// One node of the bench as a process runs it (`lash hil slave`, `lash hil master`, and the
/// children of `lash hil run`): settings → node → emulated CAN controller on a bus → the
/// periodic loop, its logs streamed to disk (log_writer.hpp), and what a run ends with
/// (statistics, counters, events). The option checks live here too, so that every face of the
/// library refuses the same values with the same message (naming the options' fields) before
/// any work. Its neighbours by concern: handover.hpp (a run from the node process to its
/// session), node_report.hpp (a run's files and statistics JSON), launch.hpp (a node's
/// configuration as data, how a session starts it). Not real-time code, except the loops it runs.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "lash/can/controller_bus.hpp"
#include "lash/hil/e2e.hpp"
#include "lash/hil/log_writer.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/hil/settings.hpp"
#include "lash/rt/periodic.hpp"

namespace lash::hil {

/// Limits of the real-time options (documented in `--help`).
inline constexpr double kMinStepMs = 0.1;     ///< shortest step the loop is let run [ms] (see docs/hil.md)
inline constexpr double kMaxStepMs = 1000.0;  ///< longest step [ms]
/// Most steps one run may take (a node streams its logs: its memory does not depend on it; the
/// percentile tails of its statistics hold steps/100 values, 0.6 MB at this limit).
inline constexpr std::size_t kMaxSteps = 20'000'000;

/// Real-time options shared by the nodes and `lash hil latency`.
struct LoopOptions {
  double step_s = 0.005;                       ///< T [s]
  int fifo = 0;                                ///< SCHED_FIFO priority 1–99; 0 = default scheduler
  int cpu = -1;                                ///< pin to this CPU; −1 = no pinning
  double spin_us = 0.0;                        ///< busy-wait this long before each release [µs]
  bool lock_memory = false;                    ///< mlockall()
  rt::OverrunPolicy policy = rt::OverrunPolicy::tolerate;
  std::size_t max_overruns = 10;               ///< policy stop: consecutive overruns before stopping
  bool hold_dma_latency = true;                ///< hold /dev/cpu_dma_latency at 0 µs while the loop runs
  /// Throws InputError naming the field (`loop.fifo`, `loop.step_s`, …) for a value out of its
  /// range (a face maps the field to its option in its message).
  void validate() const;
};

/// Parses `tolerate` / `stop`; throws InputError(field `loop.policy`) otherwise.
rt::OverrunPolicy parse_overrun_policy(const std::string& text);
/// Steps of a run of `duration_s` at `step_s`: ≥ 1, and refused (InputError naming `field`)
/// when not finite, ≤ 0 or above kMaxSteps.
std::size_t steps_for(double duration_s, double step_s, const std::string& field);
/// The loop configuration of `steps` steps (options validated first).
rt::LoopConfig make_loop_config(const LoopOptions& o, std::size_t steps);

/// The nodes' CAN controller: reception may take a fifth of the step, however hard the bus
/// is flooded (a babbling node); what is left waits on the wire for the next step.
can::ControllerConfig node_controller_config(std::int64_t period_ns);
/// Opens the node's bus with its acceptance filters (master: sensors + DTO; slave: command + CRO).
std::unique_ptr<can::Bus> open_node_bus(const std::string& address, const BenchLayout& layout, bool master);

/// Built once from the settings (the simulation and the slave node share it).
SlaveConfig slave_config(const BenchSettings& s, const BenchLayout& layout, std::size_t log_capacity = 0);
/// reference: `KIND:key=value,…` (parse_reference); dto_timeout_s ≤ 0 → the settings' value.
MasterConfig master_config(const BenchSettings& s, const std::string& reference, double dto_timeout_s = 0.0,
                           std::size_t log_capacity = 0);

/// Frame counters of one node at the end of its run. received/accepted/late/lost/resyncs and
/// the drops are those of the node's input message (SeqTracker, e2e.hpp); duplicates =
/// dropped_by_reason[Drop::repeated].
struct FrameStats {
  std::uint64_t sent = 0, received = 0, accepted = 0, late = 0, lost = 0, duplicates = 0, resyncs = 0, ignored = 0,
                send_failures = 0, bus_filtered = 0, bus_dropped = 0, bus_log_dropped = 0;
  std::uint64_t dropped = 0;                                ///< implausible frames dropped, all reasons
  std::array<std::uint64_t, kDropReasons> dropped_by_reason{};  ///< indexed by Drop
};

/// What a node's run ends with, apart from its per-step logs (trivially copyable).
struct NodeStats {
  rt::RunResult result;
  std::int64_t period_ns = 0;
  double epoch_s = 0.0;          ///< CLOCK_REALTIME of the loop's r_0 [s]
  FrameStats frames;
  can::ControllerStats controller;
  bool dma_latency_held = false; ///< /dev/cpu_dma_latency was held at 0 during the loop
  /// Loop statistics over every step [µs] (the log writer's, log_writer.hpp: the records are
  /// not kept in memory).
  rt::Summary tet_us, io_us, cycle_us, wake_latency_us;
  LogStats logs;                 ///< what the log writer wrote, and the items a full ring refused
  long peak_rss_kB = -1;         ///< the node process's peak resident set at the end of its run [kB] (getrusage)
  NodeState state = NodeState::startup;  ///< the safe-state machine's state at the end (nodes.hpp)
  // master only
  std::int64_t control_steps = 0;
  double handshake_s = -1.0;
  CompensationState compensation;  ///< the scenario law's compensator at the end (on = false without one)
  bool xcp = false;                ///< the XCP slave ran (xcp_server.hpp)
  std::uint64_t xcp_commands = 0, xcp_errors = 0, xcp_dtos = 0, xcp_samples_lost = 0, xcp_pages = 0;
  // slave only
  bool connected = false;
  std::uint64_t dto_replies = 0;
  std::uint64_t seed = 0;
};

/// The loop's side of a run: per-step records and overruns, settings warnings.
struct LoopTrace {
  std::vector<rt::StepRecord> records;
  std::vector<rt::OverrunEvent> overruns;
  std::vector<std::string> warnings;
};

struct SlaveRun {
  NodeStats stats;
  LoopTrace loop;
  std::vector<SlaveStepLog> log;
  std::vector<NodeEvent> events;     ///< the safe-state machine's transitions
};

struct MasterRun {
  NodeStats stats;
  LoopTrace loop;
  std::vector<MasterStepLog> log;
  std::vector<NodeEvent> events;     ///< the safe-state machine's transitions and the handshake
  std::vector<LoggedFrame> bus_log;  ///< timestamps as the node saw them (see write_bus_log)
  std::vector<CalibrationEvent> calibration;  ///< XCP writes that took effect (calibration.hpp)
};

struct SlaveRunOptions {
  LoopOptions loop;
  LogPaths logs;                    ///< slave.csv, slave.events.csv (streamed while the node runs)
  double duration_s = 600.0;        ///< longest run (log size) [s]
  double connect_timeout_s = 0.0;   ///< 0 = wait for CONNECT until stopped
};

struct MasterRunOptions {
  LoopOptions loop;
  LogPaths logs;                    ///< master.csv, master.events.csv, master_bus.log (streamed)
  double duration_s = 10.0;         ///< control time after the handshake [s]
  std::string reference = "step:from=500,to=1500,time=1";
  double dto_timeout_s = 0.0;       ///< 0 = from the settings
  bool xcp = true;                  ///< run the XCP-on-CAN slave (`--xcp on|off`, docs/xcp.md)
};

/// Runs the slave: waits for a CCP CONNECT (polling `stop`), then steps until `stop`, the
/// duration or an overrun stop. `on_ready(address)` is called once the bus is open.
/// Both runs stream their logs to o.logs while they run (log_writer.hpp): the returned run's
/// `log` (and the master's `bus_log`) are empty, its loop records too; the statistics are in
/// `stats`. A node killed outright leaves its logs on disk up to the last flush.
SlaveRun run_slave_node(const BenchSettings& s, const SlaveRunOptions& o, const std::atomic<bool>& stop,
                        const std::function<void(const std::string&)>& on_ready = {});
/// Runs the master: CONNECT, then `duration_s` of control (or until `stop`).
MasterRun run_master_node(const BenchSettings& s, const MasterRunOptions& o, const std::atomic<bool>& stop);

/// The flag a node's loop stops on, and handlers for SIGINT, SIGTERM and SIGHUP that set it
/// (no SA_RESTART: sleeps and blocking receives return at once). Not real-time safe.
const std::atomic<bool>& node_stop_flag() noexcept;
void install_node_signal_handlers();

}  // namespace lash::hil

// The hand-over of a run (write_run / read_run, the logs read back) lived in this header before
// it was split by concern; it is included for the code that still finds it here.
#include "lash/hil/handover.hpp"  // IWYU pragma: export
