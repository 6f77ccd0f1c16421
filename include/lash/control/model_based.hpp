#pragma once
/// @file model_based.hpp
/// Beyond the thesis: a controller designed from an identified first-order +
/// input-deadzone model (K, τ, c), and the closed loop run on the virtual pilot-valve
/// rig of rigs/pilot_valve_rig.hpp (second pole, pressure-dependent τ, two solenoids).
///
/// Design (IMC / pole-zero cancellation): PI with Kp = τ/(K·λ), Ki = 1/(K·λ), so the
/// loop gain is 1/(λs) and the nominal closed loop 1/(λs + 1), whose 90 % rise time is
/// λ·ln 10 — λ is chosen from the rise target; deadzone inverse offset = ĉ (the estimate
/// itself, times `dz_fraction`); clamp anti-windup against the 0–2000 mA driver range.
/// The model comes either from the online input-deadzone RLS estimator of
/// identify/estimators.hpp (thesis eq. 17–22) fed with an excitation run on the rig,
/// or from the offline step fit (identify/step_fit.hpp). Not real-time code, except
/// the controller it returns (ClosedLoopDiscrete).
#include <cstdint>

#include "lash/control/closed_loop.hpp"
#include "lash/rigs/pilot_valve_rig.hpp"

namespace lash {

struct FirstOrderDeadzoneModel {
  double gain_kPa_per_mA = 0.0;  ///< K
  double tau_s = 0.0;            ///< τ
  double deadzone_mA = 0.0;      ///< c (right side)
};

/// IMC PI design for a 90 % rise target; anti-windup clamp; offset = dz_fraction·ĉ.
ControllerConfig design_from_model(const FirstOrderDeadzoneModel& m, double rise_target_s, double dt_s,
                                   double dz_fraction = 1.0);

/// design_from_model with λ adjusted (bisection on the design rise) so that the noise-free
/// discrete closed loop of the *identified model* (B1 structure with K, τ, c and `bias_kPa`)
/// reaches the 90 % rise target on `test`. Uses only the model, never the rig.
ControllerConfig design_for_rise(const FirstOrderDeadzoneModel& m, double bias_kPa, double rise_target_s,
                                 double dt_s, const StepTest& test, double dz_fraction = 1.0);

/// Online identification on the rig: a seeded staircase of currents (above and below the
/// deadzone, `duration_s` long) drives the rig open loop while the input-deadzone RLS
/// estimator (λ = 0.995, switching guess c_r* = `deadzone_guess_mA`) runs sample by sample.
/// Returns K = b1/(1 + a1), τ = −T/ln(−a1), c = −e/b1 of the right side at the end.
/// Throws lash::RunError if the estimator has not identified the right side.
FirstOrderDeadzoneModel identify_online_on_rig(const rigs::PilotValveRigParams& rig, double dt_s,
                                               std::uint64_t seed, double duration_s = 20.0,
                                               double deadzone_guess_mA = 350.0);

/// Step test of `controller` around the virtual rig. The controller sees the absolute
/// pressure (rig output + the rig's bias estimate), as the bench sensor reports it,
/// so the StepTest of closed_loop.hpp means the same thing as on the B1 model.
/// Metrics on the rig's noise-free pressure + bias.
StepResult run_step_on_rig(const rigs::PilotValveRigParams& rig, const ControllerConfig& controller,
                           const StepTest& test, std::uint64_t seed);

}  // namespace lash
