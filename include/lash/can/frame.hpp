#pragma once
/// @file frame.hpp
/// A CAN frame: CAN 2.0A (11-bit) / 2.0B (29-bit) identifiers, remote frames, CAN FD
/// (up to 64 bytes, bit rate switch, error state indicator) and error frames as logs
/// hold them (SocketCAN: CAN_ERR_FLAG with the error class in the id bits).
#include <array>
#include <cstdint>
#include <span>

namespace lash::can {

struct Frame {
  static constexpr std::size_t kMaxClassicLen = 8;
  static constexpr std::size_t kMaxFdLen = 64;

  std::uint32_t id = 0;        ///< 11-bit (standard) or 29-bit (extended) identifier
  bool extended = false;       ///< 29-bit identifier (CAN 2.0B)
  bool remote = false;         ///< remote transmission request (no data)
  bool fd = false;             ///< CAN FD frame (len up to 64)
  bool brs = false;            ///< CAN FD bit rate switch
  bool esi = false;            ///< CAN FD error state indicator
  bool error = false;          ///< error frame; `id` holds the SocketCAN error class bits (29 bits)
  std::uint8_t len = 0;        ///< data length in bytes (DLC for classic CAN: 0–8)
  std::array<std::uint8_t, kMaxFdLen> data{};
  double timestamp_s = 0.0;    ///< receive (or log) time [s]; bus-specific epoch (see Bus)

  std::span<std::uint8_t> payload() noexcept { return {data.data(), len}; }
  std::span<const std::uint8_t> payload() const noexcept { return {data.data(), len}; }
  /// True when id fits its format (11/29 bits; error frames 29), len ≤ 8 (classic) or
  /// ≤ 64 (FD), BRS/ESI only on FD frames and no remote FD frame.
  bool valid() const noexcept {
    if ((extended || error) ? id > 0x1FFFFFFFu : id > 0x7FFu) return false;
    if (!fd && (brs || esi)) return false;
    if (fd && remote) return false;
    return fd ? len <= kMaxFdLen : len <= kMaxClassicLen;
  }
};

inline bool same_content(const Frame& a, const Frame& b) noexcept {
  if (a.id != b.id || a.extended != b.extended || a.remote != b.remote || a.len != b.len || a.fd != b.fd ||
      a.brs != b.brs || a.esi != b.esi || a.error != b.error)
    return false;
  for (std::size_t i = 0; i < a.len; ++i)
    if (a.data[i] != b.data[i]) return false;
  return true;
}

}  // namespace lash::can
