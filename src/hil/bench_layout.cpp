#include "lash/hil/bench_layout.hpp"


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
    : codec_(make_signal(start_bit, length, factor, lo, hi, intel)) {}

BitField::BitField(const can::dbc::Signal& signal) : codec_(signal) {}

can::Frame BenchLayout::pack_command(const CommandMsg& m) const noexcept {
  can::Frame f;
  f.id = command_id;
  f.len = command_len;
  solenoid_a.put(f, solenoid_a.to_raw(m.solenoid_a_mA));
  solenoid_b.put(f, solenoid_b.to_raw(m.solenoid_b_mA));
  restrictor.put(f, restrictor.to_raw(m.restrictor_mA));
  command_counter.put(f, m.counter);
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
