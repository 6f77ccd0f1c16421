#pragma once
// lash hil: shared option handling of the hil subcommands (parsing only; the work is in src/hil).
#include <string>

#include "cli_common.hpp"
#include "lash/io/error.hpp"
#include "controller_options.hpp"
#include "lash/hil/node_run.hpp"
#include "lash/hil/settings.hpp"

namespace lash::cli::hilcli {

/// Options every real-time subcommand takes.
struct CommonOptions {
  std::string config;
  std::string bus;
  double step_ms = 0.0;  // 0 = from the settings file
  int fifo = 0;
  int cpu = -1;
  double spin_us = 0.0;
  bool lock_memory = false;
  bool no_dma_latency = false;
  std::string overrun_policy = "tolerate";
  std::size_t max_overruns = 10;
  std::string scenario;                  // --scenario: a closed-loop scenario on the bench
  std::string compensation = "adaptive"; // --compensation (with --scenario)
  bool compensation_given = false;
  std::vector<ControllerOverride> controller;  // --kp, --ki-per-s, … (after the settings' controller)
};

void add_common(CLI::App* sub, CommonOptions& o);
/// --scenario FILE.toml and --compensation none|fixed|adaptive (run, simulate, slave, master).
void add_scenario(CLI::App* sub, CommonOptions& o);
/// --kp, --ki-per-s, … (master, slave, run, simulate): the controller after the settings file.
void add_controller(CLI::App* sub, CommonOptions& o);
/// The settings file (default config/hil/bench.toml) with --bus, --step-ms, the controller
/// overrides and --scenario applied.
hil::BenchSettings load_settings(const CommonOptions& o);
/// Validated loop options (InputError naming the option).
hil::LoopOptions loop_options(const CommonOptions& o, const hil::BenchSettings& s);
/// The settings file the options name (for the node processes of `hil run`).
std::string settings_path(const CommonOptions& o);

/// --duration: positive, and at most kMaxSteps steps of the shortest step.
CLI::Option* add_duration(CLI::App* sub, double& value, const std::string& what);

/// `e` with the library's field name (`loop.step_s`) replaced by the option (`--step-ms`).
InputError with_option_names(const InputError& e);

void add_hil_nodes(CLI::App* hil, std::function<int()>& run_selected);
void add_hil_run(CLI::App* hil, std::function<int()>& run_selected);
/// lash hil a2l (cmd_xcp.cpp).
void add_hil_a2l(CLI::App* hil, std::function<int()>& run_selected);

}  // namespace lash::cli::hilcli
