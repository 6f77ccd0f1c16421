#pragma once
// The controller override flags (--kp, --ki-per-s, …), generated from the field table
// (lash/control/controller_fields.hpp); applied after the gains file by the library.
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "lash/control/controller_fields.hpp"

namespace lash::cli {

/// One option per field that has a flag (--dt-s only when `with_dt`: the hil nodes run at
/// --step-ms); the values given are collected into `out`.
void add_controller_options(CLI::App* sub, std::vector<ControllerOverride>& out, bool with_dt);
/// The overrides as ("table.key", value text) pairs (a node's launch file, hil/launch.hpp), and back.
std::vector<std::pair<std::string, std::string>> controller_override_keys(const std::vector<ControllerOverride>& overrides);
/// Throws InputError naming `file` and the key when a key is not a field with a command-line override.
std::vector<ControllerOverride> controller_overrides_from_keys(const std::vector<std::pair<std::string, std::string>>& keys,
                                                               const std::string& file);

}  // namespace lash::cli
