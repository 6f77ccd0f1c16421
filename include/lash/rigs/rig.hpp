#pragma once
/// @file rig.hpp
/// The virtual rigs of the thesis's campaigns E3–E5 behind one name, and the
/// reading of their parameters from a campaign file's `[rig_params]` table
/// (every field of the rig's parameter struct, same name; unset fields keep
/// the documented defaults of docs/rigs.md). Not real-time safe.
#include <string>

#include "lash/io/toml_util.hpp"
#include "lash/rigs/coupled_carts.hpp"
#include "lash/rigs/motor_cart.hpp"
#include "lash/rigs/pilot_valve_rig.hpp"

namespace lash::rigs {

enum class RigKind : std::uint8_t { motor_cart, pilot_valve, coupled_carts };

/// "motor_cart", "pilot_valve", "coupled_carts"; throws std::invalid_argument otherwise.
RigKind parse_rig_kind(const std::string& name);
const char* to_string(RigKind k) noexcept;

/// The parameters of whichever rig `kind` names (the other members stay at their defaults).
struct RigConfig {
  RigKind kind = RigKind::motor_cart;
  MotorCartParams motor_cart;
  PilotValveRigParams pilot_valve;
  CoupledCartsParams coupled_carts;
};

/// Applies the overrides in `table` (a campaign's `[rig_params]`) to the defaults of `kind`.
/// Unknown keys and invalid values throw InputError naming file, line and key.
RigConfig read_rig_config(RigKind kind, TomlTable* table);
/// The same, applied on top of `base` (keys absent keep base's values; a drifting rig).
RigConfig overlay_rig_config(RigConfig base, TomlTable* table);

}  // namespace lash::rigs
