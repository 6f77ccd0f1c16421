#include "lash/can/encode.hpp"

#include <charconv>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <fmt/core.h>

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"

namespace lash::can {
namespace {

bool exact_integer(const dbc::Signal& s) {
  return s.value_type == dbc::ValueType::integer && s.factor == 1.0 && s.offset == 0.0;
}

std::uint64_t mask_of(const dbc::Signal& s) { return s.length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << s.length) - 1; }

/// Parses a whole decimal integer into raw bits that fit `s`; false when the text is no integer.
bool parse_exact(const dbc::Signal& s, const std::string& text, std::uint64_t& raw, bool& fits) {
  const char* b = text.data();
  const char* e = b + text.size();
  if (b != e && *b == '+') ++b;
  if (b != e && *b == '-') {
    std::int64_t v = 0;
    auto r = std::from_chars(b, e, v);
    if (r.ec == std::errc::result_out_of_range && r.ptr == e) {
      fits = false;
      return true;
    }
    if (r.ec != std::errc() || r.ptr != e) return false;
    fits = s.is_signed && (s.length >= 64 || v >= -(std::int64_t{1} << (s.length - 1)));
    raw = static_cast<std::uint64_t>(v) & mask_of(s);
    return true;
  }
  std::uint64_t v = 0;
  auto r = std::from_chars(b, e, v);
  if (r.ec == std::errc::result_out_of_range && r.ptr == e) {
    fits = false;
    return true;
  }
  if (r.ec != std::errc() || r.ptr != e) return false;
  const std::uint64_t top = s.is_signed ? mask_of(s) >> 1 : mask_of(s);
  fits = v <= top;
  raw = v;
  return true;
}

}  // namespace

std::uint64_t start_value(const dbc::Database& db, const dbc::Message& m, const dbc::Signal& s) {
  const std::string* text = nullptr;
  for (const auto& a : db.attributes)
    if (a.name == "GenSigStartValue" && a.object == "SG_" && a.signal == s.name &&
        (a.message_dbc_id == m.dbc_id() || (m.extended && a.message_dbc_id == m.id)))
      text = &a.value.text;
  if (!text)
    for (const auto& d : db.attribute_defaults)
      if (d.name == "GenSigStartValue") text = &d.value.text;
  if (!text) return 0;
  double v = 0;
  if (!parse_double(*text, v) || !std::isfinite(v)) return 0;
  std::uint64_t raw = 0;
  bool fits = true;
  if (parse_exact(s, *text, raw, fits) && fits) return raw;
  const double r = round_half_even(v);
  if (r < 0) return static_cast<std::uint64_t>(static_cast<std::int64_t>(r)) & mask_of(s);
  return r >= 1.8446744073709552e19 ? mask_of(s) : static_cast<std::uint64_t>(r) & mask_of(s);
}

std::string format_value(const SignalCodec& c, std::uint64_t raw) {
  const auto& s = c.signal();
  if (exact_integer(s)) {
    if (s.is_signed) return std::to_string(s.value_key(raw));
    return std::to_string(raw);
  }
  return format_double(c.to_physical(raw));
}

EncodeOutcome encode_message(const dbc::Database& db, const dbc::Message& m, const EncodeRequest& req, const std::string& file) {
  std::unique_ptr<MessageCodec> codec;
  try {
    codec = std::make_unique<MessageCodec>(m);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, 0, m.name, e.what());
  }
  const std::size_t n = codec->signal_count();
  std::vector<std::uint64_t> raw(n);
  std::vector<bool> given(n, false);
  EncodeOutcome out;
  for (std::size_t i = 0; i < n; ++i) raw[i] = start_value(db, m, m.signals[i]);
  for (const auto& [name, text] : req.values) {
    const auto idx = codec->index_of(name);
    if (!idx) throw InputError(file, 0, name, "message '" + m.name + "' has no such signal");
    const SignalCodec& c = codec->codec(*idx);
    const dbc::Signal& s = c.signal();
    const bool has_range = s.minimum < s.maximum;
    given[*idx] = true;
    if (auto r = s.value_raw(text)) {
      raw[*idx] = *r;
      continue;
    }
    std::uint64_t r = 0;
    bool fits = true;
    if (exact_integer(s) && parse_exact(s, text, r, fits)) {
      if (!fits) throw InputError(file, 0, name, fmt::format("value {} does not fit the {}-bit {} field", text, s.length, s.is_signed ? "signed" : "unsigned"));
      const double phys = s.is_signed ? static_cast<double>(s.value_key(r)) : static_cast<double>(r);
      if (has_range && (phys < s.minimum || phys > s.maximum)) {
        if (req.clamp) {
          bool ignored = false;
          r = c.to_raw(phys < s.minimum ? s.minimum : s.maximum, ignored);
          out.warnings.push_back(fmt::format("{}={} is outside [{}|{}]: clamped", name, text, format_double(s.minimum), format_double(s.maximum)));
        } else {
          out.warnings.push_back(fmt::format("{}={} is outside [{}|{}]: encoded as given", name, text, format_double(s.minimum), format_double(s.maximum)));
        }
      }
      raw[*idx] = r;
      continue;
    }
    double p = 0;
    if (!parse_double(text, p) || !std::isfinite(p))
      throw InputError(file, 0, name, "'" + text + "' is no number and no value description of the signal");
    if (has_range && (p < s.minimum || p > s.maximum)) {
      out.warnings.push_back(fmt::format("{}={} is outside [{}|{}]: {}", name, text, format_double(s.minimum),
                                         format_double(s.maximum), req.clamp ? "clamped" : "encoded as given"));
      if (req.clamp) p = p < s.minimum ? s.minimum : s.maximum;
    }
    if (s.value_type != dbc::ValueType::integer) {
      bool ignored = false;
      raw[*idx] = c.to_raw(p, ignored);
      continue;
    }
    const double q = round_half_even((p - s.offset) / s.factor);
    const double lo = s.is_signed ? -std::ldexp(1.0, static_cast<int>(s.length) - 1) : 0.0;
    const double hi = std::ldexp(1.0, static_cast<int>(s.is_signed ? s.length - 1 : s.length));
    if (!(q >= lo && q < hi))
      throw InputError(file, 0, name, fmt::format("value {} (raw {}) does not fit the {}-bit {} field", text, format_double(q),
                                                  s.length, s.is_signed ? "signed" : "unsigned"));
    raw[*idx] = q < 0 ? static_cast<std::uint64_t>(static_cast<std::int64_t>(q)) & mask_of(s)
                      : static_cast<std::uint64_t>(q);
  }
  // Which signals the multiplexors select, multiplexors first.
  std::vector<int> present(n, -1);  // -1 unknown
  const auto is_present = [&](auto& self, std::size_t i) -> bool {
    if (present[i] >= 0) return present[i] == 1;
    present[i] = 0;  // guards against cycles (check_layout refuses them)
    const dbc::Signal* p = m.multiplexor_of(m.signals[i]);
    bool on = true;
    if (p) {
      const auto pi = static_cast<std::size_t>(p - m.signals.data());
      on = self(self, pi);
      if (on) {
        on = false;
        const auto& s = m.signals[i];
        if (s.mux_ranges.empty()) on = raw[pi] == s.mux_value;
        for (const auto& r : s.mux_ranges)
          if (raw[pi] >= r.lo && raw[pi] <= r.hi) on = true;
      }
    }
    present[i] = on ? 1 : 0;
    return on;
  };
  Frame& f = out.frame;
  f.id = m.id;
  f.extended = m.extended;
  f.len = static_cast<std::uint8_t>(m.size);
  f.fd = m.size > 8;
  for (std::size_t i = 0; i < n; ++i) {
    if (!is_present(is_present, i)) {
      if (given[i]) out.warnings.push_back(fmt::format("{} is not selected by its multiplexor's value: not encoded", m.signals[i].name));
      continue;
    }
    codec->codec(i).write_raw(f.payload(), raw[i]);
  }
  return out;
}

}  // namespace lash::can
