#pragma once
/// @file settings.hpp
/// Node settings of the bench (config/hil/bench.toml): DBC, recorded CCP reply,
/// bus address, step, plant (docs/method.md §B1) and controller (docs/method.md §B2) parameters, master
/// fault handling; and the `KIND:key=value,…` reference syntax. Not real-time safe.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "lash/can/frame.hpp"
#include "lash/control/controller.hpp"
#include "lash/hil/bench_layout.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/rigs/pilot_valve_model.hpp"
#include "lash/signals/signal.hpp"

namespace lash::hil {

/// A closed-loop scenario on the bench (`--scenario FILE --compensation MODE`, docs/compensation.md):
/// the slave's rig and drifts, the master's law and reference, and what the report scores.
/// Built from a scenario file by experiments::apply_to_bench.
struct BenchScenario {
  std::string file;
  CompensationMode mode = CompensationMode::adaptive;
  RigPlant plant;
  CompensatedLaw law;
  SignalSpec reference;                    ///< r(m) [kPa] (replaces --reference)
  double duration_s = 0.0;                 ///< the scenario's duration [s]
  double score_t0_s = 0.0, score_t1_s = 0.0;  ///< score window [s]
  double first_drift_s = -1.0;             ///< time of the first drift [s]; −1 = none
};

struct BenchSettings {
  std::filesystem::path dbc_file;          ///< relative paths in the file are relative to the file
  std::filesystem::path dto_log;           ///< candump -L log with the recorded CONNECT exchange
  std::string bus = "udp:239.74.163.2:43113";
  double step_s = 0.005;                   ///< T [s]
  PilotValveParams plant;                  ///< plant.dt_s = step_s
  ControllerConfig controller;             ///< controller.pid.dt_s = step_s
  double dto_timeout_s = 2.0;
  std::uint32_t fault_missed_periods = 3;
  std::uint32_t cro_retry_steps = 10;
  std::vector<std::string> warnings;       ///< deprecated keys read (the CLI prints them)
  std::optional<BenchScenario> scenario;   ///< set by --scenario: the nodes run it instead of plant/controller
  /// Sets step_s in plant and controller (after a --step-ms override).
  void set_step(double step_s_new);
};

/// Loads and validates a settings file; every error names file, line and key (lash::InputError).
BenchSettings load_bench_settings(const std::filesystem::path& file);
/// The shipped settings: <source dir>/config/hil/bench.toml.
std::filesystem::path default_settings_path(const std::string& source_dir);

/// The DTO frame(s) of a recorded CONNECT exchange: every frame with the DTO identifier
/// that follows the first CRO CONNECT in the log. Throws InputError naming the log when
/// there is none.
std::vector<can::Frame> load_dto_reply(const std::filesystem::path& log, const BenchLayout& layout);

/// Parses a reference: `KIND[:key=value,…]`, KIND ∈ step, square, sine, triangle, random
/// (randomized), constant. Keys: amplitude, offset, frequency [rad/s] or frequency_hz, phase
/// [rad], variance, tau, seed; step: from, to, time [s]. Values in kPa. Throws InputError
/// (field `option`) on a bad spec.
SignalSpec parse_reference(const std::string& text, const std::string& option = "--reference");

}  // namespace lash::hil
