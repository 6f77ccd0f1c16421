#include "lash/hil/bench_layout.hpp"

namespace lash::hil {

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

}  // namespace lash::hil
