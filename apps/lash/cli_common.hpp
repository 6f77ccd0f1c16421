#pragma once
// Shared pieces of the lash command line: the subcommand registry, the
// error → exit-status mapping and small output helpers.
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "lash/io/atomic_file.hpp"
#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"

namespace lash::cli {

/// Exit statuses: 0 ok, 1 the job ran but failed its own check, 2 bad input.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;
inline constexpr int kExitBadInput = 2;

/// A subcommand adds itself to the app and sets `run` to the function that executes it.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

/// Each subcommand file defines one of these.
Command add_simulate(CLI::App& app);
Command add_excite(CLI::App& app);
Command add_demo(CLI::App& app);
Command add_closed_loop(CLI::App& app);
/// lash closed-loop --scenario (cmd_closed_loop_scenario.cpp).
int run_closed_loop_scenario_cmd(const std::string& path, const std::string& compensation, bool json,
                                 const std::string& out, const std::string& plot);
Command add_tune(CLI::App& app);
Command add_identify_steps(CLI::App& app);
Command add_estimate(CLI::App& app);
Command add_sweep(CLI::App& app);
/// `lash demo` part of the sweep: runs the E3 campaigns (thesis and lash settings) and prints their summaries.
int demo_e3_campaign(const std::string& out_dir);
Command add_can(CLI::App& app);
Command add_hil(CLI::App& app);
Command add_xcp(CLI::App& app);
Command add_monitor(CLI::App& app);
Command add_console(CLI::App& app);

/// The one catch-all (main): runs `fn`; InputError and std::invalid_argument → exit 2,
/// any other lash::Error, std::exception or unknown exception → exit 1; a message on stderr,
/// never an abort.
int guarded(const std::function<int()>& fn) noexcept;

/// Writes named columns as CSV (round-trip precision) atomically to `path`.
void write_columns_csv(const std::string& path, const std::vector<std::string>& names,
                       const std::vector<const std::vector<double>*>& cols);

/// Root of the source tree (for shipped config files); LASH_SOURCE_DIR or the compiled-in path.
std::string source_dir();

}  // namespace lash::cli
