#pragma once
/// @file bench_layout.hpp
/// Where the hydraulic bench's signals sit in its CAN frames, read once from
/// config/hydraulic_bench.dbc (SPEC B3, thesis paper 2 §2.7.3 Figs 2.17–2.18),
/// and the real-time pack/unpack of those frames.
///
///   BenchCommand (master → slave): SolenoidA_Current, SolenoidB_Current,
///                                  RestrictorValve_Cmd [mA], Command_Counter
///   BenchSensors (slave → master): PilotPressure_Duty, SupplyPressure_Duty
///                                  [uint16 duty code], Sensor_Counter
///   CCP_CRO / CCP_DTO: the CONNECT handshake, can::ccp::Layout (can/ccp.hpp),
///                      which BenchLayout extends.
///
/// The pilot pressure travels as the SPEC B1 sensor code
/// raw = round((p/48.82 + 5.98)·(2¹⁶ − 1)/100); both ends convert with
/// lash::encode_pressure_raw / decode_pressure_raw (rigs/pilot_valve_model.hpp).
/// Currents are raw = round(mA / factor) with the DBC factor (0.1 mA),
/// clamped to the signal's bit range. pack/unpack are noexcept and O(1).
#include <cstdint>
#include <filesystem>

#include "lash/can/bit_field.hpp"
#include "lash/can/ccp.hpp"
#include "lash/can/frame.hpp"

namespace lash::hil {

/// One signal of a frame as the DBC places it (can/bit_field.hpp).
using can::BitField;

/// Decoded BenchCommand.
struct CommandMsg {
  double solenoid_a_mA = 0.0;
  double solenoid_b_mA = 0.0;
  double restrictor_mA = 0.0;
  std::uint16_t counter = 0;
};

/// Decoded BenchSensors (raw sensor codes).
struct SensorMsg {
  std::uint16_t pilot_raw = 0;
  std::uint16_t supply_raw = 0;
  std::uint16_t counter = 0;
};

/// The bench's frames: its own command and sensor messages plus the CCP handshake
/// (cro_id, dto_id, pack_connect, is_connect, is_connect_ack from can::ccp::Layout).
struct BenchLayout : can::ccp::Layout {
  std::uint32_t command_id = 0x100, sensors_id = 0x200;
  std::uint8_t command_len = 8, sensors_len = 6;
  // Defaults: the layout of config/hydraulic_bench.dbc.
  BitField solenoid_a{0, 16, 0.1, 0, 2000}, solenoid_b{16, 16, 0.1, 0, 2000}, restrictor{32, 16, 0.1, 0, 2000},
      command_counter{48, 16, 1.0};
  BitField pilot{0, 16, 0.00152590218966964, 0, 100}, supply{16, 16, 0.00152590218966964, 0, 100},
      sensor_counter{32, 16, 1.0};

  /// Reads the layout from a DBC file. Throws lash::InputError naming the file and the
  /// missing message/signal (or a counter narrower than 8 bits). Not real-time safe.
  static BenchLayout from_dbc(const std::filesystem::path& dbc_file);

  can::Frame pack_command(const CommandMsg& m) const noexcept;
  CommandMsg unpack_command(const can::Frame& f) const noexcept;
  can::Frame pack_sensors(const SensorMsg& m) const noexcept;
  SensorMsg unpack_sensors(const can::Frame& f) const noexcept;

  /// Current command quantisation: what the slave decodes for a commanded current [mA].
  double quantize_current(double mA) const noexcept { return solenoid_a.to_physical(solenoid_a.to_raw(mA)); }
};

/// Counter distance b − a mod 2¹⁶ (1 = the next frame).
inline std::uint16_t counter_delta(std::uint16_t a, std::uint16_t b) noexcept {
  return static_cast<std::uint16_t>(b - a);
}

}  // namespace lash::hil
