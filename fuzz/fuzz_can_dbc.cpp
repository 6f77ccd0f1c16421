// libFuzzer: DBC parser. Any input either parses or throws lash::InputError. Strict mode:
// what parses writes back to text that parses to the same Database. Tolerant mode (the
// default): what loads writes back to text that loads again. Every codec
// built from it decodes and encodes a payload without touching memory it should not.
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "lash/can/codec.hpp"
#include "lash/can/dbc.hpp"
#include "lash/io/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto strict = lash::can::dbc::parse_dbc(text, "fuzz.dbc", {true});
    const auto again = lash::can::dbc::parse_dbc(lash::can::dbc::write_dbc(strict), "written.dbc", {true});
    if (!(again == strict)) std::abort();
  } catch (const lash::InputError&) {
  }
  lash::can::dbc::Database db;
  try {
    std::vector<lash::can::dbc::Diagnostic> diags;
    db = lash::can::dbc::parse_dbc(text, "fuzz.dbc", {}, &diags);
  } catch (const lash::InputError&) {
    return 0;
  }
  // What a tolerant read recovered from garbage need not be a fixed point of write → read,
  // but the text written from it must load again.
  std::vector<lash::can::dbc::Diagnostic> diags;
  try {
    (void)lash::can::dbc::parse_dbc(lash::can::dbc::write_dbc(db), "written.dbc", {}, &diags);
  } catch (const lash::InputError&) {
    std::abort();
  }
  std::uint8_t payload[64];
  for (std::size_t i = 0; i < sizeof payload; ++i) payload[i] = static_cast<std::uint8_t>(i * 37u);
  for (const auto& m : db.messages) {
    try {
      lash::can::MessageCodec c(m);
      double values[512];
      if (c.signal_count() <= 512) {
        c.decode({payload, m.size}, {values, c.signal_count()});
        c.encode({values, c.signal_count()}, {payload, m.size});
      }
    } catch (const std::invalid_argument&) {
    }
  }
  return 0;
}
