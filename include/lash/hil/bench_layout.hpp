#pragma once
/// @file bench_layout.hpp
/// Where the hydraulic bench's signals sit in its CAN frames, read once from
/// config/hydraulic_bench.dbc (SPEC B3, thesis paper 2 §2.7.3 Figs 2.17–2.18),
/// and the real-time pack/unpack of those frames.
///
///   BenchCommand (master → slave): SolenoidA_Current, SolenoidB_Current,
///                                  RestrictorValve_Cmd [mA], Command_Counter (8 bit),
///                                  Command_CRC
///   BenchSensors (slave → master): PilotPressure_Duty, SupplyPressure_Duty
///                                  [uint16 duty code], Sensor_Counter (16 bit), Sensor_CRC
///   CCP_CRO / CCP_DTO: the CONNECT handshake (CRO_CMD = 0x01; DTO_PID = 0xFF).
///
/// The pilot pressure travels as the SPEC B1 sensor code
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

#include "lash/can/codec.hpp"
#include "lash/can/dbc.hpp"
#include "lash/can/frame.hpp"
#include "lash/hil/e2e.hpp"

namespace lash::hil {

/// One signal of a frame as the DBC places it, coded by the CAN layer's SignalCodec
/// (can/codec.hpp: Intel/Motorola bit placement, physical → raw rounding to nearest and
/// clamping to the DBC range). All members are noexcept and O(1).
class BitField {
 public:
  /// An unsigned Intel signal: start bit (LSB), length, factor, physical range [lo, hi]
  /// (lo == hi: no range). `intel = false` places it Motorola (start bit = MSB).
  BitField(std::uint32_t start_bit, std::uint32_t length, double factor, double lo = 0.0, double hi = 0.0,
           bool intel = true);
  explicit BitField(const can::dbc::Signal& signal);

  void put(can::Frame& f, std::uint64_t raw) const noexcept {
    codec_.write_raw({f.data.data(), can::Frame::kMaxClassicLen}, raw);
  }
  std::uint64_t get(const can::Frame& f) const noexcept {
    return codec_.read_raw({f.data.data(), can::Frame::kMaxClassicLen}).value_or(0);
  }
  /// The same raw bits from the frame's 8 data bytes loaded as one little-endian word `le`
  /// (one shift and mask for an Intel field; the codec for a Motorola one).
  std::uint64_t get(const can::Frame& f, std::uint64_t le) const noexcept {
    return intel_ ? (le >> shift_) & mask_ : get(f);
  }
  /// physical → raw: rounds to nearest, clamps to the DBC range and the bit range.
  std::uint64_t to_raw(double physical) const noexcept {
    bool clamped = false;
    return codec_.to_raw(physical, clamped);
  }
  double to_physical(std::uint64_t raw) const noexcept { return codec_.to_physical(raw); }
  /// raw is inside the DBC's physical [min|max] (always true when the DBC gives no range).
  bool in_range(std::uint64_t raw) const noexcept { return raw >= raw_lo_ && raw <= raw_hi_; }
  const can::dbc::Signal& signal() const noexcept { return codec_.signal(); }

 private:
  void set_raw_range() noexcept;
  can::SignalCodec codec_;
  std::uint64_t raw_lo_ = 0, raw_hi_ = ~std::uint64_t{0};
  bool intel_ = false;
  std::uint32_t shift_ = 0;
  std::uint64_t mask_ = 0;
};

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

struct BenchLayout {
  std::uint32_t command_id = 0x100, sensors_id = 0x200, cro_id = 0x7E0, dto_id = 0x7E1;
  std::uint8_t command_len = 8, sensors_len = 8, cro_len = 8;
  // Defaults: the layout of config/hydraulic_bench.dbc.
  BitField solenoid_a{0, 16, 0.1, 0, 2000}, solenoid_b{16, 16, 0.1, 0, 2000}, restrictor{32, 16, 0.1, 0, 2000},
      command_counter{48, 8, 1.0}, command_crc{56, 8, 1.0};
  BitField pilot{0, 16, 0.00152590218966964, 5, 95}, supply{16, 16, 0.00152590218966964, 0, 100},
      sensor_counter{32, 16, 1.0}, sensors_crc{56, 8, 1.0};
  BitField cro_cmd{0, 8, 1.0}, cro_ctr{8, 8, 1.0}, dto_pid{0, 8, 1.0}, dto_err{8, 8, 1.0};

  /// Reads the layout from a DBC file. Throws lash::InputError naming the file and the
  /// missing message/signal (a counter of 4..16 bits, a CRC that is not one whole byte of
  /// the frame). Not real-time safe.
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
  /// CRC-8 SAE J1850 of a frame: data ID (identifier low byte, high byte), then every
  /// payload byte except the CRC byte `crc` occupies.
  static std::uint8_t e2e_crc(const can::Frame& f, const BitField& crc) noexcept;
  std::uint32_t command_counter_bits() const noexcept { return command_counter.signal().length; }
  std::uint32_t sensor_counter_bits() const noexcept { return sensor_counter.signal().length; }

  /// CCP CONNECT request (CRO_CMD = 0x01, counter ctr).
  can::Frame pack_connect(std::uint8_t ctr) const noexcept;
  bool is_connect(const can::Frame& f) const noexcept;
  /// A positive command-return DTO (PID 0xFF, error code 0x00).
  bool is_connect_ack(const can::Frame& f) const noexcept;

  /// Current command quantisation: what the slave decodes for a commanded current [mA].
  double quantize_current(double mA) const noexcept { return solenoid_a.to_physical(solenoid_a.to_raw(mA)); }
};

/// The 8 data bytes of a frame as one little-endian word (byte 0 = bits 0..7).
inline std::uint64_t load_le(const can::Frame& f) noexcept {
  std::uint64_t w = 0;
  for (std::size_t i = 0; i < 8; ++i) w |= static_cast<std::uint64_t>(f.data[i]) << (8 * i);
  return w;
}

/// Counter distance b − a mod 2¹⁶ (1 = the next frame).
inline std::uint16_t counter_delta(std::uint16_t a, std::uint16_t b) noexcept {
  return static_cast<std::uint16_t>(b - a);
}

}  // namespace lash::hil
