#pragma once
// The controller override flags (--kp, --ki-per-s, …), generated from the field table
// (lash/control/controller_fields.hpp); applied after the gains file by the library.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lash/control/controller_fields.hpp"

namespace lash::cli {

/// One option per field that has a flag (--dt-s only when `with_dt`: the hil nodes run at
/// --step-ms); the values given are collected into `out`.
void add_controller_options(CLI::App* sub, std::vector<ControllerOverride>& out, bool with_dt);
/// The overrides as command-line arguments again (for the node processes of `hil run`).
std::vector<std::string> controller_option_args(const std::vector<ControllerOverride>& overrides);

}  // namespace lash::cli
