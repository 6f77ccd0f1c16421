#pragma once
/// @file gains_file.hpp
/// Controller configuration files (config/control/*.toml):
/// ```toml
/// [pid]
/// kp = 0.71            # [mA/kPa]
/// ki = 43.2            # [mA/(kPa·s)]
/// kd = 0.092           # [mA·s/kPa]
/// n = 0                # derivative filter [1/s]; 0 = unfiltered (backward difference / du/dt)
/// dt = 0.005           # [s]
/// integrator = "forward_euler"
/// [deadzone_inverse]
/// deadzone_mA = 288.0
/// fraction = 0.97     # offset = fraction × deadzone; or give offset_mA = … instead
/// [saturation]
/// min_mA = 0.0
/// max_mA = 2000.0
/// ```
/// Unknown keys are rejected; errors name file, line and key (InputError). Not real-time code.
#include <filesystem>
#include <string>

#include "lash/control/controller.hpp"

namespace lash {

ControllerConfig load_controller_config(const std::filesystem::path& path);
/// The same file format as text (round-trip precision numbers); `comment` goes on top as # lines.
std::string controller_config_toml(const ControllerConfig& c, const std::string& comment);

}  // namespace lash
