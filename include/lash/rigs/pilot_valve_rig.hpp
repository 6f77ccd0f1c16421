#pragma once
/// @file pilot_valve_rig.hpp
/// Virtual rig of the thesis's §1.6.2 (E4): an electro-hydraulic pilot valve,
/// solenoid current in [mA] (positive → solenoid A, negative → solenoid B),
/// pilot pressure difference out [kPa]. It starts from the paper-2 model of
/// docs/method.md §B1 (deadzone 288 mA, 2.15 kPa/mA, τ = 0.07 s, bias 90.1 kPa, sensor
/// noise σ = 7.28 kPa) and adds what the thesis says the first-order model
/// ignores (§1.6.2: "a detailed pilot pressure model could easily be 3rd
/// order or higher"):
///  - a faster second pole: the solenoid force lags the current (τ_sol);
///  - a time constant that shortens as the pressure rises (τ(p) = τ0/(1 + |p|/p_half));
///  - a slightly different solenoid B (left side), as two real solenoids are;
///  - the sensor's 16-bit duty-cycle quantisation of docs/method.md §B1.
/// The measured output has the zero-current bias removed the way the thesis
/// did (paper 2 §2.7.1, docs/method.md §B6): before the run the rig records `bias_window_s`
/// at zero current and subtracts the mean of that record from every sample.
///
/// Timing: current held over one sample period (ZOH); physics integrated at
/// h = T / substeps; the measurement is taken at the end of the period.
/// This is a virtual rig, never the identified model; see docs/rigs.md.
#include <cmath>
#include <cstdint>

#include "lash/rigs/motor_cart.hpp"  // EffectiveModel
#include "lash/signals/rng.hpp"

namespace lash::rigs {

struct PilotValveRigParams {
  double deadzone_right_mA = 288.0;    ///< solenoid A: current that starts moving the spool [mA] (docs/method.md §B1)
  double deadzone_left_mA = -296.0;    ///< solenoid B (negative commands) [mA]
  double gain_right_kPa_mA = 2.15;     ///< solenoid A steady-state gain [kPa/mA] (docs/method.md §B1)
  double gain_left_kPa_mA = 2.08;      ///< solenoid B steady-state gain [kPa/mA]
  double tau0_s = 0.075;               ///< pressure time constant at zero pressure [s]
  double tau_half_pressure_kPa = 7500; ///< τ(p) = τ0/(1 + |p|/p_half): τ(1000 kPa) ≈ 0.066 s [kPa]
  double solenoid_tau_s = 0.008;       ///< the faster second pole: solenoid force lag [s]
  double bias_kPa = 90.1;              ///< sensor reading at zero current [kPa] (docs/method.md §B1)
  double noise_sigma_kPa = 7.28;       ///< Gaussian sensor noise σ [kPa] (docs/method.md §B1)
  double quantum_kPa = 48.82 * 100.0 / 65535.0;  ///< sensor LSB: 16-bit duty (docs/method.md §B1) [kPa]
  double bias_window_s = 1.0;          ///< zero-current record used to remove the bias [s]
  int substeps = 10;                   ///< internal steps per sample period [-]

  /// Throws std::invalid_argument naming the first bad parameter.
  void validate() const;
  /// τ(p) [s].
  double tau_at(double pressure_kPa) const noexcept { return tau0_s / (1.0 + std::fabs(pressure_kPa) / tau_half_pressure_kPa); }
  /// The first-order input-deadzone model (thesis eq. 19–22) this valve is when the solenoid
  /// lag, the pressure dependence of τ and the sensor are ignored: K and c per side from the
  /// steady state (exact), τ = τ(p_ref) at a reference pressure `p_ref_kPa` (see docs/rigs.md).
  EffectiveModel effective(double dt_s, double p_ref_kPa) const;
};

/// E4 virtual rig. step(current_mA) is real-time safe.
class PilotValveRig {
 public:
  /// Throws std::invalid_argument for bad parameters or dt_s ≤ 0. The bias record is taken here
  /// (with noise from `seed`), so the first step already returns bias-free values.
  PilotValveRig(const PilotValveRigParams& p, double dt_s, std::uint64_t seed);

  /// Holds `current_mA` for one sample period; returns the measured pressure difference
  /// with the estimated bias removed [kPa].
  double step(double current_mA) noexcept {
    for (int s = 0; s < substeps_; ++s) {
      // Second (fast) pole: solenoid force, expressed as an equivalent current.
      f_ += (current_mA - f_) * sol_alpha_;
      // Spring pretension + spool overlap: deadzone on the solenoid force (eq. 1).
      double target;
      if (f_ > p_.deadzone_right_mA) target = p_.gain_right_kPa_mA * (f_ - p_.deadzone_right_mA);
      else if (f_ < p_.deadzone_left_mA) target = p_.gain_left_kPa_mA * (f_ - p_.deadzone_left_mA);
      else target = 0.0;
      // Pressure pole whose time constant shortens as pressure rises: exact relaxation over h
      // with τ frozen at the pressure at the start of the internal step.
      const double tau = p_.tau_at(p_kPa_);
      p_kPa_ += (target - p_kPa_) * -std::expm1(-h_ / tau);
    }
    return measure() - bias_estimate_;
  }
  /// Replaces the physics mid-run (a drifting plant, e.g. the deadzone growing). `p` must be
  /// valid (validate() beforehand); substeps and bias_window_s keep their values. noexcept, O(1).
  void set_params(const PilotValveRigParams& p) noexcept {
    const int n = p_.substeps;
    const double w = p_.bias_window_s;
    p_ = p;
    p_.substeps = n;
    p_.bias_window_s = w;
    sol_alpha_ = -std::expm1(-h_ / p_.solenoid_tau_s);
  }
  /// Measurement before the first step, bias removed [kPa].
  double initial_output() noexcept { return measure() - bias_estimate_; }

  double true_pressure_kPa() const noexcept { return p_kPa_; }
  double bias_estimate_kPa() const noexcept { return bias_estimate_; }
  const PilotValveRigParams& params() const noexcept { return p_; }
  double dt_s() const noexcept { return dt_; }

 private:
  double measure() noexcept {
    const double raw = p_kPa_ + p_.bias_kPa + p_.noise_sigma_kPa * rng_.gaussian();
    return std::round(raw / p_.quantum_kPa) * p_.quantum_kPa;
  }
  PilotValveRigParams p_;
  double dt_, h_;
  int substeps_;
  double sol_alpha_;
  Rng rng_;
  double f_ = 0.0;       // solenoid force as equivalent current [mA]
  double p_kPa_ = 0.0;   // pressure difference above bias [kPa]
  double bias_estimate_ = 0.0;
};

}  // namespace lash::rigs
