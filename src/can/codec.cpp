// Signal codec. Bit numbering:
//  - Intel (@1): payload bit k is bit k%8 of byte k/8; the field's LSB is at start_bit.
//  - Motorola (@0): start_bit names the MSB in the DBC sawtooth numbering. With
//    q = 8*(start/8) + 7 - start%8 the big-endian linear index (0 = MSB of byte 0),
//    the field occupies big-endian bits q .. q+len-1.
// A field spanning at most 8 bytes is read from one 64-bit window (little- or
// big-endian load) as (word >> lo) & mask; fields spanning 9 bytes (len ≥ 58,
// unaligned) use a bit loop. The routine is picked once in the constructor.
#include "lash/can/codec.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>

#if defined(__SSE2__) && defined(__x86_64__)
#include <emmintrin.h>
#endif

namespace lash::can {
namespace {

inline std::uint64_t load64(const std::uint8_t* p, bool big_endian) noexcept {
  std::uint64_t w;
  std::memcpy(&w, p, 8);
  const bool swap = big_endian == (std::endian::native == std::endian::little);
  return swap ? __builtin_bswap64(w) : w;
}
inline void store64(std::uint8_t* p, std::uint64_t w, bool big_endian) noexcept {
  const bool swap = big_endian == (std::endian::native == std::endian::little);
  if (swap) w = __builtin_bswap64(w);
  std::memcpy(p, &w, 8);
}

}  // namespace

namespace {
/// The 64-bit window of an n-byte payload that holds a field whose lowest byte is `first_byte`
/// (little-endian for Intel, big-endian for Motorola; short payloads zero-padded): the word, the
/// window's first byte `w`, and `lo`, the field's LSB position in the word (from `lo_base`, its
/// position in a window starting at byte 0).
struct Window {
  std::uint64_t word = 0;
  std::uint32_t w = 0;
  std::int32_t lo = 0;
};
template <bool Motorola>
Window load_window(const std::uint8_t* d, std::size_t n, std::uint32_t first_byte, std::int32_t lo_base) noexcept {
  Window win;
  if (n >= 8) {
    win.w = std::min<std::uint32_t>(first_byte, static_cast<std::uint32_t>(n - 8));
    win.word = load64(d + win.w, Motorola);
  } else {
    for (std::size_t i = 0; i < n; ++i)
      win.word |= static_cast<std::uint64_t>(d[i]) << (Motorola ? 56 - 8 * i : 8 * i);
  }
  win.lo = Motorola ? lo_base + 8 * static_cast<std::int32_t>(win.w) : lo_base - 8 * static_cast<std::int32_t>(win.w);
  return win;
}
}  // namespace

template <bool Motorola>
std::uint64_t SignalCodec::read_window(const SignalCodec& c, const std::uint8_t* d, std::size_t n) noexcept {
  const Window win = load_window<Motorola>(d, n, c.first_byte_, c.lo_base_);
  return (win.word >> win.lo) & c.mask_;
}

template <bool Motorola>
void SignalCodec::write_window(const SignalCodec& c, std::uint8_t* d, std::size_t n, std::uint64_t raw) noexcept {
  const auto [old, w, lo] = load_window<Motorola>(d, n, c.first_byte_, c.lo_base_);
  const std::uint64_t word = (old & ~(c.mask_ << lo)) | (raw << lo);
  if (n >= 8) {
    store64(d + w, word, Motorola);
  } else {
    for (std::size_t i = 0; i < n; ++i)
      d[i] = static_cast<std::uint8_t>(word >> (Motorola ? 56 - 8 * i : 8 * i));
  }
}

namespace {
/// Byte and bit (0 = LSB) in the payload of bit i (0 = the raw value's LSB) of a field of `len`
/// bits starting at DBC start bit `start` (the MSB's position for Motorola, the LSB's for Intel).
template <bool Motorola>
constexpr std::pair<std::uint32_t, std::uint32_t> field_bit(std::uint32_t start, std::uint32_t len,
                                                            std::uint32_t i) noexcept {
  if (Motorola) {
    const std::uint32_t p = 8 * (start / 8) + 7 - start % 8 + (len - 1 - i);
    return {p / 8, 7 - p % 8};
  }
  return {(start + i) / 8, (start + i) % 8};
}
}  // namespace

template <bool Motorola>
std::uint64_t SignalCodec::read_bits(const SignalCodec& c, const std::uint8_t* d, std::size_t) noexcept {
  std::uint64_t raw = 0;
  for (std::uint32_t i = 0; i < c.length_; ++i) {
    const auto [byte, bit] = field_bit<Motorola>(c.signal_.start_bit, c.length_, i);
    raw |= static_cast<std::uint64_t>((d[byte] >> bit) & 1u) << i;
  }
  return raw;
}

template <bool Motorola>
void SignalCodec::write_bits(const SignalCodec& c, std::uint8_t* d, std::size_t, std::uint64_t raw) noexcept {
  for (std::uint32_t i = 0; i < c.length_; ++i) {
    const auto [byte, bit] = field_bit<Motorola>(c.signal_.start_bit, c.length_, i);
    const auto m = static_cast<std::uint8_t>(1u << bit);
    if ((raw >> i) & 1u) {
      d[byte] = static_cast<std::uint8_t>(d[byte] | m);
    } else {
      d[byte] = static_cast<std::uint8_t>(d[byte] & ~m);
    }
  }
}

SignalCodec::SignalCodec(const dbc::Signal& s) : signal_(s) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument(fmt::format("signal '{}': {}", s.name, why));
  };
  if (s.length < 1 || s.length > 64) throw bad("length must be 1..64 bits");
  if (!(s.factor != 0.0) || !std::isfinite(s.factor) || !std::isfinite(s.offset)) throw bad("factor must be finite and non-zero");
  if (s.value_type == dbc::ValueType::float32 && s.length != 32) throw bad("a float signal needs 32 bits");
  if (s.value_type == dbc::ValueType::float64 && s.length != 64) throw bad("a double signal needs 64 bits");
  length_ = s.length;
  signed_ = s.is_signed;
  type_ = s.value_type;
  factor_ = s.factor;
  offset_ = s.offset;
  min_phys_ = s.minimum;
  max_phys_ = s.maximum;
  has_range_ = s.minimum < s.maximum;
  mask_ = length_ == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length_) - 1;
  if (signed_) {
    raw_lo_ = -std::ldexp(1.0, static_cast<int>(length_) - 1);
    raw_hi_excl_ = std::ldexp(1.0, static_cast<int>(length_) - 1);
  } else {
    raw_lo_ = 0.0;
    raw_hi_excl_ = std::ldexp(1.0, static_cast<int>(length_));
  }
  const bool motorola = s.byte_order == dbc::ByteOrder::motorola;
  std::uint32_t b0, b1;
  if (motorola) {
    const std::uint32_t q = 8 * (s.start_bit / 8) + 7 - s.start_bit % 8;
    const std::uint32_t lsb = q + length_ - 1;
    if (lsb >= 512) throw bad("bits run past byte 64");
    b0 = q / 8;
    b1 = lsb / 8;
    lo_base_ = 63 - static_cast<std::int32_t>(lsb);
  } else {
    if (s.start_bit + length_ > 512) throw bad("bits run past byte 64");
    b0 = s.start_bit / 8;
    b1 = (s.start_bit + length_ - 1) / 8;
    lo_base_ = static_cast<std::int32_t>(s.start_bit);
  }
  first_byte_ = b0;
  min_bytes_ = b1 + 1;
  if (b1 - b0 + 1 <= 8) {
    read_ = motorola ? &read_window<true> : &read_window<false>;
    write_ = motorola ? &write_window<true> : &write_window<false>;
  } else {
    read_ = motorola ? &read_bits<true> : &read_bits<false>;
    write_ = motorola ? &write_bits<true> : &write_bits<false>;
  }
}

double SignalCodec::to_physical(std::uint64_t raw) const noexcept {
  double v;
  switch (type_) {
    case dbc::ValueType::float32:
      v = static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(raw)));
      break;
    case dbc::ValueType::float64:
      v = std::bit_cast<double>(raw);
      break;
    default:
      if (signed_) {
        const int sh = 64 - static_cast<int>(length_);
        v = static_cast<double>(static_cast<std::int64_t>(raw << sh) >> sh);
      } else if (length_ < 64) {
        v = static_cast<double>(static_cast<std::int64_t>(raw));  // cheaper than uint64 -> double
      } else {
        v = static_cast<double>(raw);
      }
  }
  return v * factor_ + offset_;
}

std::uint64_t SignalCodec::to_raw(double physical, bool& clamped) const noexcept {
  clamped = false;
  if (std::isnan(physical)) {
    clamped = true;
    return 0;
  }
  double p = physical;
  if (has_range_) {
    if (p < min_phys_) {
      p = min_phys_;
      clamped = true;
    } else if (p > max_phys_) {
      p = max_phys_;
      clamped = true;
    }
  }
  const double scaled = (p - offset_) / factor_;
  if (type_ == dbc::ValueType::float32) {
    const auto f = static_cast<float>(scaled);
    if (std::isinf(f) && !std::isinf(scaled)) clamped = true;
    return std::bit_cast<std::uint32_t>(f);
  }
  if (type_ == dbc::ValueType::float64) return std::bit_cast<std::uint64_t>(scaled);
  const double r = round_half_even(scaled);  // round to nearest, ties to even
  if (r < raw_lo_) {
    clamped = true;
    return signed_ ? (std::uint64_t{1} << (length_ - 1)) & mask_ : 0;  // most negative
  }
  if (r >= raw_hi_excl_) {
    clamped = true;
    return signed_ ? mask_ >> 1 : mask_;
  }
  if (signed_ || length_ < 64) return static_cast<std::uint64_t>(static_cast<std::int64_t>(r)) & mask_;
  return static_cast<std::uint64_t>(r);
}

MessageCodec::MessageCodec(const dbc::Message& message) : message_(message) {
  for (const auto& d : dbc::check_layout(message, "", false))
    if (d.severity == dbc::Diagnostic::Severity::error) throw std::invalid_argument(d.message);
  const std::size_t n = message.signals.size();
  codecs_.reserve(n);
  parent_.assign(n, -1);
  range_begin_.push_back(0);
  present_.assign(n, 1);
  std::vector<std::size_t> depth(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& s = message.signals[i];
    codecs_.emplace_back(s);
    if (s.mux == dbc::MuxRole::multiplexor) has_mux_ = true;
    if (const dbc::Signal* p = message.multiplexor_of(s)) {
      parent_[i] = static_cast<std::int32_t>(p - message.signals.data());
      has_mux_ = true;
      if (s.mux_ranges.empty()) {
        ranges_.push_back({s.mux_value, s.mux_value});
      } else {
        ranges_.insert(ranges_.end(), s.mux_ranges.begin(), s.mux_ranges.end());
      }
    }
    range_begin_.push_back(static_cast<std::uint32_t>(ranges_.size()));
    for (const dbc::Signal* q = &s; q && q->mux == dbc::MuxRole::multiplexed; q = message.multiplexor_of(*q)) ++depth[i];
  }
  for (std::size_t d = 0, left = n; left > 0; ++d)
    for (std::size_t i = 0; i < n; ++i)
      if (depth[i] == d) {
        order_.push_back(static_cast<std::uint32_t>(i));
        --left;
      }
  packed_ = message.size <= 8;
  for (std::size_t i = 0; i < codecs_.size() && packed_; ++i) {
    const auto& sg = message.signals[i];
    const SignalCodec& c = codecs_[i];
    if (sg.value_type != dbc::ValueType::integer || (c.length_ == 64 && !c.signed_)) {
      slow_.push_back(static_cast<std::uint32_t>(i));
      continue;
    }
    Lane l{};
    l.mask = c.mask_;
    l.factor = c.factor_;
    l.inv_factor = 1.0 / c.factor_;
    l.offset = c.offset_;
    l.min_phys = c.has_range_ ? c.min_phys_ : -std::numeric_limits<double>::infinity();
    l.max_phys = c.has_range_ ? c.max_phys_ : std::numeric_limits<double>::infinity();
    l.raw_lo = c.signed_ ? -static_cast<std::int64_t>(c.mask_ >> 1) - 1 : 0;
    l.raw_span = c.mask_;
    // Largest |raw| of the field + 1, times 2^-50 (> 3·2^-53, the relative gap between the
    // product and the quotient): fields over ~48 bits get half_tol ≤ 0 and always take
    // the reference path, which stays exact.
    l.half_tol = 0.5 - (std::ldexp(1.0, static_cast<int>(c.signed_ ? c.length_ - 1 : c.length_)) + 1.0) * std::ldexp(1.0, -50);
    l.sign = c.signed_ ? (c.mask_ >> 1) + 1 : 0;
    l.index = static_cast<std::uint32_t>(i);
    l.lo = static_cast<std::uint8_t>(c.lo_base_);  // window at byte 0
    l.word = sg.byte_order == dbc::ByteOrder::motorola ? 1 : 0;
    lanes_.push_back(l);
  }
  std::stable_partition(lanes_.begin(), lanes_.end(), [](const Lane& l) { return l.word == 0; });
  intel_lanes_ = static_cast<std::uint32_t>(std::count_if(lanes_.begin(), lanes_.end(), [](const Lane& l) { return l.word == 0; }));
  if (packed_)
    for (std::size_t i = 0; i < codecs_.size(); ++i) {
      const SignalCodec& c = codecs_[i];
      clear_all_[message.signals[i].byte_order == dbc::ByteOrder::motorola ? 1 : 0] |= c.mask_ << c.lo_base_;
    }
  clear_le_ = clear_all_[0] | __builtin_bswap64(clear_all_[1]);
  build_fast_plan();
}

namespace {
/// 1.5·2^52: for |q| < 2^51, q + kMagic rounds q to an integer, ties to even (the FPU's
/// rounding), and the representation of the sum is bits(kMagic) + that integer.
constexpr double kMagic = 6755399441055744.0;
}  // namespace

void MessageCodec::build_fast_plan() {
  fast_ = packed_ && !has_mux_ && slow_.empty() &&
          std::all_of(lanes_.begin(), lanes_.end(), [](const Lane& l) { return l.half_tol > 0; });
  if (!fast_) return;
  fast_n_ = codecs_.size();
  fast_lanes_.resize(fast_n_);
  bool range = false, tie = false, intel = false, motorola = false;
  fast_tol_ = std::numeric_limits<double>::infinity();
  for (const Lane& l : lanes_) {
    const SignalCodec& c = codecs_[l.index];
    FastLane& f = fast_lanes_[l.index];
    f.offset = l.offset;
    f.inv_factor = l.inv_factor;
    f.min_phys = l.min_phys;
    f.max_phys = l.max_phys;
    f.bias = std::bit_cast<std::uint64_t>(kMagic) + static_cast<std::uint64_t>(l.raw_lo);
    f.above = ~l.mask;
    f.mask = l.mask;
    f.place = std::uint64_t{1} << l.lo;
    // Decode: an unsigned field rotated to bit 0, a signed one to the top (bits 64-len..63)
    // so that the int64 is raw × 2^k with the field's sign; scale = factor × 2^-k makes
    // (raw × 2^k) × scale the same real number as raw × factor, hence the same double,
    // as long as scale is a normal number (checked: else no fast plan).
    const int k = c.signed_ ? 64 - static_cast<int>(c.length_) : 0;
    f.rot = static_cast<std::uint8_t>((k - l.lo + 64) % 64);
    f.field = l.mask << k;
    f.scale = std::ldexp(l.factor, -k);
    if (std::fpclassify(f.scale) != FP_NORMAL || std::ldexp(f.scale, k) != l.factor) {
      fast_ = false;
      return;
    }
    f.sel = l.word == 1 ? ~std::uint64_t{0} : 0;
    (l.word == 1 ? motorola : intel) = true;
    range = range || c.has_range_;
    // The product by the reciprocal is the quotient when the factor is a power of two:
    // only the other lanes bound the message's tie tolerance. gap < half_tol <=> gap <= tol.
    int e = 0;
    if (std::frexp(std::fabs(l.factor), &e) != 0.5) {
      tie = true;
      fast_tol_ = std::min(fast_tol_, std::nextafter(l.half_tol, 0.0));
    }
  }
  fast_pairs_.resize(fast_n_ / 2);
  for (std::size_t j = 0; j < fast_pairs_.size(); ++j)
    for (std::size_t h = 0; h < 2; ++h) {
      const FastLane& f = fast_lanes_[2 * j + h];
      FastPair& e = fast_pairs_[j];
      e.offset[h] = f.offset;
      e.inv_factor[h] = f.inv_factor;
      e.min_phys[h] = f.min_phys;
      e.max_phys[h] = f.max_phys;
      e.bias[h] = f.bias;
      e.above[h] = f.above;
      e.mask[h] = f.mask;
      e.place[h] = f.place;
    }
  // One kernel per byte order, range/tie test and lane count (0: any count, a loop).
  const std::size_t n = fast_n_ <= kUnrolled ? fast_n_ : 0;
  const auto pick = [&]<Order O, std::size_t... N>(std::index_sequence<N...>) {
    const DecodeFastFn dec[] = {&decode_fast<O, N>...};
    const EncodeFastFn enc[4][sizeof...(N)] = {{&encode_fast<O, false, false, N>...},
                                               {&encode_fast<O, false, true, N>...},
                                               {&encode_fast<O, true, false, N>...},
                                               {&encode_fast<O, true, true, N>...}};
    decode_fast_ = dec[n];
    encode_fast_ = enc[(range ? 2 : 0) + (tie ? 1 : 0)][n];
  };
  const auto counts = std::make_index_sequence<kUnrolled + 1>();
  if (intel && motorola) {
    // Mixed byte orders are rare: one loop kernel.
    decode_fast_ = &decode_fast<Order::mixed, 0>;
    encode_fast_ = range ? (tie ? &encode_fast<Order::mixed, true, true, 0> : &encode_fast<Order::mixed, true, false, 0>)
                         : (tie ? &encode_fast<Order::mixed, false, true, 0> : &encode_fast<Order::mixed, false, false, 0>);
  } else if (motorola) {
    pick.template operator()<Order::motorola>(counts);
  } else {
    pick.template operator()<Order::intel>(counts);
  }
}

bool MessageCodec::selected(std::size_t i, std::span<const std::uint8_t> data, std::span<const double> values) const noexcept {
  const std::int32_t p = parent_[i];
  if (p < 0) return true;
  if (std::isnan(values[static_cast<std::size_t>(p)])) return false;  // the multiplexor itself is absent
  const std::uint64_t raw = *codecs_[static_cast<std::size_t>(p)].read_raw(data);
  for (std::uint32_t r = range_begin_[i]; r < range_begin_[i + 1]; ++r)
    if (raw >= ranges_[r].lo && raw <= ranges_[r].hi) return true;
  return false;
}

std::optional<std::size_t> MessageCodec::index_of(std::string_view signal_name) const noexcept {
  for (std::size_t i = 0; i < codecs_.size(); ++i)
    if (codecs_[i].signal().name == signal_name) return i;
  return std::nullopt;
}

namespace {
inline std::uint64_t load_le(std::span<const std::uint8_t> data, std::size_t size) noexcept {
  std::uint64_t w = 0;
  if (data.size() >= 8) {
    std::memcpy(&w, data.data(), 8);
    if constexpr (std::endian::native == std::endian::big) w = __builtin_bswap64(w);
  } else {
    for (std::size_t i = 0; i < size; ++i) w |= static_cast<std::uint64_t>(data[i]) << (8 * i);
  }
  return w;
}
}  // namespace

namespace {
inline std::uint64_t load_le8(const std::uint8_t* p) noexcept {
  std::uint64_t w;
  std::memcpy(&w, p, 8);
  if constexpr (std::endian::native == std::endian::big) w = __builtin_bswap64(w);
  return w;
}
inline void store_le8(std::uint8_t* p, std::uint64_t w) noexcept {
  if constexpr (std::endian::native == std::endian::big) w = __builtin_bswap64(w);
  std::memcpy(p, &w, 8);
}
}  // namespace

template <MessageCodec::Order O, std::size_t N>
void MessageCodec::decode_fast(const MessageCodec& m, const std::uint8_t* data, double* values) noexcept {
  const std::uint64_t le = load_le8(data);
  const std::uint64_t be = __builtin_bswap64(le);
  const FastLane* const l = m.fast_lanes_.data();
  const std::size_t n = N != 0 ? N : m.fast_n_;
#pragma GCC unroll 8
  for (std::size_t i = 0; i < n; ++i) {
    const FastLane& f = l[i];
    std::uint64_t w;
    if constexpr (O == Order::intel) w = le;
    else if constexpr (O == Order::motorola) w = be;
    else w = (le & ~f.sel) | (be & f.sel);
    const auto x = static_cast<std::int64_t>(std::rotl(w, f.rot) & f.field);  // raw × 2^k
    values[i] = static_cast<double>(x) * f.scale + f.offset;
  }
}

template <MessageCodec::Order O, bool Range, bool Tie, std::size_t N>
bool MessageCodec::encode_fast(const MessageCodec& m, const double* values, std::uint8_t* data) noexcept {
  // Every lane without a branch, then one test: nothing is written, and encode() takes the
  // per-lane path (lane_raw(), SignalCodec::to_raw()), when a value is NaN or ±inf, outside
  // [min|max] (Range: some lane has one) or its field, or when the product by the
  // reciprocal lies within rounding error of a .5 tie (Tie: some factor is no power of two).
  double gap = 0.0;                                          // largest |q - round(q)|: must end <= fast_tol_
  double inside = std::numeric_limits<double>::infinity();  // must end >= 0
  std::uint64_t bad = 0;                                     // must end 0
  std::uint64_t s0 = 0, s1 = 0;                              // little- / big-endian word
  const FastLane* const l = m.fast_lanes_.data();
  const std::size_t n = N != 0 ? N : m.fast_n_;
  std::size_t i = 0;
#if defined(__SSE2__) && defined(__x86_64__)
  if constexpr (O != Order::mixed) {
    // Two lanes at a time: the same operations as the scalar loop below, lane by lane.
    const __m128d magic = _mm_set1_pd(kMagic);
    const __m128d abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(0x7FFFFFFFFFFFFFFF));
    __m128d gap2 = _mm_setzero_pd();
    __m128d inside2 = _mm_set1_pd(std::numeric_limits<double>::infinity());
    __m128i bad2 = _mm_setzero_si128();
    std::uint64_t s = 0;
    const FastPair* const e = m.fast_pairs_.data();
#pragma GCC unroll 4
    for (std::size_t j = 0; j < n / 2; ++j) {
      // Two 8-byte loads, not one of 16: the caller has just stored the values one by one,
      // and a 16-byte load of two 8-byte stores cannot be forwarded (a stall of ~10 cycles).
      // (The empty asm keeps the compiler from merging them back into one.)
      __m128d p0 = _mm_load_sd(values + 2 * j);
      __asm__("" : "+x"(p0));
      const __m128d p = _mm_loadh_pd(p0, values + 2 * j + 1);
      const __m128d q = _mm_mul_pd(_mm_sub_pd(p, _mm_load_pd(e[j].offset)), _mm_load_pd(e[j].inv_factor));
      const __m128d t = _mm_add_pd(q, magic);
      if constexpr (Tie) gap2 = _mm_max_pd(gap2, _mm_and_pd(_mm_sub_pd(q, _mm_sub_pd(t, magic)), abs_mask));
      if constexpr (Range)
        inside2 = _mm_min_pd(inside2, _mm_min_pd(_mm_sub_pd(p, _mm_load_pd(e[j].min_phys)),
                                                 _mm_sub_pd(_mm_load_pd(e[j].max_phys), p)));
      const __m128i b = _mm_castpd_si128(t);
      const __m128i bias = _mm_load_si128(reinterpret_cast<const __m128i*>(e[j].bias));
      const __m128i above = _mm_load_si128(reinterpret_cast<const __m128i*>(e[j].above));
      bad2 = _mm_or_si128(bad2, _mm_and_si128(_mm_sub_epi64(b, bias), above));
      const __m128i raw = _mm_and_si128(b, _mm_load_si128(reinterpret_cast<const __m128i*>(e[j].mask)));
      s |= static_cast<std::uint64_t>(_mm_cvtsi128_si64(raw)) * e[j].place[0];
      s |= static_cast<std::uint64_t>(_mm_cvtsi128_si64(_mm_unpackhi_epi64(raw, raw))) * e[j].place[1];
    }
    if constexpr (Tie) gap = _mm_cvtsd_f64(_mm_max_sd(gap2, _mm_unpackhi_pd(gap2, gap2)));
    if constexpr (Range) inside = _mm_cvtsd_f64(_mm_min_sd(inside2, _mm_unpackhi_pd(inside2, inside2)));
    bad = static_cast<std::uint64_t>(_mm_cvtsi128_si64(_mm_or_si128(bad2, _mm_unpackhi_epi64(bad2, bad2))));
    (O == Order::intel ? s0 : s1) = s;
    i = n & ~std::size_t{1};
  }
#endif
#pragma GCC unroll 8
  for (; i < n; ++i) {
    const FastLane& f = l[i];
    const double p = values[i];
    const double q = (p - f.offset) * f.inv_factor;
    const double t = q + kMagic;
    if constexpr (Tie) gap = std::max(gap, std::fabs(q - (t - kMagic)));
    // p - min and max - p are >= 0 exactly when p is inside (IEEE subtraction keeps the sign).
    if constexpr (Range) inside = std::min(inside, std::min(p - f.min_phys, f.max_phys - p));
    // bits(t) - bias = raw - smallest raw: in the field iff no bit above the mask. A |q| of
    // 2^51 or more, ±inf or NaN leaves bits far above any field of this path (≤ 49 bits).
    const auto b = std::bit_cast<std::uint64_t>(t);
    bad |= (b - f.bias) & f.above;
    // bits(kMagic) has no bit below 51: the low bits are raw's; × 2^lo puts them in place.
    const std::uint64_t v = (b & f.mask) * f.place;
    if constexpr (O == Order::intel) s0 |= v;
    else if constexpr (O == Order::motorola) s1 |= v;
    else {
      s0 |= v & ~f.sel;
      s1 |= v & f.sel;
    }
  }
  if (bad != 0 || !(gap <= m.fast_tol_) || !(inside >= 0.0)) [[unlikely]] return false;
  std::uint64_t w = load_le8(data) & ~m.clear_le_;
  if constexpr (O != Order::motorola) w |= s0;
  if constexpr (O != Order::intel) w |= __builtin_bswap64(s1);
  store_le8(data, w);
  return true;
}

bool MessageCodec::decode_general(std::span<const std::uint8_t> data, std::span<double> values) const noexcept {
  if (values.size() != codecs_.size() || data.size() < message_.size) return false;
  if (packed_) {
    const std::uint64_t le = load_le(data, message_.size);
    const std::uint64_t words[2] = {le, __builtin_bswap64(le)};  // [word]
    const Lane* const lanes = lanes_.data();
    const std::uint32_t n = static_cast<std::uint32_t>(lanes_.size());
    const auto lane = [&](const Lane& l, std::uint64_t word) {
      const std::uint64_t raw = (word >> l.lo) & l.mask;
      values[l.index] = static_cast<double>(static_cast<std::int64_t>((raw ^ l.sign) - l.sign)) * l.factor + l.offset;
    };
    for (std::uint32_t k = 0; k < intel_lanes_; ++k) lane(lanes[k], words[0]);
    for (std::uint32_t k = intel_lanes_; k < n; ++k) lane(lanes[k], words[1]);
    for (const std::uint32_t i : slow_) {
      const SignalCodec& c = codecs_[i];
      values[i] = c.to_physical((words[c.signal_.byte_order == dbc::ByteOrder::motorola ? 1 : 0] >> c.lo_base_) & c.mask_);
    }
  } else {
    for (std::size_t i = 0; i < codecs_.size(); ++i) values[i] = *codecs_[i].decode(data);
  }
  if (has_mux_)
    for (const std::uint32_t i : order_)
      if (!selected(i, data, values)) values[i] = std::numeric_limits<double>::quiet_NaN();
  return true;
}

inline std::uint64_t MessageCodec::lane_raw(const Lane& l, double p, std::uint32_t& clamped) const noexcept {
  // Fast path: p inside [min|max] (±inf without a DBC range), the product rounds like the
  // exact quotient, the result fits the field. Anything else (NaN, ±inf, a value to clamp,
  // a product within rounding error of a .5 tie) is decided by the reference to_raw().
  if (!(p < l.min_phys) && !(p > l.max_phys)) [[likely]] {
    const double q = (p - l.offset) * l.inv_factor;
    // Round half to even without libm: adding and subtracting 2^52 with q's sign leaves
    // the nearest integer (the FPU rounds ties to even).
    const double m = std::copysign(4503599627370496.0, q);
    const double r = (q + m) - m;
    // |q·(1/f) − q/f| ≤ 3·2^-53·|q|; for |q| ≤ (largest raw + 1) half_tol keeps that gap
    // away from a tie (see the constructor); a larger |q| leaves the field and takes the
    // reference path below. NaN fails this test. Beyond 2^52, q + m − m = q is integral and
    // passes the first test (e.g. q = −8.8e302): the second keeps the conversion defined.
    if (std::fabs(q - r) < l.half_tol && std::fabs(r) <= 4503599627370496.0) [[likely]] {
      const auto ir = static_cast<std::int64_t>(r);  // |r| ≤ 2^52 here
      if (static_cast<std::uint64_t>(ir) - static_cast<std::uint64_t>(l.raw_lo) <= l.raw_span) [[likely]]
        return static_cast<std::uint64_t>(ir) & l.mask;
    }
  }
  bool cl = false;
  const std::uint64_t raw = codecs_[l.index].to_raw(p, cl);
  clamped += cl ? 1u : 0u;
  return raw;
}

template <bool Mux>
std::uint32_t MessageCodec::encode_packed(std::span<const double> values, std::uint64_t set[2], std::uint64_t clear[2]) noexcept {
  std::uint32_t clamped = 0;
  const Lane* const lanes = lanes_.data();
  const std::uint32_t n = static_cast<std::uint32_t>(lanes_.size());
  // Intel lanes, then Motorola lanes, each into a register accumulator.
  std::uint64_t s0 = 0, s1 = 0, c0 = 0, c1 = 0;
  for (std::uint32_t k = 0; k < intel_lanes_; ++k) {
    const Lane& l = lanes[k];
    if constexpr (Mux) {
      if (!present_[l.index]) continue;
      c0 |= l.mask << l.lo;
    }
    s0 |= lane_raw(l, values[l.index], clamped) << l.lo;
  }
  for (std::uint32_t k = intel_lanes_; k < n; ++k) {
    const Lane& l = lanes[k];
    if constexpr (Mux) {
      if (!present_[l.index]) continue;
      c1 |= l.mask << l.lo;
    }
    s1 |= lane_raw(l, values[l.index], clamped) << l.lo;
  }
  set[0] |= s0;
  set[1] |= s1;
  clear[0] |= c0;
  clear[1] |= c1;
  for (const std::uint32_t i : slow_) {
    if (Mux && !present_[i]) continue;
    const SignalCodec& c = codecs_[i];
    const std::size_t w = c.signal_.byte_order == dbc::ByteOrder::motorola ? 1 : 0;
    bool cl = false;
    const std::uint64_t raw = c.to_raw(values[i], cl);
    clamped += cl ? 1u : 0u;
    if (Mux) clear[w] |= c.mask_ << c.lo_base_;
    set[w] |= raw << c.lo_base_;
  }
  return clamped;
}

MessageCodec::EncodeResult MessageCodec::encode_general(std::span<const double> values, std::span<std::uint8_t> data) noexcept {
  EncodeResult res;
  if (values.size() != codecs_.size() || data.size() < message_.size) return res;
  if (has_mux_) {
    // Which signals the multiplexors' encoded values select (multiplexors first).
    for (const std::uint32_t i : order_) {
      const std::int32_t p = parent_[i];
      bool on = true;
      if (p >= 0) {
        const auto pi = static_cast<std::size_t>(p);
        on = present_[pi] && !std::isnan(values[pi]) && !std::isnan(values[i]);
        if (on) {
          bool ignored = false;
          const std::uint64_t raw = codecs_[pi].to_raw(values[pi], ignored);
          on = false;
          for (std::uint32_t r = range_begin_[i]; r < range_begin_[i + 1]; ++r)
            if (raw >= ranges_[r].lo && raw <= ranges_[r].hi) on = true;
        }
      }
      present_[i] = on ? 1 : 0;
    }
  }
  if (packed_) {
    // Bits to clear/set, kept per byte order and merged into one word at the end.
    std::uint64_t set[2] = {0, 0};
    std::uint64_t clear[2] = {0, 0};
    if (has_mux_) {
      res.clamped = encode_packed<true>(values, set, clear);
    } else {
      res.clamped = encode_packed<false>(values, set, clear);
      clear[0] = clear_all_[0];
      clear[1] = clear_all_[1];
    }
    std::uint64_t w = load_le(data, message_.size);
    w = (w & ~(clear[0] | __builtin_bswap64(clear[1]))) | set[0] | __builtin_bswap64(set[1]);
    if (data.size() >= 8) {
      if constexpr (std::endian::native == std::endian::big) w = __builtin_bswap64(w);
      std::memcpy(data.data(), &w, 8);
    } else {
      for (std::size_t i = 0; i < message_.size; ++i) data[i] = static_cast<std::uint8_t>(w >> (8 * i));
    }
    clamp_count_ += res.clamped;
    res.ok = true;
    return res;
  }
  for (std::size_t i = 0; i < codecs_.size(); ++i) {
    if (has_mux_ && !present_[i]) continue;
    if (codecs_[i].encode(values[i], data) == SignalCodec::Status::clamped) ++res.clamped;
  }
  clamp_count_ += res.clamped;
  res.ok = true;
  return res;
}

}  // namespace lash::can
