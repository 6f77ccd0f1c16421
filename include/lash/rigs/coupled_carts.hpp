#pragma once
/// @file coupled_carts.hpp
/// Virtual rig of the thesis's §1.6.3 (E5): the E3 motor cart (7.35 kg) drives
/// a free cart (0.42 kg) through a pin in a slot with clearance 2d (thesis
/// Fig. 1.41). The free cart is held by bearing friction (Coulomb, with
/// stiction), so it stops soon after the pin loses contact. Pin–slot contacts
/// are impacts with a coefficient of restitution; slow approaches (below
/// `lock_speed_m_s`) end the bounce sequence and the carts move together
/// while the pin pushes (the contact force is checked every internal step and
/// the carts separate as soon as it would have to pull).
///
/// Outputs: the free cart's position from its own linear encoder and its
/// velocity by differencing that encoder (what the thesis measured).
/// The model the estimator fits (thesis Fig. 1.43, eq. 38–41) assumes a
/// massless free cart that inherits the motor cart's velocity at once; the
/// rig does not. This is a virtual rig, never the identified model; see docs/rigs.md.
#include <cmath>

#include "lash/rigs/motor_cart.hpp"

namespace lash::rigs {

struct CoupledCartsParams {
  MotorCartParams motor;                ///< the E3 cart (its mass is the thesis's 7.35 kg)
  double free_mass_kg = 0.42;           ///< free cart mass [kg] (thesis §1.6.3)
  double free_coulomb_N = 2.5;          ///< free cart bearing friction, kinetic [N] (μ ≈ 0.6: braked bearings)
  double free_static_N = 3.0;           ///< free cart bearing friction, break-away [N]
  double half_clearance_m = 0.005;      ///< d: half of (slot length − pin diameter) [m]
  double restitution = 0.3;             ///< pin–slot coefficient of restitution [-]
  double lock_speed_m_s = 0.01;         ///< approach speeds below this end in contact (no bounce) [m/s]
  double free_encoder_step_m = 1e-7;    ///< free cart linear encoder resolution (interpolated optical scale) [m]

  /// Throws std::invalid_argument naming the first bad parameter.
  void validate() const;
  /// The model of thesis eq. 38–41 while the pin pushes: the motor cart and the free cart as one
  /// body (mass m_eff + m_free), Coulomb friction of both, and the deadband d.
  EffectiveModel effective(double dt_s) const;
};

/// Measurement of one sample: free cart velocity and position.
struct CoupledCartsSample {
  double velocity_m_s = 0.0;  ///< free cart velocity by differencing its encoder [m/s]
  double position_m = 0.0;    ///< free cart encoder position [m]
};

/// E5 virtual rig. step(volts) is real-time safe.
class CoupledCarts {
 public:
  /// Throws std::invalid_argument for bad parameters or dt_s ≤ 0. `seed` fixes the amplifier
  /// noise, the friction ripple's phase and the encoder's count edges.
  CoupledCarts(const CoupledCartsParams& p, double dt_s, std::uint64_t seed = 1);

  /// Holds `volts` for one sample period; returns the free cart measurement at its end.
  CoupledCartsSample step(double volts) noexcept;
  CoupledCartsSample initial_output() const noexcept { return {0.0, 0.0}; }

  /// Replaces the free cart's and the slot's parameters mid-run (a drifting plant, e.g. a
  /// clearance that grows). `p` must be valid; the motor cart and the free encoder keep theirs.
  void set_params(const CoupledCartsParams& p) noexcept {
    const MotorCartParams m = p_.motor;
    const double enc = p_.free_encoder_step_m;
    p_ = p;
    p_.motor = m;
    p_.free_encoder_step_m = enc;
  }
  double motor_velocity_m_s() const noexcept { return drive_.velocity_m_s(); }
  double motor_position_m() const noexcept { return drive_.position_m(); }
  double free_velocity_m_s() const noexcept { return v2_; }
  double free_position_m() const noexcept { return x2_; }
  /// Number of pin–slot impacts that bounced (restitution applied) so far.
  long impacts() const noexcept { return impacts_; }
  const CoupledCartsParams& params() const noexcept { return p_; }
  double dt_s() const noexcept { return dt_; }
  EffectiveModel effective() const { return p_.effective(dt_); }

 private:
  void substep(double volts) noexcept;
  void free_cart_alone() noexcept;
  void resolve_contact() noexcept;

  CoupledCartsParams p_;
  double dt_, inv_dt_, h_;
  int substeps_;
  Rng rng_;
  CartDrive drive_;
  Encoder encoder_;
  double x2_ = 0.0, v2_ = 0.0;  // free cart: slot centre position [m], velocity [m/s]
  int locked_ = 0;              // +1: pin pushes at the slot's front end, −1: at its rear end, 0: free
  long impacts_ = 0;
  double last_pos_ = 0.0;
};

}  // namespace lash::rigs
