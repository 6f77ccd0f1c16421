#pragma once
// Readers and writers of the vendor log formats behind can::read_log / write_log.
#include <cstddef>
#include <cstdint>
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

/// Records one bad line/object: InputError without a report, a counted drop with one
/// (its problem text is "file:line: field: why"; `line` is a byte offset for BLF).
void drop(LogReadReport* report, const std::string& file, long line, const std::string& field, const std::string& why);

/// Splits `line` on blanks (space, tab, CR) into at most `max` fields; returns how many.
std::size_t split_blank(std::string_view line, std::string_view* out, std::size_t max);

/// CAN FD data length [bytes] of a DLC code (0–8, 12, 16, 20, 24, 32, 48, 64); 0xFF above 15.
inline std::uint8_t fd_len(std::uint32_t dlc) noexcept {
  static constexpr std::uint8_t k[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  return dlc < 16 ? k[dlc] : 0xFF;
}
/// The smallest DLC code whose data length holds `len` bytes (15 above 64).
inline std::uint32_t fd_dlc(std::uint32_t len) noexcept {
  for (std::uint32_t d = 0; d < 16; ++d)
    if (fd_len(d) >= len) return d;
  return 15;
}

/// The BLF header's start time [s] for a log whose earliest frame is at `t0` [s]: t0 cut to
/// the millisecond when it is a date (as python-can: from 1990-01-01 on), else 0 (times are
/// offsets). Object times are written relative to it. `t0` within writable_times(blf).
double blf_start_of(double t0) noexcept;

/// Days since 1970-01-01 of a proleptic Gregorian date (Howard Hinnant's algorithm).
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d);

}  // namespace lash::can::detail
