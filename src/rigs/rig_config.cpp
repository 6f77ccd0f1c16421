#include <stdexcept>

#include "lash/io/error.hpp"
#include "lash/rigs/rig.hpp"

namespace lash::rigs {

RigKind parse_rig_kind(const std::string& name) {
  if (name == "motor_cart") return RigKind::motor_cart;
  if (name == "pilot_valve") return RigKind::pilot_valve;
  if (name == "coupled_carts") return RigKind::coupled_carts;
  throw std::invalid_argument("unknown rig '" + name + "' (expected motor_cart, pilot_valve, coupled_carts)");
}

const char* to_string(RigKind k) noexcept {
  switch (k) {
    case RigKind::motor_cart: return "motor_cart";
    case RigKind::pilot_valve: return "pilot_valve";
    case RigKind::coupled_carts: return "coupled_carts";
  }
  return "?";
}

namespace {

void num(TomlTable& t, const char* key, double& field) {
  if (auto v = t.number_opt(key)) field = *v;
}
void integer(TomlTable& t, const char* key, int& field) {
  if (auto v = t.integer_opt(key)) {
    if (*v < 1 || *v > 10000) t.fail(key, "must be an integer in 1..10000");
    field = static_cast<int>(*v);
  }
}

void read_motor(TomlTable& t, MotorCartParams& p) {
  num(t, "resistance_ohm", p.resistance_ohm);
  num(t, "inductance_H", p.inductance_H);
  num(t, "torque_constant_Nm_A", p.torque_constant_Nm_A);
  num(t, "rotor_inertia_kgm2", p.rotor_inertia_kgm2);
  num(t, "gear_ratio", p.gear_ratio);
  num(t, "pinion_radius_m", p.pinion_radius_m);
  num(t, "mass_kg", p.mass_kg);
  num(t, "viscous_Ns_m", p.viscous_Ns_m);
  num(t, "coulomb_right_N", p.coulomb_right_N);
  num(t, "coulomb_left_N", p.coulomb_left_N);
  num(t, "breakaway_ratio", p.breakaway_ratio);
  num(t, "friction_ripple", p.friction_ripple);
  num(t, "friction_ripple_period_m", p.friction_ripple_period_m);
  num(t, "voltage_noise_V", p.voltage_noise_V);
  num(t, "encoder_counts_per_rev", p.encoder_counts_per_rev);
  integer(t, "substeps", p.substeps);
}

void read_valve(TomlTable& t, PilotValveRigParams& p) {
  num(t, "deadzone_right_mA", p.deadzone_right_mA);
  num(t, "deadzone_left_mA", p.deadzone_left_mA);
  num(t, "gain_right_kPa_mA", p.gain_right_kPa_mA);
  num(t, "gain_left_kPa_mA", p.gain_left_kPa_mA);
  num(t, "tau0_s", p.tau0_s);
  num(t, "tau_half_pressure_kPa", p.tau_half_pressure_kPa);
  num(t, "solenoid_tau_s", p.solenoid_tau_s);
  num(t, "bias_kPa", p.bias_kPa);
  num(t, "noise_sigma_kPa", p.noise_sigma_kPa);
  num(t, "quantum_kPa", p.quantum_kPa);
  num(t, "bias_window_s", p.bias_window_s);
  integer(t, "substeps", p.substeps);
}

void read_carts(TomlTable& t, CoupledCartsParams& p) {
  read_motor(t, p.motor);
  num(t, "free_mass_kg", p.free_mass_kg);
  num(t, "free_coulomb_N", p.free_coulomb_N);
  num(t, "free_static_N", p.free_static_N);
  num(t, "half_clearance_m", p.half_clearance_m);
  num(t, "restitution", p.restitution);
  num(t, "lock_speed_m_s", p.lock_speed_m_s);
  num(t, "free_encoder_step_m", p.free_encoder_step_m);
}

}  // namespace

RigConfig read_rig_config(RigKind kind, TomlTable* table) {
  RigConfig c;
  c.kind = kind;
  return overlay_rig_config(c, table);
}

RigConfig overlay_rig_config(RigConfig c, TomlTable* table) {
  const RigKind kind = c.kind;
  if (table) {
    switch (kind) {
      case RigKind::motor_cart: read_motor(*table, c.motor_cart); break;
      case RigKind::pilot_valve: read_valve(*table, c.pilot_valve); break;
      case RigKind::coupled_carts: read_carts(*table, c.coupled_carts); break;
    }
    table->finish();
  }
  try {
    switch (kind) {
      case RigKind::motor_cart: c.motor_cart.validate(); break;
      case RigKind::pilot_valve: c.pilot_valve.validate(); break;
      case RigKind::coupled_carts: c.coupled_carts.validate(); break;
    }
  } catch (const std::invalid_argument& e) {
    if (table) throw InputError(table->file(), table->line(), table->path(""), e.what());
    throw;
  }
  return c;
}

}  // namespace lash::rigs
