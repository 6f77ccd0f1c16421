#pragma once
/// @file e2e.hpp
/// End-to-end protection of the bench's cyclic frames, in the manner of AUTOSAR E2E
/// (profiles 1/2: data ID + alive counter + CRC-8 SAE J1850), and the receiver's
/// plausibility check that production ECUs run before a frame reaches the application:
///
///   1. DLC: the frame's length equals the DBC's message size          → Drop::dlc
///   2. CRC: CRC-8 SAE J1850 over the data ID (the 11-bit identifier, low byte then
///      high byte) and every payload byte but the CRC byte, equals the CRC signal → Drop::crc
///   3. range: every data signal's physical value is inside the DBC's [min|max] → Drop::range
///   4. counter: the alive counter advanced by 1..max_delta (mod 2^bits) since the last
///      accepted frame; 0 = repeated → Drop::repeated; anything else → Drop::sequence,
///      unless `sync_frames` frames in a row follow each other (a restarted sender), which
///      re-synchronises on the newest (counted as a resync).
///
/// Staleness (no accepted frame for N periods) is the nodes' business (nodes.hpp).
/// Everything here is noexcept, allocation-free and O(1) (the CRC is table-driven).
#include <array>
#include <cstdint>
#include <span>

namespace lash::hil {

namespace detail {
/// The CRC-8 table of polynomial 0x1D, MSB first: kCrc8Table[b] = CRC register after shifting byte b through.
constexpr std::array<std::uint8_t, 256> make_crc8_table(std::uint8_t poly) noexcept {
  std::array<std::uint8_t, 256> t{};
  for (unsigned i = 0; i < 256; ++i) {
    unsigned c = i;
    for (int k = 0; k < 8; ++k) c = (c & 0x80u) ? ((c << 1) ^ poly) : (c << 1);
    t[i] = static_cast<std::uint8_t>(c);
  }
  return t;
}
inline constexpr std::array<std::uint8_t, 256> kCrc8J1850Table = make_crc8_table(0x1D);
}  // namespace detail

/// CRC-8 SAE J1850: polynomial 0x1D (x⁸+x⁴+x³+x²+1), initial value 0xFF, final XOR 0xFF,
/// no reflection (AUTOSAR SWS CRC Library `Crc_CalculateCRC8`). Check value: "123456789" → 0x4B.
class Crc8SaeJ1850 {
 public:
  static constexpr std::uint8_t kPoly = 0x1D, kInit = 0xFF, kXorOut = 0xFF;

  /// Feeds bytes into a running register (start with kInit); finish() applies the final XOR.
  static constexpr std::uint8_t update(std::uint8_t reg, std::span<const std::uint8_t> bytes) noexcept {
    for (const std::uint8_t b : bytes) reg = kTable[reg ^ b];
    return reg;
  }
  static constexpr std::uint8_t update(std::uint8_t reg, std::uint8_t byte) noexcept { return kTable[reg ^ byte]; }
  static constexpr std::uint8_t finish(std::uint8_t reg) noexcept { return static_cast<std::uint8_t>(reg ^ kXorOut); }
  /// The CRC of `bytes`.
  static constexpr std::uint8_t compute(std::span<const std::uint8_t> bytes) noexcept {
    return finish(update(kInit, bytes));
  }

 private:
  static constexpr const std::array<std::uint8_t, 256>& kTable = detail::kCrc8J1850Table;
};

/// Why a received frame was dropped.
enum class Drop : std::uint8_t { dlc, crc, range, repeated, sequence };
inline constexpr std::size_t kDropReasons = 5;
/// "dlc" | "crc" | "range" | "repeated_counter" | "wrong_sequence".
const char* to_string(Drop d) noexcept;

/// Dropped frames of one message, per reason.
struct DropCounts {
  std::array<std::uint64_t, kDropReasons> n{};
  void add(Drop d) noexcept { ++n[static_cast<std::size_t>(d)]; }
  std::uint64_t operator[](Drop d) const noexcept { return n[static_cast<std::size_t>(d)]; }
  std::uint64_t total() const noexcept {
    std::uint64_t s = 0;
    for (auto v : n) s += v;
    return s;
  }
};

/// The E2E receiver settings of one node (validated by the node's constructor).
struct E2EConfig {
  std::uint32_t max_counter_delta = 10;  ///< counter may advance 1..this per accepted frame (≤ delta − 1 lost)
  std::uint32_t sync_frames = 2;         ///< consecutive counters that re-synchronise after a wrong sequence
  std::uint32_t recovery_frames = 5;     ///< good steps in a row that bring degraded/safe back to running
  double ramp_mA_per_s = 4000.0;         ///< degraded: the current ramps to 0 mA at this rate [mA/s]
};

/// Alive-counter continuity and the receive statistics of one cyclic message (docs/method.md §B3).
/// received: frames with the message's identifier (any content); late: accepted frames that
/// arrived after the step that should have used them (more than one accepted frame in one
/// step); lost: counter values skipped between accepted frames; resyncs: re-synchronisations
/// on a new counter sequence (a restarted sender). Dropped frames are in `drops`.
struct SeqTracker {
  std::uint32_t bits = 16;  ///< counter width [bit], 2..16
  std::uint32_t max_delta = 10, sync_frames = 2;
  bool have = false;
  std::uint16_t last = 0;          ///< last accepted counter
  std::uint64_t extended = 0;      ///< the accepted counter unwrapped, monotone (a re-synchronisation is a forward jump)
  std::uint16_t candidate = 0;     ///< last counter of a wrong sequence
  std::uint32_t run = 0;           ///< frames in a row of that wrong sequence
  std::uint64_t received = 0, accepted = 0, late = 0, lost = 0, resyncs = 0;
  DropCounts drops;
  std::uint32_t in_step = 0;

  /// Counter check of a frame that passed DLC, CRC and range: true = accepted (newer than
  /// the last accepted one, within the window, or a completed re-synchronisation).
  /// Otherwise counts Drop::repeated or Drop::sequence and returns false.
  bool on_counter(std::uint16_t counter) noexcept;
  /// A frame dropped before its counter was looked at.
  void on_drop(Drop d) noexcept { drops.add(d); }
  void end_step() noexcept {
    if (in_step > 1) late += in_step - 1;
    in_step = 0;
  }
  std::uint16_t modulus_mask() const noexcept { return static_cast<std::uint16_t>((1u << bits) - 1u); }
};

}  // namespace lash::hil
