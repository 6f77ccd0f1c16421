#pragma once
/// @file bit_field.hpp
/// One unsigned signal of a frame as a DBC places it, coded by SignalCodec
/// (codec.hpp: Intel/Motorola bit placement, physical → raw rounding to nearest and
/// clamping to the DBC range), with a checked constructor from a DBC message.
/// put/get/to_raw/to_physical are noexcept and O(1); constructors are not real-time safe.
#include <cstdint>
#include <string>

#include "lash/can/codec.hpp"
#include "lash/can/dbc.hpp"
#include "lash/can/frame.hpp"

namespace lash::can {

class BitField {
 public:
  /// An unsigned Intel signal: start bit (LSB), length, factor, physical range [lo, hi]
  /// (lo == hi: no range). `intel = false` places it Motorola (start bit = MSB).
  BitField(std::uint32_t start_bit, std::uint32_t length, double factor, double lo = 0.0, double hi = 0.0,
           bool intel = true);
  explicit BitField(const dbc::Signal& signal);

  /// Signal `name` of message `m` of DBC `file`, which must be an unsigned integer signal of
  /// min_bits..max_bits bits with a non-zero factor; lash::InputError naming file and
  /// "Message.Signal" otherwise.
  static BitField from_message(const dbc::Message& m, const char* name, const std::string& file,
                               std::uint32_t min_bits = 1, std::uint32_t max_bits = 64);

  void put(Frame& f, std::uint64_t raw) const noexcept { codec_.write_raw({f.data.data(), Frame::kMaxClassicLen}, raw); }
  std::uint64_t get(const Frame& f) const noexcept {
    return codec_.read_raw({f.data.data(), Frame::kMaxClassicLen}).value_or(0);
  }
  /// physical → raw: rounds to nearest, clamps to the DBC range and the bit range.
  std::uint64_t to_raw(double physical) const noexcept {
    bool clamped = false;
    return codec_.to_raw(physical, clamped);
  }
  double to_physical(std::uint64_t raw) const noexcept { return codec_.to_physical(raw); }
  const dbc::Signal& signal() const noexcept { return codec_.signal(); }

 private:
  SignalCodec codec_;
};

/// Message `name` of the DBC, which must exist and use an 11-bit identifier; InputError otherwise.
const dbc::Message& standard_message(const dbc::Database& db, const char* name, const std::string& file);
/// Payload length of a classic CAN message (≤ 8 bytes); InputError otherwise.
std::uint8_t classic_length(const dbc::Message& m, const std::string& file);

}  // namespace lash::can
