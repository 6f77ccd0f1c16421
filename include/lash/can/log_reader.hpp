#pragma once
/// @file log_reader.hpp
/// Bus logs read one frame at a time, and written one frame at a time, with bounded memory.
///
/// LogReader reads a log of any LogFormat (by extension, log.hpp) as it comes — a regular file,
/// a FIFO, standard input (`-`) — and hands out one LogEntry per next() call. It keeps what one
/// record needs, not the log:
///  - candump, ASC, TRC: one line (lines longer than kMaxLineBytes are dropped, counted);
///  - BLF: one container's compressed and inflated bytes (python-can and Vector write 128 KiB
///    containers; the inflated size is capped at 1 GiB as before) and the frames decoded from
///    it, plus at most kMaxHeldObjectBytes of an object that continues in the next container
///    (larger objects are skipped as their bytes arrive).
/// The frames, their order, the dropped records and the messages naming file and line (BLF: byte
/// offset) are those of read_log, which is this reader collecting every entry; a BLF mixing
/// top-level frame objects with containers is read in file order.
///
/// LogWriter writes entries one by one in the format of the extension; relative formats need the
/// earliest time of the log up front (a first pass: LogReader, or the entries at hand). Not
/// real-time safe.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>

#include "lash/can/log.hpp"

namespace lash::can {

class LogReader {
 public:
  static constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;        ///< a longer text line is dropped
  static constexpr std::size_t kMaxHeldObjectBytes = std::size_t{1} << 20;  ///< BLF objects larger are skipped, not held

  /// Opens `path` (format by extension; `-` = standard input, candump). Throws lash::InputError
  /// when it cannot be opened, and (BLF) when it has no LOGG header. `report` as read_log: null =
  /// the first bad record throws InputError naming file, line (offset) and field; else drops are
  /// counted there. The report must outlive the reader.
  explicit LogReader(const std::filesystem::path& path, LogReadReport* report = nullptr);
  /// Reads `bytes` (not copied: they must outlive the reader) as a log of `format`; `name` stands
  /// for the file in messages. `chunk` > 0 hands the bytes over in pieces of that size, as a
  /// slow FIFO would (tests of the record boundaries).
  LogReader(std::string_view bytes, LogFormat format, std::string name, LogReadReport* report = nullptr,
            std::size_t chunk = 0);
  ~LogReader();
  LogReader(LogReader&&) noexcept;
  LogReader& operator=(LogReader&&) noexcept;

  /// The next frame into `out`; false at the end of the log. Blocks on a FIFO until a record
  /// (or the end) arrives.
  bool next(LogEntry& out);
  LogFormat format() const noexcept;
  /// Frames handed out so far.
  std::uint64_t count() const noexcept;
  /// Keeps at most `n` problem texts in the report (the first ones; `dropped` still counts every
  /// drop), so that a long log of garbage does not grow it. Default: all.
  void keep_problems(std::size_t n) noexcept;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// What the times of a log need known before a relative format can be written.
struct LogTimes {
  std::uint64_t count = 0;  ///< entries
  double earliest_s = 0.0;  ///< smallest time (std::min over the entries in order, as the writers take it)
  void add(double t) noexcept {
    earliest_s = count == 0 ? t : std::min(earliest_s, t);
    ++count;
  }
};

class LogWriter {
 public:
  /// Writes to `out` in `format`; `times` are the log's (earliest time and count) from a first
  /// pass. `file` names the target in errors. The header is written here.
  LogWriter(std::ostream& out, LogFormat format, const LogTimes& times, std::string file = "");
  ~LogWriter();
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;

  /// Writes one entry. Throws lash::InputError (file, field "frame N") when its time cannot be
  /// written in the format (writable_times): the caller discards the output (AtomicFile).
  void write(const LogEntry& e);
  /// Writes what is buffered and the trailer (BLF: the last container, then the header's sizes
  /// and stop time, by seeking back on a seekable stream).
  void finish();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace lash::can
