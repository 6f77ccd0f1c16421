// Layout validation of DBC messages (dbc::check_layout): what makes a message
// impossible to code (errors) or dubious (warnings), found when the file is read.
#include <bitset>
#include <cmath>

#include <fmt/core.h>

#include "lash/can/dbc.hpp"

namespace lash::can::dbc {

std::int64_t Signal::value_key(std::uint64_t raw) const noexcept {
  if (!is_signed || length >= 64 || length == 0) return static_cast<std::int64_t>(raw);
  const unsigned sh = 64 - length;
  return static_cast<std::int64_t>(raw << sh) >> sh;
}

const std::string* Signal::value_text(std::uint64_t raw) const noexcept {
  const std::int64_t key = value_key(raw);
  for (const auto& v : values)
    if (v.value == key) return &v.text;
  return nullptr;
}

std::optional<std::uint64_t> Signal::value_raw(std::string_view text) const noexcept {
  const std::uint64_t mask = length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1;
  for (const auto& v : values)
    if (v.text == text) return static_cast<std::uint64_t>(v.value) & mask;
  return std::nullopt;
}

const Signal* Message::multiplexor_of(const Signal& s) const noexcept {
  if (s.mux != MuxRole::multiplexed) return nullptr;
  if (!s.multiplexor.empty()) return signal(s.multiplexor);
  for (const auto& o : signals)
    if (o.mux == MuxRole::multiplexor) return &o;
  return nullptr;
}

namespace {

using Bits = std::bitset<512>;

/// Bits of the payload a signal occupies (Intel numbering: bit k = bit k%8 of byte k/8);
/// false when it runs past byte 64.
bool occupied(const Signal& s, Bits& bits) {
  for (std::uint32_t i = 0; i < s.length; ++i) {
    std::uint32_t byte, bit;
    if (s.byte_order == ByteOrder::motorola) {
      const std::uint32_t q = 8 * (s.start_bit / 8) + 7 - s.start_bit % 8;  // big-endian index of the MSB
      const std::uint32_t p = q + i;
      byte = p / 8;
      bit = 7 - p % 8;
    } else {
      byte = (s.start_bit + i) / 8;
      bit = (s.start_bit + i) % 8;
    }
    if (byte >= 64) return false;
    bits.set(8 * byte + bit);
  }
  return true;
}

bool ranges_intersect(const std::vector<MuxRange>& a, const std::vector<MuxRange>& b) {
  for (const auto& x : a)
    for (const auto& y : b)
      if (x.lo <= y.hi && y.lo <= x.hi) return true;
  return false;
}

std::vector<MuxRange> selecting(const Signal& s) {
  if (!s.mux_ranges.empty()) return s.mux_ranges;
  return {MuxRange{s.mux_value, s.mux_value}};
}

}  // namespace

std::vector<Diagnostic> check_layout(const Message& m, const std::string& file, bool overlaps) {
  std::vector<Diagnostic> out;
  const auto error = [&](const char* kind, const std::string& msg) {
    out.push_back({Diagnostic::Severity::error, file, 0, kind, fmt::format("message '{}' (id 0x{:X}): {}", m.name, m.id, msg)});
  };
  if (!m.size_is_dlc())
    out.push_back({Diagnostic::Severity::warning, file, 0, "size-not-a-dlc",
                   fmt::format("message '{}' (id 0x{:X}): {} bytes is no CAN FD frame length (12, 16, 20, 24, 32, 48, 64)",
                               m.name, m.id, m.size)});
  std::vector<Bits> bits(m.signals.size());
  std::vector<bool> usable(m.signals.size(), true);
  for (std::size_t i = 0; i < m.signals.size(); ++i) {
    const Signal& s = m.signals[i];
    if (s.length < 1 || s.length > 64) {
      error("bad-signal", fmt::format("signal '{}' has {} bits (1..64)", s.name, s.length));
      usable[i] = false;
      continue;
    }
    if (!(s.factor != 0.0) || !std::isfinite(s.factor) || !std::isfinite(s.offset))
      error("bad-signal", fmt::format("signal '{}' has factor {} (must be finite and non-zero)", s.name, s.factor));
    if ((s.value_type == ValueType::float32 && s.length != 32) || (s.value_type == ValueType::float64 && s.length != 64))
      error("bad-signal", fmt::format("signal '{}': a float type needs 32 or 64 bits", s.name));
    if (!occupied(s, bits[i])) {
      error("signal-out-of-frame", fmt::format("signal '{}' runs past byte 64", s.name));
      usable[i] = false;
      continue;
    }
    std::size_t top = 0;
    for (std::size_t b = 0; b < 512; ++b)
      if (bits[i][b]) top = b;
    if (top / 8 >= m.size)
      error("signal-out-of-frame",
            fmt::format("signal '{}' (start bit {}, {} bits) needs {} bytes but the message has {}", s.name, s.start_bit,
                        s.length, top / 8 + 1, m.size));
    if (s.mux == MuxRole::multiplexed) {
      const Signal* p = m.multiplexor_of(s);
      if (!p) {
        error("mux-without-multiplexor",
              fmt::format("signal '{}' is multiplexed but {}", s.name,
                          s.multiplexor.empty() ? "the message has no multiplexor" : "there is no signal '" + s.multiplexor + "'"));
        continue;
      }
      if (p->mux != MuxRole::multiplexor && !p->mux_switch)
        error("mux-without-multiplexor", fmt::format("signal '{}' is selected by '{}', which is no multiplexor", s.name, p->name));
      // a chain of multiplexors must end at a top-level one
      const Signal* q = &s;
      std::size_t depth = 0;
      while (q && q->mux == MuxRole::multiplexed && depth <= m.signals.size()) {
        q = m.multiplexor_of(*q);
        ++depth;
      }
      if (depth > m.signals.size()) error("mux-cycle", fmt::format("signal '{}': its multiplexors form a cycle", s.name));
    }
  }
  if (!overlaps) return out;
  // Two signals can be present together unless a common multiplexor selects them with disjoint values.
  const auto exclusive = [&](const Signal& a, const Signal& b) {
    for (const Signal* x = &a; x && x->mux == MuxRole::multiplexed; x = m.multiplexor_of(*x))
      for (const Signal* y = &b; y && y->mux == MuxRole::multiplexed; y = m.multiplexor_of(*y))
        if (m.multiplexor_of(*x) == m.multiplexor_of(*y) && !ranges_intersect(selecting(*x), selecting(*y))) return true;
    return false;
  };
  for (std::size_t i = 0; i < m.signals.size(); ++i)
    for (std::size_t j = i + 1; j < m.signals.size(); ++j) {
      if (!usable[i] || !usable[j] || (bits[i] & bits[j]).none()) continue;
      if (exclusive(m.signals[i], m.signals[j])) continue;
      error("overlap", fmt::format("signals '{}' and '{}' share {} bit(s)", m.signals[i].name, m.signals[j].name,
                                   (bits[i] & bits[j]).count()));
    }
  return out;
}

}  // namespace lash::can::dbc
