#pragma once
/// @file closed_loop_scenario.hpp
/// Closed-loop scenarios with drifting plants (docs/compensation.md): a virtual rig under a
/// PID with no, a fixed or an adaptive inverse, a reference, parameter drifts at given times,
/// and tracking figures over a score window.
///
///  - `pilot_valve`: pressure control. e = r − y [kPa]; u = PID(e) [mA];
///    u = PID(e) + k_ff·r; i = sat(DI(u)) [mA] (DI: the deadzone inverse, none/fixed/adaptive); y = rig(i).
///    The adaptive DI is fed by an input-deadzone estimator on (i, y).
///  - `coupled_carts`: position control of the free cart through the clearance. The reference
///    r is the free cart's desired position [m]; the motor cart's target is w* = BI(r) (the
///    backlash inverse); v = sat(PID(w* − w) + k_ff·(w* − w*(k−1))/T) [V] with w the motor cart's position; y = the
///    free cart's position. The adaptive BI is fed by the gap estimator on (w, y).
///
/// Loading is not real-time safe; errors are lash::InputError naming file, line and key.
/// The run loop calls only noexcept, allocation-free step functions per sample.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "lash/control/adaptive_compensator.hpp"
#include "lash/control/pid.hpp"
#include "lash/rigs/rig.hpp"
#include "lash/signals/signal.hpp"

namespace lash::experiments {

/// One parameter change of the rig at `at_s` (the full rig configuration after it).
struct Drift {
  double at_s = 0.0;         ///< [s]
  std::string param;         ///< a `[rig_params]` key
  double value = 0.0;        ///< its new value [the key's unit]
  rigs::RigConfig after;     ///< the rig's parameters from at_s on (earlier drifts included)
};

struct ClosedLoopScenario {
  std::string file;                  ///< where it was read from ("" = built in code)
  rigs::RigKind rig = rigs::RigKind::pilot_valve;
  double dt_s = 0.005;               ///< sample period T [s]
  double duration_s = 40.0;          ///< [s]
  std::uint64_t seed = 1;            ///< rig noise seed
  rigs::RigConfig rig_config;        ///< the rig at t = 0
  std::vector<Drift> drift;          ///< in time order
  SignalSpec reference;              ///< r [kPa or m]
  PidConfig pid;                     ///< the controller (dt = dt_s)
  /// Reference feedforward u_ff = feedforward·r added to the PID output (a 2-DOF loop: the
  /// inverse is what lets a feedforward through the deadzone) [rig input unit / output unit].
  double feedforward = 0.0;
  double command_min = -2000.0;      ///< saturation of the rig input [mA or V]
  double command_max = 2000.0;
  /// Nominal inverse parameters in the rig's input units (valve: deadzone edges [mA], carts:
  /// deadband half-widths [m]); the smoothing band goes in DeadzoneInverseParams/BacklashInverseParams.
  DeadzoneInverseParams deadzone;    ///< valve
  BacklashInverseParams backlash;    ///< carts
  EstimatorConfig estimator;         ///< valve: the adaptive compensator's input-deadzone estimator
  BacklashEstimatorConfig backlash_estimator;  ///< carts: the adaptive compensator's deadzone-deadband estimator
  AdaptationSettings adaptation;
  double score_t0_s = 0.0, score_t1_s = 0.0;  ///< score window [s]
};

/// Reads a scenario TOML (keys in docs/compensation.md). Throws InputError (file:line:key).
ClosedLoopScenario load_closed_loop_scenario(const std::filesystem::path& path);

struct ClosedLoopScenarioTrace {
  std::vector<double> t_s, reference, output, command, param_right, param_left;
  std::vector<double> drive;  ///< coupled carts: the motor cart's position w [m] (empty for the valve)
};

struct ClosedLoopScenarioResult {
  CompensationMode mode = CompensationMode::none;
  double rms_error = 0.0;      ///< RMS of r − y over the score window [rig output unit]
  double max_abs_error = 0.0;  ///< max |r − y| over the score window [rig output unit]
  double final_right = 0.0, final_left = 0.0;  ///< inverse parameters in use at the end (0 for none)
  std::uint64_t updates = 0;   ///< samples on which the inverse's parameters changed
  AdaptationReason reason = AdaptationReason::nominal;
  std::string estimator_reason;  ///< the estimator's side of the verdict
  bool estimator_identified = false;
  ClosedLoopScenarioTrace trace;
};

/// Runs the scenario with the given compensation. Throws std::invalid_argument on an invalid
/// configuration (a scenario from load_closed_loop_scenario is valid).
ClosedLoopScenarioResult run_closed_loop_scenario(const ClosedLoopScenario& s, CompensationMode mode);

}  // namespace lash::experiments
