#pragma once
/// @file bench_layout.hpp
/// Where the hydraulic bench's signals sit in its CAN frames, read once from
/// config/hydraulic_bench.dbc (docs/method.md §B3, thesis paper 2 §2.7.3 Figs 2.17–2.18),
/// and the real-time pack/unpack of those frames.
///
///   BenchCommand (master → slave): SolenoidA_Current, SolenoidB_Current,
///                                  RestrictorValve_Cmd [mA], Command_Counter (8 bit),
///                                  Command_CRC
///   BenchSensors (slave → master): PilotPressure_Duty, SupplyPressure_Duty
///                                  [uint16 duty code], Sensor_Counter (16 bit), Sensor_CRC
///   CCP_CRO / CCP_DTO: the CONNECT handshake, can::ccp::Layout (can/ccp.hpp),
///                      which BenchLayout extends.
///
/// The pilot pressure travels as the sensor code of docs/method.md §B1
/// raw = round((p/48.82 + 5.98)·(2¹⁶ − 1)/100); both ends convert with
/// lash::encode_pressure_raw / decode_pressure_raw (rigs/pilot_valve_model.hpp).
/// Currents are raw = round(mA / factor) with the DBC factor (0.1 mA),
/// clamped to the signal's bit range. pack/unpack are noexcept and O(1).
///
/// Both cyclic frames are E2E-protected (hil/e2e.hpp): pack_* writes the CRC-8 SAE J1850
/// of the data ID and payload into the CRC byte; check_* is the receiver's stateless part
/// of the plausibility check (DLC, CRC, DBC ranges), noexcept and allocation-free.
#include <cstdint>
#include <filesystem>
#include <optional>

#include "lash/can/bit_field.hpp"
#include "lash/can/ccp.hpp"
#include "lash/can/frame.hpp"
#include "lash/hil/e2e.hpp"

namespace lash::hil {

/// One signal of a frame as the DBC places it (can/bit_field.hpp).
using can::BitField;

/// A field's plausibility data, precomputed from its BitField: where its bits sit in the
/// frame's 8 data bytes read as one little-endian word (Intel fields), and the raw codes
/// whose physical value raw·factor + offset lies in the DBC's [min|max] (a relative
/// tolerance of 1e-9 absorbs decimal factors; no range given = every code).
struct FieldCheck {
  bool intel = false;
  std::uint32_t shift = 0;
  std::uint64_t mask = 0, lo = 0, hi = ~std::uint64_t{0};

  static FieldCheck of(const BitField& field) noexcept;
  /// The field's raw bits: one shift and mask of `le` for an Intel field, the codec otherwise.
  std::uint64_t get(const BitField& field, const can::Frame& f, std::uint64_t le) const noexcept {
    return intel ? (le >> shift) & mask : field.get(f);
  }
  bool in_range(std::uint64_t raw) const noexcept { return raw >= lo && raw <= hi; }
};

/// The 8 data bytes of a frame as one little-endian word (byte 0 = bits 0..7).
inline std::uint64_t load_le(const can::Frame& f) noexcept {
  std::uint64_t w = 0;
  for (std::size_t i = 0; i < 8; ++i) w |= static_cast<std::uint64_t>(f.data[i]) << (8 * i);
  return w;
}

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
  std::uint32_t xcp_cmd_id = 0x7F0, xcp_res_id = 0x7F1;  ///< XCP on CAN: CAN_ID_MASTER / CAN_ID_SLAVE (XCP_CMD / XCP_RES)
  std::uint8_t command_len = 8, sensors_len = 8;
  // Defaults: the layout of config/hydraulic_bench.dbc.
  BitField solenoid_a{0, 16, 0.1, 0, 2000}, solenoid_b{16, 16, 0.1, 0, 2000}, restrictor{32, 16, 0.1, 0, 2000},
      command_counter{48, 8, 1.0}, command_crc{56, 8, 1.0};
  BitField pilot{0, 16, 0.00152590218966964, 5, 95}, supply{16, 16, 0.00152590218966964, 0, 100},
      sensor_counter{32, 16, 1.0}, sensors_crc{56, 8, 1.0};

  BenchLayout() { refresh_checks(); }
  /// Recomputes the plausibility data of the fields above; call it after changing one.
  void refresh_checks() noexcept;

  /// Reads the layout from a DBC file. Throws lash::InputError naming the file and the
  /// missing message/signal (a command counter of 4..16 bits, a sensor counter of 16 bits,
  /// a CRC that is not one whole byte of the frame). Not real-time safe.
  static BenchLayout from_dbc(const std::filesystem::path& dbc_file);

  /// The counter goes on the bus modulo 2^(counter bits); the CRC is computed last.
  can::Frame pack_command(const CommandMsg& m) const noexcept;
  CommandMsg unpack_command(const can::Frame& f) const noexcept;
  can::Frame pack_sensors(const SensorMsg& m) const noexcept;
  SensorMsg unpack_sensors(const can::Frame& f) const noexcept;
  /// The stateless plausibility check of a frame that has the message's identifier:
  /// nullopt = DLC, CRC and every data signal's DBC range are right; else the first failure.
  std::optional<Drop> check_command(const can::Frame& f) const noexcept;
  std::optional<Drop> check_sensors(const can::Frame& f) const noexcept;
  /// The same checks, and the decoded message in `out` when they pass (one read of the payload).
  std::optional<Drop> check_command(const can::Frame& f, CommandMsg& out) const noexcept;
  std::optional<Drop> check_sensors(const can::Frame& f, SensorMsg& out) const noexcept;
  /// CRC-8 SAE J1850 of a frame: data ID (identifier low byte, high byte), then every
  /// payload byte except the CRC byte `crc` occupies.
  static std::uint8_t e2e_crc(const can::Frame& f, const BitField& crc) noexcept;
  /// The same with the CRC's byte index.
  static std::uint8_t e2e_crc(const can::Frame& f, std::size_t crc_byte) noexcept;
  std::uint32_t command_counter_bits() const noexcept { return command_counter.signal().length; }
  std::uint32_t sensor_counter_bits() const noexcept { return sensor_counter.signal().length; }
  /// Plausibility data of the fields (refresh_checks()).
  struct Checks {
    FieldCheck solenoid_a, solenoid_b, restrictor, command_counter, command_crc, pilot, supply, sensor_counter,
        sensors_crc;
  } checks;

  /// Current command quantisation: what the slave decodes for a commanded current [mA].
  double quantize_current(double mA) const noexcept { return solenoid_a.to_physical(solenoid_a.to_raw(mA)); }
};

/// Counter distance b − a mod 2¹⁶ (1 = the next frame).
inline std::uint16_t counter_delta(std::uint16_t a, std::uint16_t b) noexcept {
  return static_cast<std::uint16_t>(b - a);
}

}  // namespace lash::hil
