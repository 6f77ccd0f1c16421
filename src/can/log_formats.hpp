#pragma once
// Readers and writers of the vendor log formats behind can::read_log / write_log.
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "lash/can/log.hpp"

namespace lash::can::detail {

std::vector<LogEntry> parse_asc(std::string_view text, const std::string& file, LogReadReport* report);
void write_asc(std::ostream& out, const std::vector<LogEntry>& entries);
std::vector<LogEntry> parse_trc(std::string_view text, const std::string& file, LogReadReport* report);
void write_trc(std::ostream& out, const std::vector<LogEntry>& entries);
std::vector<LogEntry> parse_blf(std::string_view bytes, const std::string& file, LogReadReport* report);
void write_blf(std::ostream& out, const std::vector<LogEntry>& entries);

/// Records one bad line/object: InputError without a report, a counted drop with one.
void drop(LogReadReport* report, const std::string& file, long line, const std::string& field, const std::string& why);

}  // namespace lash::can::detail
