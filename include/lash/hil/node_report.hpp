#pragma once
/// @file node_report.hpp
/// What a node run leaves for a person: its logs written from a run in memory (the nodes
/// themselves stream theirs while they run: log_writer.hpp, same formats) and its statistics
/// JSON (`lash hil slave|master --stats`). Columns in docs/hil.md. Not real-time code.
#include <filesystem>
#include <string>
#include <vector>

#include "lash/hil/node_run.hpp"

namespace lash::hil {

/// Log files of a run (atomic writes; columns documented in docs/hil.md).
void write_slave_csv(const std::filesystem::path& path, const SlaveRun& r);
void write_master_csv(const std::filesystem::path& path, const MasterRun& r);
/// A node's events CSV: `step,t_s,event,from,to`.
void write_events(const std::filesystem::path& path, const std::vector<NodeEvent>& events);
/// The master's events CSV: `step,t_s,event,from,to,name,old,new`, the state events and the
/// calibration writes (event `calibration`, the object's name, its old and new value) in step order.
void write_events(const std::filesystem::path& path, const std::vector<NodeEvent>& events,
                  const std::vector<CalibrationEvent>& calibration);
/// candump -L log of the frames the master sent and received, in wall-clock seconds: a sent
/// frame carries its loop time (added to the loop's epoch), a received one the bus's receive
/// timestamp, which is wall-clock already.
void write_bus_log(const std::filesystem::path& path, const MasterRun& r);
/// The statistics JSON of `lash hil slave/master --stats`.
std::string slave_stats_json(const SlaveRun& r);
std::string master_stats_json(const MasterRun& r, const std::string& reference);

}  // namespace lash::hil
