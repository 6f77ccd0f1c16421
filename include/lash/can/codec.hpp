#pragma once
/// @file codec.hpp
/// Signal codec: physical ↔ raw ↔ payload bits for DBC signals up to 64 bits.
///
/// physical = raw × factor + offset (DBC). physical → raw rounds to nearest
/// (ties to even, like canmatrix's Python `round`), never truncates. Values
/// outside the signal's range — the DBC [min|max] when min < max, and always
/// the range its bits can hold — are clamped, and each clamp is counted.
///
/// Real-time contract: decode()/encode()/read_raw()/write_raw() are noexcept,
/// allocation-free and O(1). The bit routine (Intel or Motorola; one 8-byte
/// window or the rare 9-byte span) is chosen once, at construction, as a
/// function pointer — no virtual call and no per-sample layout decision.
/// Every call takes a length-checked std::span and refuses spans too short for
/// the signal. Constructors validate and are not real-time safe.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lash/can/dbc.hpp"

namespace lash::can {

/// Round to nearest, ties to even, without libm (std::nearbyint is a library call on
/// baseline x86-64). Exact for every double: values with |x| ≥ 2^52 are integers already.
inline double round_half_even(double x) noexcept {
  constexpr double k2p52 = 4503599627370496.0;
  const double a = x < 0 ? -x : x;
  if (!(a < k2p52)) return x;  // also NaN
  const double r = (a + k2p52) - k2p52;
  return x < 0 ? -r : r;
}

class SignalCodec {
 public:
  /// Throws std::invalid_argument for a layout that cannot be coded (length 0/>64,
  /// factor 0, float type with the wrong length, bits past byte 64).
  explicit SignalCodec(const dbc::Signal& signal);

  /// Bytes a payload must hold for this signal (highest byte touched + 1).
  std::size_t min_bytes() const noexcept { return min_bytes_; }
  const dbc::Signal& signal() const noexcept { return signal_; }

  /// Raw bits (zero-extended, `length` bits) or nullopt when `data` is too short.
  std::optional<std::uint64_t> read_raw(std::span<const std::uint8_t> data) const noexcept {
    if (data.size() < min_bytes_) return std::nullopt;
    return read_(*this, data.data(), data.size());
  }
  /// Writes the low `length` bits of `raw`, leaving other bits alone. False when `data` is too short.
  bool write_raw(std::span<std::uint8_t> data, std::uint64_t raw) const noexcept {
    if (data.size() < min_bytes_) return false;
    write_(*this, data.data(), data.size(), raw & mask_);
    return true;
  }

  /// raw bits → physical value (sign extension / IEEE float per the signal).
  double to_physical(std::uint64_t raw) const noexcept;
  /// physical → raw bits: round to nearest, clamp (sets `clamped`).
  std::uint64_t to_raw(double physical, bool& clamped) const noexcept;

  /// Physical value of the signal in `data`, or nullopt when `data` is too short.
  std::optional<double> decode(std::span<const std::uint8_t> data) const noexcept {
    auto raw = read_raw(data);
    if (!raw) return std::nullopt;
    return to_physical(*raw);
  }
  enum class Status : std::uint8_t { ok, clamped, too_short };
  /// Encodes `physical` into `data`; counts a clamp.
  Status encode(double physical, std::span<std::uint8_t> data) noexcept {
    if (data.size() < min_bytes_) return Status::too_short;
    bool clamped = false;
    const std::uint64_t raw = to_raw(physical, clamped);
    write_(*this, data.data(), data.size(), raw);
    if (clamped) {
      ++clamp_count_;
      return Status::clamped;
    }
    return Status::ok;
  }
  std::uint64_t clamp_count() const noexcept { return clamp_count_; }

 private:
  friend class MessageCodec;
  using ReadFn = std::uint64_t (*)(const SignalCodec&, const std::uint8_t*, std::size_t) noexcept;
  using WriteFn = void (*)(const SignalCodec&, std::uint8_t*, std::size_t, std::uint64_t) noexcept;
  template <bool Motorola>
  static std::uint64_t read_window(const SignalCodec& c, const std::uint8_t* d, std::size_t n) noexcept;
  template <bool Motorola>
  static void write_window(const SignalCodec& c, std::uint8_t* d, std::size_t n, std::uint64_t raw) noexcept;
  template <bool Motorola>
  static std::uint64_t read_bits(const SignalCodec& c, const std::uint8_t* d, std::size_t n) noexcept;
  template <bool Motorola>
  static void write_bits(const SignalCodec& c, std::uint8_t* d, std::size_t n, std::uint64_t raw) noexcept;

  dbc::Signal signal_;
  ReadFn read_ = nullptr;
  WriteFn write_ = nullptr;
  std::uint64_t mask_ = 0;       ///< low `length` bits
  std::uint32_t first_byte_ = 0; ///< lowest byte touched
  std::uint32_t min_bytes_ = 0;  ///< highest byte touched + 1
  std::int32_t lo_base_ = 0;     ///< LSB position in a 64-bit window starting at byte 0 (see codec.cpp)
  std::uint32_t length_ = 0;
  bool signed_ = false;
  dbc::ValueType type_ = dbc::ValueType::integer;
  double factor_ = 1.0;
  double offset_ = 0.0;
  double min_phys_ = 0.0;
  double max_phys_ = 0.0;
  bool has_range_ = false;
  double raw_lo_ = 0.0;       ///< smallest raw value (as double)
  double raw_hi_excl_ = 0.0;  ///< raw values must be < this (2^len or 2^(len-1))
  std::uint64_t clamp_count_ = 0;
};

/// All signals of one DBC message, with multiplexing.
class MessageCodec {
 public:
  /// Throws std::invalid_argument (naming the signal) when dbc::check_layout()
  /// finds an error (a signal that cannot be coded or does not fit the message's
  /// size, a multiplexed signal without multiplexor). Not real-time safe.
  explicit MessageCodec(const dbc::Message& message);

  const dbc::Message& message() const noexcept { return message_; }
  std::size_t signal_count() const noexcept { return codecs_.size(); }
  /// Index of a signal by name (not real-time safe).
  std::optional<std::size_t> index_of(std::string_view signal_name) const noexcept;
  const SignalCodec& codec(std::size_t i) const noexcept { return codecs_[i]; }

  /// Decodes all signals into `values` (size == signal_count()). Multiplexed
  /// signals not selected (by their multiplexor's raw value, through every level of
  /// extended multiplexing) come out as NaN.
  /// False (values untouched) when a span is too short.
  bool decode(std::span<const std::uint8_t> data, std::span<double> values) const noexcept {
    if (fast_ && data.size() >= 8 && values.size() == fast_n_) [[likely]] {
      decode_fast_(*this, data.data(), values.data());
      return true;
    }
    return decode_general(data, values);
  }

  struct EncodeResult {
    bool ok = false;            ///< false: a span was too short, nothing written
    std::uint32_t clamped = 0;  ///< signals clamped in this call
  };
  /// Encodes `values` (size == signal_count()) into `data` (size ≥ message size).
  /// Multiplexed signals are written only when the multiplexor's encoded value
  /// selects them; NaN values of multiplexed signals are skipped too.
  EncodeResult encode(std::span<const double> values, std::span<std::uint8_t> data) noexcept {
    if (fast_ && data.size() >= 8 && values.size() == fast_n_) [[likely]]
      if (encode_fast_(*this, values.data(), data.data())) return {true, 0};
    return encode_general(values, data);
  }
  /// Clamps counted over this codec's lifetime.
  std::uint64_t clamp_count() const noexcept { return clamp_count_; }
  /// True when the message fits 8 bytes and uses the one-word path (see codec.cpp).
  bool packed() const noexcept { return packed_; }

 private:
  /// Per-signal plan of the one-word path for messages of at most 8 bytes, built at
  /// construction: the payload is loaded once as a little- and a big-endian 64-bit
  /// word and every integer signal is a shift and a mask of one of them (Intel lanes
  /// first, then Motorola, each accumulated in a register), sign-extended with an xor and
  /// a subtraction (sign bit 0 for unsigned fields), scaled with the factor; encoding
  /// multiplies by the reciprocal of the factor. No per-signal flags are tested on this
  /// path: the range is ±inf when the DBC gives none; one test on [min|max], one on the
  /// distance to a rounding tie and one unsigned integer compare on the field send every
  /// other case (NaN, ±inf, a clamp, a product that might round unlike the quotient) to
  /// SignalCodec::to_raw(), the reference. Float signals and unsigned 64-bit fields go
  /// through `slow_`.
  struct Lane {
    double inv_factor, offset, min_phys, max_phys, factor;
    double half_tol;         ///< 0.5 less the largest gap between p×(1/factor) and p/factor over the field
    std::int64_t raw_lo;     ///< smallest raw value of the field (integer)
    std::uint64_t raw_span;  ///< largest - smallest raw value: in range iff raw - raw_lo <= raw_span (unsigned)
    std::uint64_t mask;
    std::uint64_t sign;    ///< the field's sign bit for signed fields, else 0: value = (raw ^ sign) - sign
    std::uint32_t index;   ///< signal index
    std::uint8_t lo;       ///< LSB position in the word
    std::uint8_t word;     ///< 0 = little-endian (Intel) word, 1 = big-endian (Motorola)
  };
  /// Raw bits of one lane for `p` (the exact to_raw() result); adds 1 to `clamped` on a clamp.
  std::uint64_t lane_raw(const Lane& l, double p, std::uint32_t& clamped) const noexcept;
  template <bool Mux>
  std::uint32_t encode_packed(std::span<const double> values, std::uint64_t set[2], std::uint64_t clear[2]) noexcept;
  std::vector<Lane> lanes_;          ///< integer signals of a packed message, Intel lanes first
  std::uint32_t intel_lanes_ = 0;    ///< lanes_[0 .. intel_lanes_) use word 0, the rest word 1
  std::vector<std::uint32_t> slow_;  ///< the other signals of a packed message
  std::uint64_t clear_all_[2] = {0, 0};  ///< bits of every signal per word (messages without multiplexing)
  /// The fast path (a plan built at construction): a packed message without multiplexing
  /// whose signals are all integer lanes of at most 48 bits (49 signed), coded from/into a
  /// span of at least 8 bytes with one load and one store. One lane per signal, in layout
  /// order (values[i] is lane i, no index). Decoding: each lane is a rotation and a mask
  /// of the little- or big-endian word (unsigned fields rotated to bit 0, signed ones to
  /// the top, so that the int64 carries the sign), times factor × 2^-position (exact), plus
  /// offset. Encoding: every lane without a branch, and one test per message (see
  /// encode_fast()); on any doubt the per-lane path decides. The byte order (all Intel, all
  /// Motorola, mixed), the range and tie tests and the lane count (up to kUnrolled) are
  /// template parameters chosen at construction.
  struct FastLane {
    double offset, inv_factor, min_phys, max_phys;
    double scale;          ///< decode: factor × 2^-k, k the field's position after the rotation (exact)
    std::uint64_t bias;    ///< bits of kMagic + smallest raw (see encode_fast)
    std::uint64_t above;   ///< ~mask: bits that must stay clear in bits(t) - bias
    std::uint64_t mask;    ///< low `length` bits
    std::uint64_t place;   ///< encode: 2^lo (the field's bits times place = the bits in the word)
    std::uint64_t field;   ///< decode: the field's bits after the rotation (at 0 unsigned, at the top signed)
    std::uint64_t sel;     ///< mixed byte orders: all ones for a Motorola lane, else 0
    std::uint8_t rot;      ///< decode: left rotation of the word
  };
  /// Two consecutive lanes of an Intel-only or Motorola-only plan, for encode_fast's
  /// two-wide (SSE2) arithmetic: lanes 2j and 2j+1 side by side.
  struct alignas(16) FastPair {
    double offset[2], inv_factor[2], min_phys[2], max_phys[2];
    std::uint64_t bias[2], above[2], mask[2], place[2];
  };
  enum class Order : std::uint8_t { intel, motorola, mixed };
  /// Lane counts up to this have their own (fully unrolled) kernels; more take a loop.
  static constexpr std::size_t kUnrolled = 8;
  using EncodeFastFn = bool (*)(const MessageCodec&, const double*, std::uint8_t*) noexcept;
  using DecodeFastFn = void (*)(const MessageCodec&, const std::uint8_t*, double*) noexcept;
  template <Order O, bool Range, bool Tie, std::size_t N>
  static bool encode_fast(const MessageCodec& m, const double* values, std::uint8_t* data) noexcept;
  template <Order O, std::size_t N>
  static void decode_fast(const MessageCodec& m, const std::uint8_t* data, double* values) noexcept;
  void build_fast_plan();
  bool decode_general(std::span<const std::uint8_t> data, std::span<double> values) const noexcept;
  EncodeResult encode_general(std::span<const double> values, std::span<std::uint8_t> data) noexcept;
  bool fast_ = false;
  std::size_t fast_n_ = 0;            ///< signal count (the fast path's values size)
  std::vector<FastLane> fast_lanes_;  ///< one per signal, layout order
  std::vector<FastPair> fast_pairs_;  ///< lanes 2j, 2j+1 (a last odd lane is only in fast_lanes_)
  double fast_tol_ = 0.0;  ///< largest |q - round(q)| that cannot hide a tie, over the lanes that need the test
  EncodeFastFn encode_fast_ = nullptr;
  DecodeFastFn decode_fast_ = nullptr;
  std::uint64_t clear_le_ = 0;  ///< every signal's bits in the little-endian word
  /// Multiplexing: signal i is present when its multiplexor parent_[i] is present and
  /// holds a raw value in ranges_[range_begin_[i] .. range_begin_[i + 1]).
  bool selected(std::size_t i, std::span<const std::uint8_t> data, std::span<const double> values) const noexcept;
  bool packed_ = false;
  dbc::Message message_;
  std::vector<SignalCodec> codecs_;
  std::vector<std::int32_t> parent_;       ///< multiplexor index per signal, -1 = always present
  std::vector<std::uint32_t> order_;       ///< signal indices, multiplexors before what they select
  std::vector<std::uint32_t> range_begin_;
  std::vector<dbc::MuxRange> ranges_;
  std::vector<std::uint8_t> present_;      ///< encode's scratch: signal selected by its multiplexors
  bool has_mux_ = false;
  std::uint64_t clamp_count_ = 0;
};

}  // namespace lash::can
