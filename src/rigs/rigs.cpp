#include <cmath>
#include <stdexcept>
#include <string>

#include "lash/rigs/coupled_carts.hpp"
#include "lash/rigs/motor_cart.hpp"
#include "lash/rigs/pilot_valve_rig.hpp"
#include "lash/io/numeric.hpp"

namespace lash::rigs {
namespace {

void require_positive(double x, const char* name) {
  if (!(std::isfinite(x) && x > 0.0)) throw std::invalid_argument(std::string(name) + " must be finite and > 0");
}
void require_nonnegative(double x, const char* name) {
  if (!(std::isfinite(x) && x >= 0.0)) throw std::invalid_argument(std::string(name) + " must be finite and >= 0");
}
void require_substeps(int n) {
  if (n < 1 || n > 10000) throw std::invalid_argument("substeps must be in 1..10000");
}
void require_dt(double dt_s) { require_positive(dt_s, "dt_s"); }

EffectiveSide make_side(double gain, double tau_s, double c, double dt_s) {
  EffectiveSide s;
  s.gain = gain;
  s.tau_s = tau_s;
  s.c = c;
  s.a1 = -std::exp(-dt_s / tau_s);
  s.b1 = gain * -std::expm1(-dt_s / tau_s);
  return s;
}

}  // namespace

// ---------------------------------------------------------------- motor cart
void MotorCartParams::validate() const {
  require_positive(resistance_ohm, "resistance_ohm");
  require_positive(inductance_H, "inductance_H");
  require_positive(torque_constant_Nm_A, "torque_constant_Nm_A");
  require_nonnegative(rotor_inertia_kgm2, "rotor_inertia_kgm2");
  require_positive(gear_ratio, "gear_ratio");
  require_positive(pinion_radius_m, "pinion_radius_m");
  require_positive(mass_kg, "mass_kg");
  require_nonnegative(viscous_Ns_m, "viscous_Ns_m");
  require_nonnegative(coulomb_right_N, "coulomb_right_N");
  require_nonnegative(coulomb_left_N, "coulomb_left_N");
  if (!(std::isfinite(breakaway_ratio) && breakaway_ratio >= 1.0))
    throw std::invalid_argument("breakaway_ratio must be finite and >= 1");
  if (!(std::isfinite(friction_ripple) && friction_ripple >= 0.0 && friction_ripple < 1.0))
    throw std::invalid_argument("friction_ripple must be in [0, 1)");
  require_positive(friction_ripple_period_m, "friction_ripple_period_m");
  require_nonnegative(voltage_noise_V, "voltage_noise_V");
  require_positive(encoder_counts_per_rev, "encoder_counts_per_rev");
  require_substeps(substeps);
}

EffectiveModel MotorCartParams::effective(double dt_s, double extra_mass_kg, double extra_coulomb_N) const {
  require_dt(dt_s);
  const double B = total_damping();
  const double tau = (effective_mass() + extra_mass_kg) / B;
  const double K = force_per_volt() / B;
  EffectiveModel m;
  m.side.right = make_side(K, tau, (coulomb_right_N + extra_coulomb_N) / B, dt_s);
  m.side.left = make_side(K, tau, -(coulomb_left_N + extra_coulomb_N) / B, dt_s);
  return m;
}

CartDrive::CartDrive(const MotorCartParams& p, double h_s) {
  p.validate();
  require_positive(h_s, "internal step h");
  h_ = h_s;
  r_ = p.resistance_ohm;
  ke_ = p.torque_constant_Nm_A;
  g_over_r_ = p.gear_ratio / p.pinion_radius_m;
  kt_g_over_r_ = p.torque_constant_Nm_A * g_over_r_;
  decay_ = std::exp(-h_s * p.resistance_ohm / p.inductance_H);
  m_eff_ = p.effective_mass();
  b_ = p.viscous_Ns_m;
  fc_r0_ = p.coulomb_right_N;
  fc_l0_ = p.coulomb_left_N;
  fs_r0_ = p.coulomb_right_N * p.breakaway_ratio;
  fs_l0_ = p.coulomb_left_N * p.breakaway_ratio;
  ripple_amp_ = p.friction_ripple;
  ripple_k_ = 2.0 * 3.14159265358979323846 / p.friction_ripple_period_m;
}

MotorCart::MotorCart(const MotorCartParams& p, double dt_s, std::uint64_t seed)
    : p_(p), dt_(dt_s), inv_dt_(0), substeps_(p.substeps), noise_V_(p.voltage_noise_V), rng_(seed) {
  require_dt(dt_s);
  p_.validate();
  inv_dt_ = 1.0 / dt_s;
  drive_ = CartDrive(p_, dt_s / p_.substeps);
  drive_.set_ripple_phase(2.0 * 3.14159265358979323846 * rng_.uniform());
  encoder_ = Encoder(p_.encoder_step_m(), p_.encoder_step_m() * rng_.uniform());
}

// ---------------------------------------------------------------- pilot valve
void PilotValveRigParams::validate() const {
  require_positive(deadzone_right_mA, "deadzone_right_mA");
  if (!(std::isfinite(deadzone_left_mA) && deadzone_left_mA < 0.0))
    throw std::invalid_argument("deadzone_left_mA must be finite and < 0");
  require_positive(gain_right_kPa_mA, "gain_right_kPa_mA");
  require_positive(gain_left_kPa_mA, "gain_left_kPa_mA");
  require_positive(tau0_s, "tau0_s");
  require_positive(tau_half_pressure_kPa, "tau_half_pressure_kPa");
  require_positive(solenoid_tau_s, "solenoid_tau_s");
  if (!std::isfinite(bias_kPa)) throw std::invalid_argument("bias_kPa must be finite");
  require_nonnegative(noise_sigma_kPa, "noise_sigma_kPa");
  require_positive(quantum_kPa, "quantum_kPa");
  require_nonnegative(bias_window_s, "bias_window_s");
  require_substeps(substeps);
}

EffectiveModel PilotValveRigParams::effective(double dt_s, double p_ref_kPa) const {
  require_dt(dt_s);
  const double tau = tau_at(p_ref_kPa);
  EffectiveModel m;
  m.side.right = make_side(gain_right_kPa_mA, tau, deadzone_right_mA, dt_s);
  m.side.left = make_side(gain_left_kPa_mA, tau, deadzone_left_mA, dt_s);
  return m;
}

PilotValveRig::PilotValveRig(const PilotValveRigParams& p, double dt_s, std::uint64_t seed)
    : p_(p), dt_(dt_s), h_(0), substeps_(p.substeps), sol_alpha_(0), rng_(seed) {
  require_dt(dt_s);
  p_.validate();
  h_ = dt_s / p_.substeps;
  sol_alpha_ = -std::expm1(-h_ / p_.solenoid_tau_s);
  // Bias record at zero current (paper 2 §2.7.1): mean of the readings over bias_window_s.
  const auto n = static_cast<long>(steps_or_throw(p_.bias_window_s, dt_s, "bias_window_s", std::size_t{100'000'000}));
  if (n > 0) {
    double sum = 0.0;
    for (long k = 0; k < n; ++k) sum += measure();
    bias_estimate_ = sum / static_cast<double>(n);
  } else {
    bias_estimate_ = p_.bias_kPa;  // no record: the nominal bias
  }
}

// ---------------------------------------------------------------- coupled carts
void CoupledCartsParams::validate() const {
  motor.validate();
  require_positive(free_mass_kg, "free_mass_kg");
  require_nonnegative(free_coulomb_N, "free_coulomb_N");
  if (!(std::isfinite(free_static_N) && free_static_N >= free_coulomb_N))
    throw std::invalid_argument("free_static_N must be finite and >= free_coulomb_N");
  require_nonnegative(half_clearance_m, "half_clearance_m");
  if (!(std::isfinite(restitution) && restitution >= 0.0 && restitution <= 1.0))
    throw std::invalid_argument("restitution must be in [0, 1]");
  require_nonnegative(lock_speed_m_s, "lock_speed_m_s");
  require_positive(free_encoder_step_m, "free_encoder_step_m");
}

EffectiveModel CoupledCartsParams::effective(double dt_s) const {
  EffectiveModel m = motor.effective(dt_s, free_mass_kg, free_coulomb_N);
  m.d = half_clearance_m;
  return m;
}

CoupledCarts::CoupledCarts(const CoupledCartsParams& p, double dt_s, std::uint64_t seed)
    : p_(p), dt_(dt_s), inv_dt_(0), h_(0), substeps_(p.motor.substeps), rng_(seed) {
  require_dt(dt_s);
  p_.validate();
  inv_dt_ = 1.0 / dt_s;
  h_ = dt_s / substeps_;
  drive_ = CartDrive(p_.motor, h_);
  drive_.set_ripple_phase(2.0 * 3.14159265358979323846 * rng_.uniform());
  encoder_ = Encoder(p_.free_encoder_step_m, p_.free_encoder_step_m * rng_.uniform());
}

void CoupledCarts::free_cart_alone() noexcept {
  if (v2_ == 0.0) return;  // held by bearing stiction; only the pin can move it
  const double dir = v2_ > 0.0 ? 1.0 : -1.0;
  const double v_new = v2_ - dir * h_ * p_.free_coulomb_N / p_.free_mass_kg;
  if (v_new * dir <= 0.0) {
    x2_ += 0.5 * v2_ * h_ * (v2_ / (v2_ - v_new));
    v2_ = 0.0;
    return;
  }
  x2_ += 0.5 * (v2_ + v_new) * h_;
  v2_ = v_new;
}

void CoupledCarts::resolve_contact() noexcept {
  const double d = p_.half_clearance_m;
  const double x1 = drive_.position_m();
  const double rel = x1 - x2_;
  int side = 0;
  if (rel > d) side = 1;
  else if (rel < -d) side = -1;
  if (side == 0) return;
  x2_ = x1 - side * d;  // the pin pushes the slot's end (positions are made consistent)
  const double v1 = drive_.velocity_m_s();
  const double u = side * (v1 - v2_);  // approach speed
  if (u <= 0.0) return;                // already separating
  const double m1 = drive_.effective_mass_kg();
  const double m2 = p_.free_mass_kg;
  if (u <= p_.lock_speed_m_s) {
    const double vc = (m1 * v1 + m2 * v2_) / (m1 + m2);
    drive_.set_velocity(vc);
    v2_ = vc;
    locked_ = side;
    return;
  }
  // Newton's impact law with restitution e, momentum conserved.
  const double j = (1.0 + p_.restitution) * u * m1 * m2 / (m1 + m2);
  drive_.set_velocity(v1 - side * j / m1);
  v2_ = v2_ + side * j / m2;
  ++impacts_;
}

void CoupledCarts::substep(double volts) noexcept {
  const double f = drive_.advance_current(volts);
  if (locked_ != 0) {
    const double v_before = drive_.velocity_m_s();
    const bool stuck = drive_.advance_body(f, p_.free_mass_kg, p_.free_coulomb_N, p_.free_static_N);
    const double d = p_.half_clearance_m;
    v2_ = drive_.velocity_m_s();
    x2_ = drive_.position_m() - locked_ * d;
    if (stuck || v_before == 0.0) {
      locked_ = 0;  // both stopped: each is held by its own stiction from here on
      if (stuck) v2_ = 0.0;
      return;
    }
    // Contact force the pin must exert on the free cart to keep it moving with the motor cart:
    // N = m2·a + F_f·sgn(v). The pin can only push (towards locked_).
    const double a = (drive_.velocity_m_s() - v_before) / h_;
    const double n = p_.free_mass_kg * a + p_.free_coulomb_N * (v2_ > 0.0 ? 1.0 : -1.0);
    if (locked_ * n < 0.0) locked_ = 0;
    return;
  }
  drive_.advance_body(f, 0.0, 0.0, 0.0);
  free_cart_alone();
  resolve_contact();
}

CoupledCartsSample CoupledCarts::step(double volts) noexcept {
  const double u = volts + p_.motor.voltage_noise_V * rng_.gaussian();
  drive_.update_ripple();
  for (int s = 0; s < substeps_; ++s) substep(u);
  const double pos = encoder_.read(x2_);
  CoupledCartsSample out;
  out.velocity_m_s = (pos - last_pos_) * inv_dt_;
  out.position_m = pos;
  last_pos_ = pos;
  return out;
}

}  // namespace lash::rigs
