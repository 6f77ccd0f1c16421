#pragma once
/// @file motor_cart.hpp
/// Virtual rig of the thesis's §1.6.1 (E3): a DC-motor-driven cart, voltage in,
/// velocity out. The physics is richer than the first-order output-deadzone
/// model the estimator fits (thesis eq. 36): armature inductance (a fast
/// second pole), rotor inertia, viscous friction, Coulomb friction that is
/// different per direction, stiction (the cart sticks until the motor force
/// exceeds the break-away level), a quadrature encoder that quantises the
/// position, and velocity obtained by differencing the encoder counts.
///
/// It is a *virtual rig*: every parameter below is documented in docs/rigs.md
/// (value, unit, why). It is never the identified model itself.
///
/// Timing: the input voltage is held over one sample period T (zero-order
/// hold, as a DAC does); the rig integrates its physics at a fine internal
/// step h = T / substeps and returns the measurement at the end of the period.
#include <cmath>
#include <cstdint>

#include "lash/blocks/side.hpp"
#include "lash/signals/rng.hpp"

namespace lash::rigs {

/// The first-order model a rig "really" is when its extra physics is ignored
/// (no inductance, no stiction, no quantisation): per side, the continuous
/// gain K, time constant τ and the deadzone edge c, plus the discrete
/// a1 = −exp(−T/τ), b1 = K(1 − exp(−T/τ)) of eq. 9–10. Units are the rig's
/// input/output units. For output-deadzone rigs c is in output units
/// (eq. 36: e = −c(1 + a1)); for input-deadzone rigs c is in input units.
struct EffectiveSide {
  double gain = 0.0;   ///< K [output unit / input unit]
  double tau_s = 0.0;  ///< τ [s]
  double c = 0.0;      ///< deadzone edge (c_r > 0 on the right, c_l < 0 on the left)
  double a1 = 0.0;     ///< −exp(−T/τ) [-]
  double b1 = 0.0;     ///< K(1 − exp(−T/τ))
};
struct EffectiveModel {
  PerSide<EffectiveSide> side;
  double d = 0.0;  ///< deadband half-width [output-position unit] (coupled carts only)
};

/// Parameters of the motor and cart. SI units throughout.
struct MotorCartParams {
  // DC motor (permanent magnet, armature-controlled)
  double resistance_ohm = 2.0;          ///< armature resistance R [Ω]
  double inductance_H = 2.0e-3;         ///< armature inductance L [H] (τ_e = L/R = 1 ms)
  double torque_constant_Nm_A = 0.05;   ///< K_t [N·m/A] = back-EMF constant K_e [V·s/rad] in SI
  double rotor_inertia_kgm2 = 1.0e-5;   ///< J_m [kg·m²], reflected to the cart as J_m·G²/r²
  double gear_ratio = 8.0;              ///< G = motor angle / pinion angle [-]
  double pinion_radius_m = 0.02;        ///< r [m]: cart travel per pinion radian
  // cart
  double mass_kg = 7.35;                ///< cart mass m [kg] (thesis §1.6.3: 7.35 kg)
  double viscous_Ns_m = 5.0;            ///< viscous friction b [N·s/m]
  double coulomb_right_N = 4.0;         ///< kinetic Coulomb friction moving forward F_c+ [N]
  double coulomb_left_N = 4.4;          ///< kinetic Coulomb friction moving backward F_c− [N]
  double breakaway_ratio = 1.3;         ///< static / kinetic friction F_s/F_c [-] (stiction)
  double friction_ripple = 0.05;        ///< relative ripple of F_c along the track (rail joints, wear) [-]
  double friction_ripple_period_m = 0.05; ///< spatial period of that ripple [m]; phase random per seed
  // amplifier
  double voltage_noise_V = 0.02;        ///< σ of the power amplifier's output noise, per sample [V]
  // sensing
  double encoder_counts_per_rev = 8000; ///< quadrature counts per motor revolution (2000 lines × 4) [-]
  int substeps = 10;                    ///< internal steps per sample period [-]

  /// Throws std::invalid_argument naming the first parameter that is not finite and positive
  /// (breakaway_ratio must be ≥ 1).
  void validate() const;
  /// Motor force per volt with the rotor blocked, α = K_t·G/(r·R) [N/V].
  double force_per_volt() const noexcept { return torque_constant_Nm_A * gear_ratio / (pinion_radius_m * resistance_ohm); }
  /// Back-EMF damping β = K_t·K_e·G²/(r²·R) [N·s/m].
  double emf_damping() const noexcept {
    const double k = torque_constant_Nm_A * gear_ratio / pinion_radius_m;
    return k * k / resistance_ohm;
  }
  /// Total damping B = b + β [N·s/m].
  double total_damping() const noexcept { return viscous_Ns_m + emf_damping(); }
  /// Effective mass m + J_m·G²/r² [kg].
  double effective_mass() const noexcept {
    const double k = gear_ratio / pinion_radius_m;
    return mass_kg + rotor_inertia_kgm2 * k * k;
  }
  /// Cart travel per encoder count [m].
  double encoder_step_m() const noexcept {
    return 2.0 * 3.14159265358979323846 * pinion_radius_m / (gear_ratio * encoder_counts_per_rev);
  }
  /// The first-order output-deadzone model of eq. 36 that this cart is when L, stiction and
  /// quantisation are ignored: τ = m_eff/B, K = α/B [m/s per V], c_r = F_c+/B, c_l = −F_c−/B [m/s].
  /// `extra_mass_kg` and `extra_coulomb_N` add a pushed load (coupled carts).
  EffectiveModel effective(double dt_s, double extra_mass_kg = 0.0, double extra_coulomb_N = 0.0) const;
};

/// The motor and cart body shared by the E3 and E5 rigs: electrical state, velocity,
/// position, stick/slip. All members are real-time safe (noexcept, no allocation, O(1)).
class CartDrive {
 public:
  CartDrive() = default;
  /// Throws std::invalid_argument for bad parameters.
  CartDrive(const MotorCartParams& p, double h_s);

  /// Motor force [N] after advancing the armature current over one internal step h with
  /// voltage `volts` held (exact exponential for the frozen back-EMF; stable for any h).
  double advance_current(double volts) noexcept {
    const double omega = v_ * g_over_r_;
    const double i_ss = (volts - ke_ * omega) / r_;
    i_ = i_ss + (i_ - i_ss) * decay_;
    return kt_g_over_r_ * i_;
  }
  /// Advances the mechanics by one internal step with motor force `force_N`, extra resisting
  /// Coulomb force `extra_coulomb_N` and extra inertia `extra_mass_kg` (a rigidly pushed load).
  /// Returns true if the cart is (or became) stuck at zero velocity.
  bool advance_body(double force_N, double extra_mass_kg, double extra_coulomb_N, double extra_static_N) noexcept {
    const double m = m_eff_ + extra_mass_kg;
    const double fc_r_ = fc_r0_ * ripple_, fc_l_ = fc_l0_ * ripple_;
    const double fs_r_ = fs_r0_ * ripple_, fs_l_ = fs_l0_ * ripple_;
    if (v_ == 0.0) {
      // Stiction: stay put until the motor force exceeds the break-away level.
      const double fs = (force_N >= 0.0 ? fs_r_ : fs_l_) + extra_static_N;
      if (std::fabs(force_N) <= fs) return true;
      const double fc = (force_N >= 0.0 ? fc_r_ : -fc_l_) + (force_N >= 0.0 ? extra_coulomb_N : -extra_coulomb_N);
      v_ = h_ * (force_N - fc) / m;
      x_ += 0.5 * v_ * h_;
      return false;
    }
    const double dir = v_ > 0.0 ? 1.0 : -1.0;
    const double fc = (v_ > 0.0 ? fc_r_ : fc_l_) + extra_coulomb_N;
    // Semi-implicit in the viscous term: v' = (v + h(F − F_c·dir)/m) / (1 + h·B_mech/m).
    const double v_new = (v_ + h_ * (force_N - fc * dir) / m) / (1.0 + h_ * b_ / m);
    if (v_new * dir <= 0.0) {
      // Velocity reached zero inside the step: the cart stops (and sticks).
      x_ += 0.5 * v_ * h_ * (v_ / (v_ - v_new));
      v_ = 0.0;
      return true;
    }
    x_ += 0.5 * (v_ + v_new) * h_;
    v_ = v_new;
    return false;
  }

  double velocity_m_s() const noexcept { return v_; }
  double position_m() const noexcept { return x_; }
  double current_A() const noexcept { return i_; }
  double h_s() const noexcept { return h_; }
  double effective_mass_kg() const noexcept { return m_eff_; }
  void set_velocity(double v_m_s) noexcept { v_ = v_m_s; }
  void set_position(double x_m) noexcept { x_ = x_m; }
  /// Updates the track friction ripple factor 1 + δ·sin(2πx/λ + φ) at the current position
  /// (called once per sample period: the cart moves < 1 mm per period, λ = 50 mm).
  void update_ripple() noexcept {
    if (ripple_amp_ != 0.0) ripple_ = 1.0 + ripple_amp_ * std::sin(ripple_k_ * x_ + ripple_phase_);
  }
  void set_ripple_phase(double phase_rad) noexcept { ripple_phase_ = phase_rad; update_ripple(); }
  double viscous_Ns_m() const noexcept { return b_; }
  void reset() noexcept { i_ = v_ = x_ = 0.0; }

 private:
  double h_ = 1e-4;
  double r_ = 1, ke_ = 0, g_over_r_ = 0, kt_g_over_r_ = 0, decay_ = 0;
  double m_eff_ = 1, b_ = 0, fc_r0_ = 0, fc_l0_ = 0, fs_r0_ = 0, fs_l0_ = 0;
  double ripple_amp_ = 0.0, ripple_k_ = 0.0, ripple_phase_ = 0.0, ripple_ = 1.0;
  double i_ = 0.0, v_ = 0.0, x_ = 0.0;
};

/// Incremental encoder: counts = floor((x + offset)/step) − floor(offset/step), position =
/// counts·step (0 at start). `offset` ∈ [0, step) places the count edges (random per run).
class Encoder {
 public:
  Encoder() = default;
  Encoder(double step_m, double offset_m) noexcept
      : step_(step_m), offset_(offset_m), zero_(std::floor(offset_m / step_m)) {}
  double read(double x_m) const noexcept { return (std::floor((x_m + offset_) / step_) - zero_) * step_; }
  double step_m() const noexcept { return step_; }

 private:
  double step_ = 1e-6;
  double offset_ = 0.0;
  double zero_ = 0.0;
};

/// E3 virtual rig. step(volts) is real-time safe.
class MotorCart {
 public:
  /// Throws std::invalid_argument for bad parameters or dt_s ≤ 0. `seed` fixes the amplifier
  /// noise, the phase of the friction ripple and where the encoder's count edges lie.
  MotorCart(const MotorCartParams& p, double dt_s, std::uint64_t seed = 1);

  /// Holds `volts` (plus amplifier noise) for one sample period and returns the measured velocity
  /// at its end [m/s]: (encoder position now − encoder position one period ago) / T.
  double step(double volts) noexcept {
    const double u = volts + noise_V_ * rng_.gaussian();
    drive_.update_ripple();
    for (int s = 0; s < substeps_; ++s) {
      const double f = drive_.advance_current(u);
      drive_.advance_body(f, 0.0, 0.0, 0.0);
    }
    const double pos = encoder_.read(drive_.position_m());
    const double vel = (pos - last_pos_) * inv_dt_;
    last_pos_ = pos;
    return vel;
  }
  /// Measurement before the first step (incremental encoder: 0).
  double initial_output() const noexcept { return 0.0; }
  double true_velocity_m_s() const noexcept { return drive_.velocity_m_s(); }
  double true_position_m() const noexcept { return drive_.position_m(); }
  double measured_position_m() const noexcept { return last_pos_; }
  const MotorCartParams& params() const noexcept { return p_; }
  double dt_s() const noexcept { return dt_; }
  EffectiveModel effective() const { return p_.effective(dt_); }

 private:
  MotorCartParams p_;
  double dt_;
  double inv_dt_;
  int substeps_;
  double noise_V_;
  Rng rng_;
  CartDrive drive_;
  Encoder encoder_;
  double last_pos_ = 0.0;
};

}  // namespace lash::rigs
