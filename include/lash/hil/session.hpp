#pragma once
/// @file session.hpp
/// `lash hil run`: the slave and the master as two processes on a bus in a private network
/// namespace, supervised until the master is done, and the run report. Each node is started
/// from a launch file (launch.hpp: the node's configuration as data, written by the session)
/// with the command the face gives (node_command); the session writes no command line.
/// By concern: process control (process.hpp, private), the hand-over (handover.hpp: statistics
/// in a memory file, logs read back from disk), the report (report.hpp).
///
/// Supervision:
///   - a stop signal to the session (SIGTERM, SIGINT, SIGHUP; see stop_signal()) is forwarded
///     to both nodes, which stop at a step boundary and hand over complete logs; the report is
///     written and marked interrupted; the namespace goes away with the last process in it;
///   - a node that dies is reported (exit status or signal, and when); with restart_slave a
///     dead slave is started again (a watchdog) and the report gives the gap;
///   - the nodes die with the session (PR_SET_PDEATHSIG) if it is killed outright;
///   - the files a run owns are removed from the output directory before it starts, so a
///     file from an earlier run never sits beside new logs.
/// Each node hands its run's statistics to the session through an inherited memory file
/// (handover.hpp); its CSV logs are streamed by the node itself while it runs (log_writer.hpp)
/// and read back by the session, also when the node was killed (the report says what it
/// recovered).
/// Not real-time code; the session process itself runs no loop.
#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "lash/hil/node_run.hpp"
#include "lash/hil/report.hpp"
#include "lash/hil/settings.hpp"

namespace lash::hil {

struct SessionOptions {
  std::filesystem::path config;          ///< settings file the nodes load
  BenchSettings settings;                ///< loaded from `config` (plus overrides below)
  LoopOptions loop;                      ///< both nodes; slave_cpu overrides the slave's CPU
  int slave_cpu = -1;                    ///< −1: as loop.cpu
  double duration_s = 5.0;               ///< control time [s]
  std::string reference = "step:from=500,to=1500,time=1";
  bool xcp = true;                        ///< the master's XCP slave (`--xcp off` disables it)
  std::filesystem::path out_dir = "hil-out";
  bool isolate = true;                   ///< private network namespace (else the host's network)
  bool restart_slave = false;            ///< watchdog: start a dead slave again
  /// The command that runs a node from a launch file (launch.hpp), given by the face: [0] is
  /// the executable; the session appends the launch file's path. E.g. {"/proc/self/exe", "hil",
  /// "node"} for the lash executable.
  std::vector<std::string> node_command;
  /// The closed-loop scenario both nodes load themselves (`settings.scenario` must hold the same
  /// for the report), and its compensation mode; "" = none.
  std::filesystem::path scenario;
  std::string compensation;
  /// Controller overrides both nodes apply after the settings' controller: ("table.key" of
  /// controller_fields(), value text).
  std::vector<std::pair<std::string, std::string>> controller;
  /// Called once both nodes were started, in the session's network namespace (the private one
  /// when isolated), e.g. to start a tool that joins the bus (the console's XCP client).
  std::function<void()> on_nodes_started;
  /// Checks what can be checked before any process starts (reference, duration, loop options,
  /// output directory writable, a node command); throws InputError naming the field
  /// (`duration_s`, `loop.fifo`, `out_dir`, …).
  void validate() const;
};

/// The files a run writes into out_dir (removed before a run starts).
std::vector<std::string> session_files();

/// The signal number that stopped the session (0 = none): set it from a signal handler.
std::atomic<int>& stop_signal() noexcept;
/// Installs handlers for SIGTERM, SIGINT and SIGHUP that set stop_signal() (no SA_RESTART).
void install_session_signal_handlers();

class Session {
 public:
  explicit Session(SessionOptions options);
  /// Runs the session to its end and returns the report (also written to out_dir/report.json).
  /// `progress` gets one line per notable event (a node died, restarted, a signal).
  RunReport run(const std::function<void(const std::string&)>& progress = {});

 private:
  SessionOptions o_;
};

}  // namespace lash::hil
