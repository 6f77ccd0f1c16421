#include "lash/hil/e2e.hpp"

namespace lash::hil {

static_assert(Crc8SaeJ1850::compute(std::array<std::uint8_t, 9>{'1', '2', '3', '4', '5', '6', '7', '8', '9'}) == 0x4B,
              "CRC-8 SAE J1850 check value");

const char* to_string(Drop d) noexcept {
  switch (d) {
    case Drop::dlc: return "dlc";
    case Drop::crc: return "crc";
    case Drop::range: return "range";
    case Drop::repeated: return "repeated_counter";
    case Drop::sequence: return "wrong_sequence";
  }
  return "?";
}

bool SeqTracker::on_counter(std::uint16_t counter) noexcept {
  const std::uint16_t mask = modulus_mask();
  counter = static_cast<std::uint16_t>(counter & mask);
  auto accept = [&](std::uint16_t c) noexcept {
    last = c;
    run = 0;
    ++accepted;
    ++in_step;
    return true;
  };
  if (!have) {
    have = true;
    extended = counter;
    return accept(counter);
  }
  const auto d = static_cast<std::uint16_t>((counter - last) & mask);
  if (d == 0) {
    drops.add(Drop::repeated);
    return false;
  }
  if (d <= max_delta) {
    lost += d - 1u;
    extended += d;
    return accept(counter);
  }
  // A wrong sequence: dropped, unless it is the sync_frames-th consecutive counter of a new
  // sequence (a restarted sender), which becomes the reference.
  run = (run > 0 && static_cast<std::uint16_t>((counter - candidate) & mask) == 1) ? run + 1 : 1;
  candidate = counter;
  if (run >= sync_frames) {
    ++resyncs;
    // A forward jump: a gap of more than max_delta frames (a stalled receiver, frames lost) and a
    // restarted sender look the same on the wire; taking it as a jump keeps `extended` monotone
    // and congruent to the counter, so it goes on numbering a running sender's frames (which the
    // replay of the logs needs, hil simulate --schedule). Ambiguous only past 2^bits lost frames.
    extended += static_cast<std::uint16_t>((counter - last) & mask);
    return accept(counter);
  }
  drops.add(Drop::sequence);
  return false;
}

}  // namespace lash::hil
