#pragma once
// The `lash can` subcommands, one registration function per file.
#include <atomic>
#include <functional>
#include <vector>

#include "cli_common.hpp"
#include "lash/can/log.hpp"
#include "lash/can/log_reader.hpp"

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

/// A log read one frame at a time (can::LogReader) whose dropped records are printed to stderr at
/// the end ("lash can WHO: dropped: file:line: field: why", the first 20, then a count).
class ReportingReader {
 public:
  ReportingReader(const std::string& path, const char* who);
  bool next(can::LogEntry& e) { return reader_.next(e); }
  /// Prints the drops and "N of M records of FILE dropped"; InputError (exit 2) when records were
  /// dropped and none was valid. Returns the frames read.
  std::uint64_t finish();

 private:
  std::string path_;
  const char* who_;
  can::LogReadReport report_;
  can::LogReader reader_;
};

/// Set by SIGINT/SIGTERM once install_stop_handler() ran.
extern std::atomic<bool> g_stop;
void install_stop_handler();

}  // namespace lash::cli::can_cmd
