// libFuzzer: the ASC log reader. Any input reads (bad parts counted as drops) or
// throws lash::InputError; every frame read is valid and survives a write → read
// round trip in the same format.
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

#include "../src/can/log_formats.hpp"
#include "lash/io/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lash::can;
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  std::vector<LogEntry> entries;
  LogReadReport report;
  try {
    entries = detail::parse_asc(in, "fuzz.asc", &report);
  } catch (const lash::InputError&) {
    return 0;
  }
  for (const auto& e : entries)
    if (!e.frame.valid()) std::abort();
  std::ostringstream os;
  detail::write_asc(os, entries);
  LogReadReport again;
  const auto back = detail::parse_asc(os.str(), "fuzz-back.asc", &again);
  if (back.size() != entries.size() || again.dropped != 0) std::abort();
  for (std::size_t i = 0; i < back.size(); ++i)
    if (!same_content(back[i].frame, entries[i].frame)) std::abort();
  return 0;
}
