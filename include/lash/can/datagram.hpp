#pragma once
/// @file datagram.hpp
/// The UDP multicast wire format of python-can's `udp_multicast` interface
/// (can/interfaces/udp_multicast/utils.py, pack_message): one msgpack map per
/// datagram with the 11 keys timestamp, arbitration_id, is_extended_id,
/// is_remote_frame, is_error_frame, channel, dlc, data, is_fd, bitrate_switch,
/// error_state_indicator (`msgpack.packb(..., use_bin_type=True)`).
///
/// A self-contained msgpack subset codec: no allocation, noexcept, bounded
/// input. Real-time safe.
#include <cstddef>
#include <cstdint>
#include <span>

#include "lash/can/frame.hpp"

namespace lash::can::udp {

/// Datagrams larger than this are dropped unread as oversized [byte].
inline constexpr std::size_t kMaxDatagram = 1024;

/// Encodes `frame` (with `timestamp_s` as the "timestamp" value) into `out`;
/// returns the byte count, or 0 when `out` is too small or the frame is invalid.
std::size_t encode_datagram(const Frame& frame, double timestamp_s, std::span<std::uint8_t> out) noexcept;

enum class DecodeStatus : std::uint8_t {
  ok,
  oversized,     ///< larger than kMaxDatagram
  malformed,     ///< not one well-formed msgpack map of the expected types
  unknown_key,   ///< a key python-can does not send
  invalid,       ///< well-formed but not a valid frame (id range, dlc/data mismatch)
  error_frame,   ///< is_error_frame set: no data frame to deliver
};
const char* to_string(DecodeStatus s) noexcept;

/// Decodes one datagram into `frame` (timestamp_s = the datagram's "timestamp",
/// 0 when absent). `frame` is written only on ok.
DecodeStatus decode_datagram(std::span<const std::uint8_t> in, Frame& frame) noexcept;

}  // namespace lash::can::udp
