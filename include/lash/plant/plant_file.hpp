#pragma once
/// @file plant_file.hpp
/// Plant files (TOML), documented key by key in docs/plant-files.md.
/// Not real-time safe; errors are lash::InputError naming file, line and key.
#include <filesystem>

#include "lash/io/toml_util.hpp"
#include "lash/plant/plant.hpp"

namespace lash {

/// Reads `dt` and `[[blocks]]` from a plant file; `dt_s_override` > 0 replaces the file's dt
/// (linear parts given by gain/tau are discretised at the new dt; a1/b1 are taken as written).
Plant load_plant(const std::filesystem::path& path, double dt_s_override = 0.0);
/// Builds a plant from an already parsed table (e.g. `[plant]` of a scenario file).
/// `dt_s_override` > 0 replaces the table's `dt` (and may stand in for a missing one).
Plant plant_from_toml(TomlTable& table, double dt_s_override = 0.0);

}  // namespace lash
