#pragma once
/// @file gains_file.hpp
/// Controller configuration files (config/control/*.toml):
/// ```toml
/// [pid]
/// kp = 0.71            # [mA/kPa]
/// ki_per_s = 43.2      # [mA/(kPa·s)]
/// kd_s = 0.092         # [mA·s/kPa]
/// n_per_s = 0          # derivative filter [1/s]; 0 = unfiltered (backward difference / du/dt)
/// dt_s = 0.005         # [s]
/// integrator = "forward_euler"
/// anti_windup = "none" # or "clamp", with output_min / output_max
/// [deadzone_inverse]
/// deadzone_mA = 288.0
/// fraction = 0.97     # offset = fraction × deadzone; or give offset_mA = … instead
/// [saturation]
/// min_mA = 0.0
/// max_mA = 2000.0
/// ```
/// The one schema of a ControllerConfig: a gains file is exactly this, and the bench settings'
/// `[controller]` table (hil/settings.hpp) holds the same tables (`[controller.pid]`, …).
/// Deprecated keys, accepted until lash 0.3 with a warning: `ki`, `kd`, `n`, `dt` in [pid]
/// (gains files of 0.1), and the flat `[controller]` keys of the 0.1 bench settings — `kp`,
/// `ki_per_s`, `kd_s`, `n_per_s`, `integrator` (→ pid.*), `deadzone_inverse_mA`
/// (→ deadzone_inverse.offset_mA), `current_min_mA`/`current_max_mA` (→ saturation.min_mA/max_mA).
/// A setting given under two names is an error.
/// Unknown keys are rejected; errors name file, line and key (InputError). Not real-time code.
/// Reader and writer are generated from the field table (controller_fields.hpp), which also
/// lists every key, its unit and range (docs/control.md shows it).
#include <filesystem>
#include <functional>
#include <string>

#include "lash/control/controller.hpp"
#include "lash/io/toml_util.hpp"

namespace lash {

/// Receives each deprecation warning ("file:line: 'pid.ki' is deprecated, …"); when empty,
/// the warning goes to stderr.
using ControllerWarn = std::function<void(const std::string&)>;

/// Reads the controller tables of `table` (implemented in controller_fields.cpp) (its other keys are left to the caller's finish()).
ControllerConfig read_controller_config(TomlTable& table, const ControllerWarn& warn = {});
/// A gains file: the controller tables and nothing else.
ControllerConfig load_controller_config(const std::filesystem::path& path, const ControllerWarn& warn = {});
/// The same file format as text (round-trip precision numbers); `comment` goes on top as # lines.
std::string controller_config_toml(const ControllerConfig& c, const std::string& comment);

}  // namespace lash
