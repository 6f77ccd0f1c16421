#pragma once
/// @file ccp.hpp
/// CCP (CAN Calibration Protocol, the thesis's CRO/DTO) as far as lash's nodes use it:
/// the CONNECT handshake. A CRO (command receive object) carries a command byte and a
/// counter (CONNECT = 0x01); the DTO (data transmission object) reply begins with
/// packet id 0xFF, an error code (0x00 = acknowledge) and the same counter.
/// Where these bytes sit comes from the DBC messages CCP_CRO (CRO_CMD, CRO_CTR) and
/// CCP_DTO (DTO_PID, DTO_ERR). pack/recognise are noexcept and O(1).
#include <cstdint>
#include <string>

#include "lash/can/bit_field.hpp"
#include "lash/can/dbc.hpp"
#include "lash/can/frame.hpp"

namespace lash::can::ccp {

inline constexpr std::uint8_t kConnect = 0x01;       ///< CRO command CONNECT
inline constexpr std::uint8_t kCommandReturn = 0xFF; ///< DTO packet id of a command return
inline constexpr std::uint8_t kAcknowledge = 0x00;   ///< DTO error code: no error

struct Layout {
  std::uint32_t cro_id = 0x7E0, dto_id = 0x7E1;
  std::uint8_t cro_len = 8;
  BitField cro_cmd{0, 8, 1.0}, cro_ctr{8, 8, 1.0}, dto_pid{0, 8, 1.0}, dto_err{8, 8, 1.0};

  /// Reads CCP_CRO / CCP_DTO from a DBC (`file` names it in errors). Throws lash::InputError
  /// naming the missing message or signal. Not real-time safe.
  static Layout from_dbc(const dbc::Database& db, const std::string& file);

  /// CONNECT request (CRO_CMD = 0x01, counter ctr).
  Frame pack_connect(std::uint8_t ctr) const noexcept;
  bool is_connect(const Frame& f) const noexcept;
  /// A positive command-return DTO (PID 0xFF, error code 0x00).
  bool is_connect_ack(const Frame& f) const noexcept;
};

}  // namespace lash::can::ccp
