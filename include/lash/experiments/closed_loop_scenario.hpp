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
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "lash/control/adaptive_compensator.hpp"
#include "lash/control/pid.hpp"
#include "lash/hil/report.hpp"
#include "lash/hil/schedule.hpp"
#include "lash/hil/settings.hpp"
#include "lash/rigs/rig.hpp"
#include "lash/signals/signal.hpp"

namespace lash::experiments {

/// One parameter change of the rig: a step at `at_s` (ramp_s = 0) or a linear ramp from the value
/// before to `value` over [at_s, at_s + ramp_s] (wear), moving once per sample.
struct Drift {
  double at_s = 0.0;         ///< [s]
  double ramp_s = 0.0;       ///< [s]; 0 = a step
  std::string param;         ///< a `[rig_params]` key
  double value = 0.0;        ///< its new value [the key's unit]
  rigs::RigConfig before;    ///< the rig's parameters before at_s (earlier drifts included)
  rigs::RigConfig after;     ///< the rig's parameters from at_s + ramp_s on (earlier drifts included)
};


struct ClosedLoopScenario {
  std::string file;                  ///< where it was read from ("" = built in code)
  rigs::RigKind rig = rigs::RigKind::pilot_valve;
  double dt_s = 0.005;               ///< sample period T [s]
  double duration_s = 40.0;          ///< [s]
  std::uint64_t seed = 1;            ///< rig noise seed
  rigs::RigConfig rig_config;        ///< the rig at t = 0
  std::vector<Drift> drift;          ///< in time order (a drift starts after the previous one ended)
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
  ReguessSettings reguess;           ///< [compensation] reguess = true|false (identify/reguess.hpp)
  double score_t0_s = 0.0, score_t1_s = 0.0;  ///< score window [s]
};

/// The rig's parameters at sample k of a run: the drifts applied, a ramp interpolated linearly
/// per sample (f = (k − k0)/n, k0 = round(at_s/dt_s), n = round(ramp_s/dt_s); f = 1 gives the
/// drift's value exactly; rigs::lerp). O(number of drifts); the runs walk the same values with a
/// rigs::DriftCursor.
rigs::RigConfig rig_config_at(const ClosedLoopScenario& s, std::int64_t k);

/// Reads a scenario TOML (keys in docs/compensation.md). Throws InputError (file:line:key).
ClosedLoopScenario load_closed_loop_scenario(const std::filesystem::path& path);

/// One sample of a scenario run (a row of `lash closed-loop --scenario -o`).
struct ClosedLoopScenarioRow {
  double t_s = 0.0;
  double reference = 0.0, output = 0.0, command = 0.0;  ///< r, y [rig output unit]; the rig input [mA or V]
  double param_right = 0.0, param_left = 0.0;           ///< the inverse's parameters in use
  double drive = 0.0;  ///< coupled carts: the motor cart's position w [m] (0 for the valve)
};
using ScenarioRowFn = std::function<void(const ClosedLoopScenarioRow&)>;

struct ClosedLoopScenarioResult {
  CompensationMode mode = CompensationMode::none;
  double rms_error = 0.0;      ///< RMS of r − y over the score window [rig output unit]
  double max_abs_error = 0.0;  ///< max |r − y| over the score window [rig output unit]
  double final_right = 0.0, final_left = 0.0;  ///< inverse parameters in use at the end (0 for none)
  std::uint64_t updates = 0;   ///< samples on which the inverse's parameters changed
  /// Re-guesses of the estimator's switching guesses (identify/reguess.hpp) per side, and the
  /// guesses at the end [v unit of the estimator: valve mA, carts m (shifted input)].
  std::uint64_t reguesses_right = 0, reguesses_left = 0;
  double guess_right = 0.0, guess_left = 0.0;
  /// Re-guesses and drift events of the adaptive compensator (t = sample × dt_s).
  AdaptationEvents events;
  AdaptationReason reason = AdaptationReason::nominal;
  std::string estimator_reason;  ///< the estimator's side of the verdict
  bool estimator_identified = false;
  std::size_t samples = 0;       ///< samples run
  /// pilot_valve: the scenario's figures of the bench's report (tracking over the window and
  /// before/after the first drift; the runner computes them for both rigs, the carts do not report them).
  std::optional<hil::ScenarioFigures> bench;
};

/// The bench settings `b` with this scenario (`lash hil run|simulate --scenario`): the slave's
/// rig and drifts, the master's law, reference and step. The bench is the pilot valve (each
/// solenoid 0..2000 mA, hil/nodes.hpp kScenarioPressureZero_kPa): a coupled_carts scenario, a
/// [controller] min below −2000 or max above 2000 mA is refused (InputError naming file and key).
void apply_to_bench(const ClosedLoopScenario& s, CompensationMode mode, hil::BenchSettings& b);

/// Runs the scenario with the given compensation: one loop for both rigs (each control step the
/// rig's law, plant and sensor, then the scoring and the trace row; the compensator's state at
/// the end). A pilot_valve scenario runs on the bench's nodes (hil::BenchSimulation with
/// apply_to_bench's settings and the ideal schedule): the same step code, timing and bus
/// quantisation as `lash hil run --scenario`, so the figures agree bit for bit; coupled carts run
/// in process. Throws std::invalid_argument on an invalid configuration (a scenario from
/// load_closed_loop_scenario is valid).
///
/// Memory O(1) in the duration for both rigs: `row` (when set) gets every sample as it is
/// produced, the figures are accumulated on the way (hil::ScenarioScore), a drift ramp is
/// interpolated at each step (rigs/drift.hpp), and the bench's nodes keep one row each.
ClosedLoopScenarioResult run_closed_loop_scenario(const ClosedLoopScenario& s, CompensationMode mode,
                                                  const ScenarioRowFn& row = {});

}  // namespace lash::experiments
