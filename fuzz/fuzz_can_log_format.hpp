#pragma once
// The libFuzzer harness shared by the vendor log readers (ASC, BLF, TRC): any input reads
// (bad parts counted as drops) or throws lash::InputError; every frame read is valid and
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

inline int round_trip(Parse parse, Write write, const std::uint8_t* data, std::size_t size) {
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
