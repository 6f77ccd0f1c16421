#include "lash/hil/bench_layout.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace lash::hil {

FieldCheck FieldCheck::of(const BitField& field) noexcept {
  const auto& s = field.signal();
  FieldCheck c;
  const std::uint64_t top = s.length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << s.length) - 1u;
  c.intel = s.byte_order == can::dbc::ByteOrder::intel && s.start_bit + s.length <= 64;
  c.shift = s.start_bit;
  c.mask = top;
  c.lo = 0;
  c.hi = top;
  if ((s.minimum == 0.0 && s.maximum == 0.0) || s.is_signed || s.value_type != can::dbc::ValueType::integer ||
      s.factor == 0.0)
    return c;
  double a = (s.minimum - s.offset) / s.factor, b = (s.maximum - s.offset) / s.factor;
  if (a > b) std::swap(a, b);
  const double tol = 1e-9 * std::max({1.0, std::abs(a), std::abs(b)});
  const double lo = std::ceil(a - tol), hi = std::floor(b + tol);
  const double dtop = static_cast<double>(top);
  if (hi < 0 || lo > dtop || lo > hi) {  // an empty range: nothing is plausible
    c.lo = 1;
    c.hi = 0;
    return c;
  }
  c.lo = lo <= 0 ? 0 : static_cast<std::uint64_t>(lo);
  c.hi = hi >= dtop ? top : static_cast<std::uint64_t>(hi);
  return c;
}

void BenchLayout::refresh_checks() noexcept {
  checks = Checks{FieldCheck::of(solenoid_a),     FieldCheck::of(solenoid_b), FieldCheck::of(restrictor),
                  FieldCheck::of(command_counter), FieldCheck::of(command_crc), FieldCheck::of(pilot),
                  FieldCheck::of(supply),          FieldCheck::of(sensor_counter), FieldCheck::of(sensors_crc)};
}

std::uint8_t BenchLayout::e2e_crc(const can::Frame& f, const BitField& crc) noexcept {
  return e2e_crc(f, crc.signal().start_bit / 8);
}

std::uint8_t BenchLayout::e2e_crc(const can::Frame& f, std::size_t at) noexcept {
  std::uint8_t reg = Crc8SaeJ1850::kInit;
  reg = Crc8SaeJ1850::update(reg, static_cast<std::uint8_t>(f.id & 0xFFu));
  reg = Crc8SaeJ1850::update(reg, static_cast<std::uint8_t>((f.id >> 8) & 0xFFu));
  const std::size_t n = f.len <= can::Frame::kMaxClassicLen ? f.len : can::Frame::kMaxClassicLen;
  const std::size_t head = at < n ? at : n;
  for (std::size_t i = 0; i < head; ++i) reg = Crc8SaeJ1850::update(reg, f.data[i]);
  for (std::size_t i = head + 1; i < n; ++i) reg = Crc8SaeJ1850::update(reg, f.data[i]);
  return Crc8SaeJ1850::finish(reg);
}

std::optional<Drop> BenchLayout::check_command(const can::Frame& f, CommandMsg& out) const noexcept {
  if (f.remote || f.len != command_len) return Drop::dlc;
  const std::uint64_t w = load_le(f);
  const Checks& c = checks;
  if (c.command_crc.get(command_crc, f, w) != e2e_crc(f, c.command_crc.shift / 8)) return Drop::crc;
  const std::uint64_t a = c.solenoid_a.get(solenoid_a, f, w), b = c.solenoid_b.get(solenoid_b, f, w),
                      r = c.restrictor.get(restrictor, f, w);
  if (!c.solenoid_a.in_range(a) || !c.solenoid_b.in_range(b) || !c.restrictor.in_range(r)) return Drop::range;
  out.solenoid_a_mA = solenoid_a.to_physical(a);
  out.solenoid_b_mA = solenoid_b.to_physical(b);
  out.restrictor_mA = restrictor.to_physical(r);
  out.counter = static_cast<std::uint16_t>(c.command_counter.get(command_counter, f, w));
  return std::nullopt;
}

std::optional<Drop> BenchLayout::check_sensors(const can::Frame& f, SensorMsg& out) const noexcept {
  if (f.remote || f.len != sensors_len) return Drop::dlc;
  const std::uint64_t w = load_le(f);
  const Checks& c = checks;
  if (c.sensors_crc.get(sensors_crc, f, w) != e2e_crc(f, c.sensors_crc.shift / 8)) return Drop::crc;
  const std::uint64_t p = c.pilot.get(pilot, f, w), s = c.supply.get(supply, f, w);
  if (!c.pilot.in_range(p) || !c.supply.in_range(s)) return Drop::range;
  out.pilot_raw = static_cast<std::uint16_t>(p);
  out.supply_raw = static_cast<std::uint16_t>(s);
  out.counter = static_cast<std::uint16_t>(c.sensor_counter.get(sensor_counter, f, w));
  return std::nullopt;
}

std::optional<Drop> BenchLayout::check_command(const can::Frame& f) const noexcept {
  CommandMsg m;
  return check_command(f, m);
}

std::optional<Drop> BenchLayout::check_sensors(const can::Frame& f) const noexcept {
  SensorMsg m;
  return check_sensors(f, m);
}

can::Frame BenchLayout::pack_command(const CommandMsg& m) const noexcept {
  can::Frame f;
  f.id = command_id;
  f.len = command_len;
  solenoid_a.put(f, solenoid_a.to_raw(m.solenoid_a_mA));
  solenoid_b.put(f, solenoid_b.to_raw(m.solenoid_b_mA));
  restrictor.put(f, restrictor.to_raw(m.restrictor_mA));
  command_counter.put(f, m.counter);
  f.data[checks.command_crc.shift / 8] = e2e_crc(f, checks.command_crc.shift / 8);  // a whole byte (from_dbc)
  return f;
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
  f.data[checks.sensors_crc.shift / 8] = e2e_crc(f, checks.sensors_crc.shift / 8);
  return f;
}

SensorMsg BenchLayout::unpack_sensors(const can::Frame& f) const noexcept {
  SensorMsg m;
  m.pilot_raw = static_cast<std::uint16_t>(pilot.get(f));
  m.supply_raw = static_cast<std::uint16_t>(supply.get(f));
  m.counter = static_cast<std::uint16_t>(sensor_counter.get(f));
  return m;
}

}  // namespace lash::hil
