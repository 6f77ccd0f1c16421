#pragma once
/// @file log.hpp
/// Bus logs. can-utils text forms of frames:
///  - `ID#HEXDATA` (cansend): 3 hex digits = 11-bit id, 8 hex digits = 29-bit id;
///    `ID#R` / `ID#R<dlc>` remote frames; `ID##<flags>HEXDATA` CAN FD;
///  - `candump -L` log lines: `(seconds.microseconds) iface ID#HEXDATA` with six
///    microsecond digits (an optional trailing ` R`/` T` direction, as python-can
///    writes, is accepted). canplayer and python-can's CanutilsLogReader read them.
/// Not real-time safe (strings).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lash/can/frame.hpp"

namespace lash::can {

/// Parses `ID#HEX`; returns nullopt and sets `error` on bad text. Never throws.
std::optional<Frame> parse_frame_text(std::string_view text, std::string& error) noexcept;
/// `123#DEADBEEF`, `12345678#00`, `123#R`, `123#R4`, `123##0AABB`.
std::string format_frame_text(const Frame& frame);

struct LogEntry {
  Frame frame;            ///< frame.timestamp_s holds the log time [s]
  std::string interface;  ///< e.g. "vcan0"
};

/// Parses one `candump -L` line. nullopt + `error` on bad text. Never throws.
std::optional<LogEntry> parse_log_line(std::string_view line, std::string& error) noexcept;
/// `(1600000000.123456) vcan0 123#DEADBEEF` (no newline); time rounded to 1 µs, written as 0
/// when candump cannot hold it (writable_times).
std::string format_log_line(const Frame& frame, std::string_view interface);
/// The same with `fraction_digits` (6 or 9) digits of the second: 9 keeps a time to the
/// nanosecond (read_log reads up to 9), as `lash can dump` spools the frames of a relative format.
std::string format_log_line(const Frame& frame, std::string_view interface, unsigned fraction_digits);

/// Log file formats, chosen by extension: .asc (Vector ASCII), .blf (Vector binary
/// logging format), .trc (PEAK trace), anything else candump (-L or default output).
enum class LogFormat : std::uint8_t { candump, asc, blf, trc };
LogFormat log_format_of(const std::filesystem::path& path) noexcept;
const char* to_string(LogFormat f) noexcept;

/// What a tolerant read left out: every dropped line/object, counted and located.
struct LogReadReport {
  std::size_t dropped = 0;
  std::vector<std::string> problems;  ///< "file:line: why" (BLF: "file@offset: why")
};

/// Reads a log of any LogFormat (by extension). Blank lines and comments are skipped.
/// Without `report`: throws lash::InputError naming file, line (offset) and field on
/// the first bad line or object. With `report`: bad lines are dropped, counted and
/// listed there; a file that cannot be read at all (missing, not a BLF, …) still throws.
std::vector<LogEntry> read_log(const std::filesystem::path& path, LogReadReport* report = nullptr);
/// Parses candump text (same rules as read_log; `file` names the source in errors).
std::vector<LogEntry> parse_log(std::string_view text, const std::string& file = "<log>", LogReadReport* report = nullptr);
/// Writes entries atomically (lash::AtomicFile) in the format of the extension.
/// Throws lash::InputError (nothing written) when a frame's time cannot be written in that
/// format (see writable_times).
void write_log(const std::filesystem::path& path, const std::vector<LogEntry>& entries);

/// The times [s] a format can write. Absolute formats (candump) bound each time; relative
/// formats (ASC, TRC, BLF) bound each time's offset from the earliest frame, and BLF its
/// header date (the earliest time) as well. Every time must be finite.
struct TimeSpan {
  double min_abs_s;     ///< smallest time (absolute formats and BLF's start)
  double max_abs_s;     ///< largest time / BLF header date (exclusive)
  double max_offset_s;  ///< largest offset from the earliest frame (exclusive)
};
TimeSpan writable_times(LogFormat format) noexcept;
/// Throws lash::InputError (file `file`, field "frame N" 1-based, the time) at the first
/// frame whose time `format` cannot represent; writers call it before writing a byte.
void check_writable_times(const std::vector<LogEntry>& entries, LogFormat format, const std::string& file);

}  // namespace lash::can
