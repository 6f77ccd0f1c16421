// libFuzzer: candump -L log reader. Any input parses or throws lash::InputError; every
// parsed frame formats back to a line that parses to the same frame.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "lash/can/log.hpp"
#include "lash/io/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<lash::can::LogEntry> entries;
  try {
    entries = lash::can::parse_log(text, "fuzz.log");
  } catch (const lash::InputError&) {
    return 0;
  }
  for (const auto& e : entries) {
    if (!e.frame.valid()) std::abort();
    std::string err;
    const auto back = lash::can::parse_log_line(lash::can::format_log_line(e.frame, e.interface), err);
    if (!back || !lash::can::same_content(back->frame, e.frame) || back->frame.fd != e.frame.fd) std::abort();
  }
  return 0;
}
