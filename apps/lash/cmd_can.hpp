#pragma once
// The `lash can` subcommands, one registration function per file.
#include <atomic>
#include <functional>
#include <vector>

#include "cli_common.hpp"
#include "lash/can/log.hpp"

namespace lash::cli::can_cmd {

/// A `lash can` subcommand: `run` executes it when `app` was parsed.
struct Sub {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

std::vector<Sub> add_bus_commands(CLI::App& can);    ///< dump, send (cmd_can.cpp)
std::vector<Sub> add_codec_commands(CLI::App& can);  ///< encode, decode (cmd_can_codec.cpp)
std::vector<Sub> add_dbc_commands(CLI::App& can);    ///< dbc check, dbc list (cmd_can_dbc.cpp)
std::vector<Sub> add_replay_command(CLI::App& can);  ///< replay, convert (cmd_can_replay.cpp)

/// can::read_log with every dropped record printed to stderr ("lash can WHO: dropped: file:line: why").
std::vector<can::LogEntry> read_log_reporting(const std::string& path, const char* who);

/// Set by SIGINT/SIGTERM once install_stop_handler() ran.
extern std::atomic<bool> g_stop;
void install_stop_handler();

}  // namespace lash::cli::can_cmd
