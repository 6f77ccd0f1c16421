#include "lash/hil/bench_layout.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace lash::hil {

namespace {
can::dbc::Signal make_signal(std::uint32_t start_bit, std::uint32_t length, double factor, double lo, double hi,
                             bool intel) {
  can::dbc::Signal s;
  s.name = "field";
  s.start_bit = start_bit;
  s.length = length;
  s.byte_order = intel ? can::dbc::ByteOrder::intel : can::dbc::ByteOrder::motorola;
  s.factor = factor;
  s.minimum = lo;
  s.maximum = hi;
  return s;
}
}  // namespace

BitField::BitField(std::uint32_t start_bit, std::uint32_t length, double factor, double lo, double hi, bool intel)
    : codec_(make_signal(start_bit, length, factor, lo, hi, intel)) {
  set_raw_range();
}

BitField::BitField(const can::dbc::Signal& signal) : codec_(signal) { set_raw_range(); }

// The raw codes whose physical value raw·factor + offset lies in [min, max] (a relative
// tolerance of 1e-9 absorbs the DBC's decimal factors), for unsigned integer signals.
void BitField::set_raw_range() noexcept {
  const auto& s = codec_.signal();
  const std::uint64_t top = s.length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << s.length) - 1u;
  intel_ = s.byte_order == can::dbc::ByteOrder::intel && s.start_bit + s.length <= 64;
  shift_ = s.start_bit;
  mask_ = top;
  raw_lo_ = 0;
  raw_hi_ = top;
  if ((s.minimum == 0.0 && s.maximum == 0.0) || s.is_signed || s.value_type != can::dbc::ValueType::integer ||
      s.factor == 0.0)
    return;
  double a = (s.minimum - s.offset) / s.factor, b = (s.maximum - s.offset) / s.factor;
  if (a > b) std::swap(a, b);
  const double tol = 1e-9 * std::max({1.0, std::abs(a), std::abs(b)});
  const double lo = std::ceil(a - tol), hi = std::floor(b + tol);
  const double dtop = static_cast<double>(top);
  if (hi < 0 || lo > dtop || lo > hi) {  // an empty range: nothing is plausible
    raw_lo_ = 1;
    raw_hi_ = 0;
    return;
  }
  raw_lo_ = lo <= 0 ? 0 : static_cast<std::uint64_t>(lo);
  raw_hi_ = hi >= dtop ? top : static_cast<std::uint64_t>(hi);
}

std::uint8_t BenchLayout::e2e_crc(const can::Frame& f, const BitField& crc) noexcept {
  const std::size_t at = crc.signal().start_bit / 8;
  std::uint8_t reg = Crc8SaeJ1850::kInit;
  reg = Crc8SaeJ1850::update(reg, static_cast<std::uint8_t>(f.id & 0xFFu));
  reg = Crc8SaeJ1850::update(reg, static_cast<std::uint8_t>((f.id >> 8) & 0xFFu));
  const std::size_t n = f.len <= can::Frame::kMaxClassicLen ? f.len : can::Frame::kMaxClassicLen;
  const std::size_t head = at < n ? at : n;
  for (std::size_t i = 0; i < head; ++i) reg = Crc8SaeJ1850::update(reg, f.data[i]);
  for (std::size_t i = head + 1; i < n; ++i) reg = Crc8SaeJ1850::update(reg, f.data[i]);
  return Crc8SaeJ1850::finish(reg);
}

can::Frame BenchLayout::pack_command(const CommandMsg& m) const noexcept {
  can::Frame f;
  f.id = command_id;
  f.len = command_len;
  solenoid_a.put(f, solenoid_a.to_raw(m.solenoid_a_mA));
  solenoid_b.put(f, solenoid_b.to_raw(m.solenoid_b_mA));
  restrictor.put(f, restrictor.to_raw(m.restrictor_mA));
  command_counter.put(f, m.counter);
  command_crc.put(f, e2e_crc(f, command_crc));
  return f;
}

std::optional<Drop> BenchLayout::check_command(const can::Frame& f) const noexcept {
  if (f.remote || f.len != command_len) return Drop::dlc;
  const std::uint64_t w = load_le(f);
  if (command_crc.get(f, w) != e2e_crc(f, command_crc)) return Drop::crc;
  if (!solenoid_a.in_range(solenoid_a.get(f, w)) || !solenoid_b.in_range(solenoid_b.get(f, w)) ||
      !restrictor.in_range(restrictor.get(f, w)))
    return Drop::range;
  return std::nullopt;
}

std::optional<Drop> BenchLayout::check_sensors(const can::Frame& f) const noexcept {
  if (f.remote || f.len != sensors_len) return Drop::dlc;
  const std::uint64_t w = load_le(f);
  if (sensors_crc.get(f, w) != e2e_crc(f, sensors_crc)) return Drop::crc;
  if (!pilot.in_range(pilot.get(f, w)) || !supply.in_range(supply.get(f, w))) return Drop::range;
  return std::nullopt;
}

CommandMsg BenchLayout::unpack_command(const can::Frame& f) const noexcept {
  CommandMsg m;
  m.solenoid_a_mA = solenoid_a.to_physical(solenoid_a.get(f));
  m.solenoid_b_mA = solenoid_b.to_physical(solenoid_b.get(f));
  m.restrictor_mA = restrictor.to_physical(restrictor.get(f));
  m.counter = static_cast<std::uint16_t>(command_counter.get(f));
  return m;
}

can::Frame BenchLayout::pack_sensors(const SensorMsg& m) const noexcept {
  can::Frame f;
  f.id = sensors_id;
  f.len = sensors_len;
  pilot.put(f, m.pilot_raw);
  supply.put(f, m.supply_raw);
  sensor_counter.put(f, m.counter);
  sensors_crc.put(f, e2e_crc(f, sensors_crc));
  return f;
}

SensorMsg BenchLayout::unpack_sensors(const can::Frame& f) const noexcept {
  SensorMsg m;
  m.pilot_raw = static_cast<std::uint16_t>(pilot.get(f));
  m.supply_raw = static_cast<std::uint16_t>(supply.get(f));
  m.counter = static_cast<std::uint16_t>(sensor_counter.get(f));
  return m;
}

can::Frame BenchLayout::pack_connect(std::uint8_t ctr) const noexcept {
  can::Frame f;
  f.id = cro_id;
  f.len = cro_len;
  cro_cmd.put(f, 0x01);
  cro_ctr.put(f, ctr);
  return f;
}

bool BenchLayout::is_connect(const can::Frame& f) const noexcept {
  return !f.extended && !f.remote && f.id == cro_id && f.len >= 1 && cro_cmd.get(f) == 0x01;
}

bool BenchLayout::is_connect_ack(const can::Frame& f) const noexcept {
  return !f.extended && !f.remote && f.id == dto_id && f.len >= 2 && dto_pid.get(f) == 0xFF && dto_err.get(f) == 0x00;
}

}  // namespace lash::hil
