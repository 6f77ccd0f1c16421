#include "lash/hil/bench_layout.hpp"

#include <cmath>

namespace lash::hil {

void BitField::put(can::Frame& f, std::uint64_t raw) const noexcept {
  raw &= max_raw();
  if (intel) {
    for (std::uint32_t i = 0; i < length; ++i) {
      const std::uint32_t bit = start_bit + i;
      if (bit >= 64) return;
      const auto byte = bit / 8, pos = bit % 8;
      const auto mask = static_cast<std::uint8_t>(1u << pos);
      if ((raw >> i) & 1u)
        f.data[byte] = static_cast<std::uint8_t>(f.data[byte] | mask);
      else
        f.data[byte] = static_cast<std::uint8_t>(f.data[byte] & ~mask);
    }
  } else {
    // Motorola: start bit is the MSB; walk down the sawtooth numbering.
    std::uint32_t bit = start_bit;
    for (std::uint32_t i = 0; i < length; ++i) {
      if (bit >= 64) return;
      const auto byte = bit / 8, pos = bit % 8;
      const auto mask = static_cast<std::uint8_t>(1u << pos);
      if ((raw >> (length - 1 - i)) & 1u)
        f.data[byte] = static_cast<std::uint8_t>(f.data[byte] | mask);
      else
        f.data[byte] = static_cast<std::uint8_t>(f.data[byte] & ~mask);
      bit = (pos == 0) ? bit + 15 : bit - 1;
    }
  }
}

std::uint64_t BitField::get(const can::Frame& f) const noexcept {
  std::uint64_t raw = 0;
  if (intel) {
    for (std::uint32_t i = 0; i < length; ++i) {
      const std::uint32_t bit = start_bit + i;
      if (bit >= 64) break;
      if ((f.data[bit / 8] >> (bit % 8)) & 1u) raw |= (1ULL << i);
    }
  } else {
    std::uint32_t bit = start_bit;
    for (std::uint32_t i = 0; i < length; ++i) {
      if (bit >= 64) break;
      const auto pos = bit % 8;
      raw = (raw << 1) | ((f.data[bit / 8] >> pos) & 1u);
      bit = (pos == 0) ? bit + 15 : bit - 1;
    }
  }
  return raw;
}

std::uint64_t BitField::to_raw(double physical) const noexcept {
  const double r = std::round((physical - offset) / factor);
  if (!(r > 0.0)) return 0;  // also NaN
  const double top = static_cast<double>(max_raw());
  if (r >= top) return max_raw();
  return static_cast<std::uint64_t>(r);
}

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
