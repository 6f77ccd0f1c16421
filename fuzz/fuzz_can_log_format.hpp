#pragma once
// The libFuzzer harness shared by the vendor log readers (ASC, BLF, TRC): any input reads
// (bad parts counted as drops) or throws lash::InputError; the streaming reader (LogReader)
// fed the bytes in small pieces gives the same frames and drops; every frame read is valid and
// survives a write → read round trip in the same format with no drop, unless the writer
// refuses a time the format cannot hold (lash::InputError, see can::writable_times).
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "../src/can/log_formats.hpp"
#include "lash/io/error.hpp"

namespace lash::can::fuzz {

using Parse = std::vector<LogEntry> (*)(std::string_view, const std::string&, LogReadReport*);
using Write = void (*)(std::ostream&, const std::vector<LogEntry>&);

/// The bytes read `chunk` at a time by LogReader give `entries` and `report`'s drops.
inline void same_in_pieces(std::string_view in, LogFormat format, std::size_t chunk, const std::vector<LogEntry>& entries,
                           const LogReadReport& report) {
  LogReadReport again;
  std::vector<LogEntry> got;
  LogReader r(in, format, "fuzz.log", &again, chunk);
  for (LogEntry e; r.next(e);) got.push_back(e);
  if (got.size() != entries.size() || again.problems != report.problems) std::abort();
  for (std::size_t i = 0; i < got.size(); ++i)
    if (!same_content(got[i].frame, entries[i].frame) || got[i].interface != entries[i].interface) std::abort();
}

inline int round_trip(Parse parse, Write write, LogFormat format, const std::uint8_t* data, std::size_t size) {
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  std::vector<LogEntry> entries;
  LogReadReport report;
  try {
    entries = parse(in, "fuzz.log", &report);
  } catch (const lash::InputError&) {
    return 0;
  }
  for (const auto& e : entries)
    if (!e.frame.valid()) std::abort();
  same_in_pieces(in, format, 1 + size % 13, entries, report);
  std::ostringstream os;
  try {
    write(os, entries);
  } catch (const lash::InputError&) {
    return 0;  // a time the format cannot hold: refused before a byte is written
  }
  LogReadReport again;
  const auto back = parse(os.str(), "fuzz-back.log", &again);
  if (back.size() != entries.size() || again.dropped != 0) std::abort();
  for (std::size_t i = 0; i < back.size(); ++i)
    if (!same_content(back[i].frame, entries[i].frame)) std::abort();
  return 0;
}

}  // namespace lash::can::fuzz
