#pragma once
/// @file launch.hpp
/// How a session starts a node process: the node's whole configuration as data (NodeLaunch),
/// serialised by the library (write_launch: a JSON file) and read back by the child
/// (read_launch). The session never writes a command line: the face that runs the session
/// gives the command that runs a node from a launch file (SessionOptions::node_command, e.g.
/// the `lash` executable's hidden `hil node FILE`); the library appends the file's path.
/// Errors name the struct's fields (`loop.step_s`, `duration_s`); a face maps them to its own
/// options in its messages. Not real-time code.
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "lash/hil/log_writer.hpp"
#include "lash/hil/node_run.hpp"

namespace lash::hil {

struct NodeLaunch {
  enum class Role : std::uint8_t { slave, master };
  Role role = Role::slave;
  // The settings the node loads, and what overrides them (in this order).
  std::filesystem::path config;       ///< the settings file (TOML, settings.hpp)
  std::string bus;                    ///< bus address ("" = the settings')
  double step_s = 0.0;                ///< the step [s] (0 = the settings')
  std::int64_t seed = -1;             ///< the plant's noise seed (−1 = the settings')
  std::filesystem::path scenario;     ///< a closed-loop scenario file ("" = none)
  std::string compensation;           ///< with a scenario: none | fixed | adaptive
  /// Controller overrides after the settings' controller: (key of controller_fields(), value text).
  std::vector<std::pair<std::string, std::string>> controller;
  // The run.
  LoopOptions loop;
  double duration_s = 0.0;            ///< slave: longest run; master: control time [s]
  double connect_timeout_s = 0.0;     ///< slave: 0 = wait for CONNECT until stopped
  std::string reference;              ///< master: `KIND:key=value,…`
  double dto_timeout_s = 0.0;         ///< master: 0 = the settings'
  bool xcp = true;                    ///< master: the XCP slave
  LogPaths logs;                      ///< streamed logs
  std::filesystem::path stats;        ///< statistics JSON ("" = none)
  int result_fd = -1;                 ///< inherited memory file the run is handed over in (−1 = none)
};

const char* to_string(NodeLaunch::Role r) noexcept;

/// The launch as JSON text (one object; every field of NodeLaunch by name).
std::string launch_json(const NodeLaunch& l);
/// Writes launch_json(l) to `path` (atomically). Throws InputError naming the file.
void write_launch(const std::filesystem::path& path, const NodeLaunch& l);
/// Reads a launch file. Throws InputError naming the file and the field (`loop.fifo`) of a
/// missing or mistyped value; the values' ranges are checked where they are used
/// (LoopOptions::validate, steps_for, …), with the same field names.
NodeLaunch read_launch(const std::filesystem::path& path);

}  // namespace lash::hil
