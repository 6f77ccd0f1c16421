#pragma once
// Readers and writers of the log formats behind can::LogReader / LogWriter (log_reader.hpp):
// one record at a time. parse_* / write_* over whole texts are the same readers and writers
// collecting (the fuzz harnesses call them).
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "lash/can/log.hpp"
#include "lash/can/log_reader.hpp"

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

/// Where a reader's bytes come from: a file descriptor (file, FIFO, stdin) or memory.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  /// Up to `n` bytes into `dst`; 0 at the end. Blocks until some arrive. Throws InputError when
  /// the file cannot be read.
  virtual std::size_t read(char* dst, std::size_t n) = 0;
  /// Exactly `n` bytes unless the end comes first; returns how many.
  std::size_t read_full(char* dst, std::size_t n);
  /// Reads and forgets up to `n` bytes; returns how many.
  std::uint64_t skip(std::uint64_t n);
};

/// One candump line (blank lines skipped: false without a drop). True with `out` set for a frame;
/// false after a drop (InputError without a report).
bool candump_line(std::string_view line, long lineno, const std::string& file, LogReadReport* report, LogEntry& out);

/// Vector ASC, line by line (python-can's ASCReader): the `base` line sets the number base.
class AscLines {
 public:
  bool line(std::string_view line, long lineno, const std::string& file, LogReadReport* report, LogEntry& out);

 private:
  int base_ = 16;
};

/// PEAK TRC, line by line: ;$FILEVERSION and ;$COLUMNS set the layout.
class TrcLines {
 public:
  bool line(std::string_view line, long lineno, const std::string& file, LogReadReport* report, LogEntry& out);

 private:
  int version_ = 100;               ///< 100 = 1.0, 101 = 1.1, … 201 = 2.1
  std::string columns_ = "NOTIdlD";  ///< 2.x: ;$COLUMNS letters (default for 2.0)
};

/// Vector BLF from a byte source: the file header (InputError when it is not a BLF), then one
/// top-level object per fill() call; the frames go to `out`.
class BlfStream {
 public:
  BlfStream(ByteSource& src, std::string file, LogReadReport* report);
  ~BlfStream();
  BlfStream(const BlfStream&) = delete;
  BlfStream& operator=(const BlfStream&) = delete;
  /// Reads the next top-level object, appending its frames to `out`; false at the end.
  bool fill(std::deque<LogEntry>& out);

  struct Objects;  // the objects of the concatenated container payloads, as they arrive

 private:
  void end_of_file(std::deque<LogEntry>& out);
  ByteSource& src_;
  std::string file_;
  LogReadReport* report_;
  double start_ = 0.0;
  std::uint64_t pos_ = 0;  ///< file offset of the next top-level object
  bool done_ = false;
  std::vector<char> payload_;  ///< one container's (compressed) payload
  std::unique_ptr<unsigned char[]> raw_;
  std::size_t raw_cap_ = 0;
  std::unique_ptr<Objects> stream_;
};

/// Per-format writers of one entry at a time (LogWriter). `t0` is the earliest time.
void asc_header(std::ostream& os);
void asc_entry(std::ostream& os, const LogEntry& e, double t0);
void asc_trailer(std::ostream& os);
void trc_header(std::ostream& os);
void trc_entry(std::ostream& os, const LogEntry& e, double t0, std::size_t number);

/// BLF, streamed: objects are gathered into 128 KiB pieces, each compressed into a container as
/// it fills; the header (sizes, count, stop time) is written at finish(), by seeking back when
/// the stream can, else after holding the containers in memory.
class BlfWriter {
 public:
  BlfWriter(std::ostream& os, double t0);
  void entry(const LogEntry& e);
  void finish();

 private:
  void flush_chunk(std::size_t n);
  std::ostream& os_;
  double start_;
  double stop_ = 0.0;
  std::uint32_t count_ = 0;
  std::uint64_t file_bytes_ = 0, obj_bytes_ = 0;
  std::string objs_;      ///< objects not yet compressed (< 128 KiB after each entry)
  std::string held_;      ///< containers, when the stream cannot seek back to the header
  bool seekable_ = false;
  std::ostream::pos_type header_at_{};
};

/// The times [s] a format can write, checked one entry at a time (check_writable_times).
class TimeCheck {
 public:
  TimeCheck(LogFormat format, const LogTimes& times, std::string file);
  /// Throws InputError (field "frame N", 1-based) when `t` cannot be written.
  void check(double t, std::uint64_t index) const;

 private:
  LogFormat format_;
  TimeSpan span_;
  double t0_, origin_;
  std::string file_;
};

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
