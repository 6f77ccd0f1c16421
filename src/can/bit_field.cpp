#include "lash/can/bit_field.hpp"

#include <stdexcept>

#include "lash/io/error.hpp"

namespace lash::can {

namespace {
dbc::Signal make_signal(std::uint32_t start_bit, std::uint32_t length, double factor, double lo, double hi,
                        bool intel) {
  dbc::Signal s;
  s.name = "field";
  s.start_bit = start_bit;
  s.length = length;
  s.byte_order = intel ? dbc::ByteOrder::intel : dbc::ByteOrder::motorola;
  s.factor = factor;
  s.minimum = lo;
  s.maximum = hi;
  return s;
}
}  // namespace

BitField::BitField(std::uint32_t start_bit, std::uint32_t length, double factor, double lo, double hi, bool intel)
    : codec_(make_signal(start_bit, length, factor, lo, hi, intel)) {}

BitField::BitField(const dbc::Signal& signal) : codec_(signal) {}

BitField BitField::from_message(const dbc::Message& m, const char* name, const std::string& file,
                                std::uint32_t min_bits, std::uint32_t max_bits) {
  const auto* s = m.signal(name);
  const std::string where = m.name + "." + name;
  if (s == nullptr) throw InputError(file, 0, where, "the DBC has no signal " + where);
  if (s->is_signed || s->value_type != dbc::ValueType::integer)
    throw InputError(file, 0, where, "must be an unsigned integer signal");
  if (s->length < min_bits || s->length > max_bits)
    throw InputError(file, 0, where, "must be " + std::to_string(min_bits) + ".." + std::to_string(max_bits) + " bits long");
  if (s->factor == 0.0) throw InputError(file, 0, where, "factor must not be 0");
  try {
    return BitField(*s);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, 0, where, e.what());
  }
}

const dbc::Message& standard_message(const dbc::Database& db, const char* name, const std::string& file) {
  const auto* m = db.message(std::string_view(name));
  if (m == nullptr) throw InputError(file, 0, name, std::string("the DBC has no message ") + name);
  if (m->extended) throw InputError(file, 0, name, std::string(name) + " must use an 11-bit identifier (CAN 2.0A)");
  return *m;
}

std::uint8_t classic_length(const dbc::Message& m, const std::string& file) {
  if (m.size > 8) throw InputError(file, 0, m.name, "classic CAN frames carry at most 8 bytes");
  return static_cast<std::uint8_t>(m.size);
}

}  // namespace lash::can
