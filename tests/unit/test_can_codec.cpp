// Signal codec against a naive bit-by-bit reference (dbcppp's testing idea) and hand-computed frames.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "lash/can/codec.hpp"
#include "lash/signals/rng.hpp"

using namespace lash::can;
using dbc::ByteOrder;

namespace {

// Naive reference, written from the DBC definition, independent of codec.cpp:
// Intel: raw bit i is payload bit start+i (bit k = byte k/8, bit k%8).
// Motorola: start is the MSB; walk the sawtooth (7..0, 15..8, ...) towards the LSB:
// from bit b the next less significant bit is b-1, or b+15 at a byte boundary (b%8 == 0).
std::vector<std::uint32_t> naive_positions(const dbc::Signal& s) {
  std::vector<std::uint32_t> pos(s.length);  // pos[i] = payload bit of raw bit i
  if (s.byte_order == ByteOrder::intel) {
    for (std::uint32_t i = 0; i < s.length; ++i) pos[i] = s.start_bit + i;
  } else {
    std::uint32_t b = s.start_bit;
    for (std::uint32_t k = 0; k < s.length; ++k) {
      pos[s.length - 1 - k] = b;
      b = (b % 8 == 0) ? b + 15 : b - 1;
    }
  }
  return pos;
}
std::uint64_t naive_read(const dbc::Signal& s, const std::vector<std::uint8_t>& d) {
  const auto pos = naive_positions(s);
  std::uint64_t raw = 0;
  for (std::uint32_t i = 0; i < s.length; ++i)
    if ((d[pos[i] / 8] >> (pos[i] % 8)) & 1u) raw |= std::uint64_t{1} << i;
  return raw;
}
void naive_write(const dbc::Signal& s, std::vector<std::uint8_t>& d, std::uint64_t raw) {
  const auto pos = naive_positions(s);
  for (std::uint32_t i = 0; i < s.length; ++i) {
    const auto m = static_cast<std::uint8_t>(1u << (pos[i] % 8));
    if ((raw >> i) & 1u)
      d[pos[i] / 8] = static_cast<std::uint8_t>(d[pos[i] / 8] | m);
    else
      d[pos[i] / 8] = static_cast<std::uint8_t>(d[pos[i] / 8] & ~m);
  }
}
std::size_t naive_min_bytes(const dbc::Signal& s) {
  std::uint32_t mx = 0;
  for (auto p : naive_positions(s)) mx = std::max(mx, p);
  return mx / 8 + 1;
}

dbc::Signal make(std::uint32_t start, std::uint32_t len, ByteOrder o, bool is_signed, double factor = 1,
                 double offset = 0) {
  dbc::Signal s;
  s.name = "s";
  s.start_bit = start;
  s.length = len;
  s.byte_order = o;
  s.is_signed = is_signed;
  s.factor = factor;
  s.offset = offset;
  return s;
}

}  // namespace

TEST(CanCodec, RandomLayoutsMatchNaiveReference) {
  lash::Rng rng(20260522);
  const int kLayouts = 120000;
  int wide = 0, short_frames = 0;
  for (int n = 0; n < kLayouts; ++n) {
    // Frame sizes: mostly classic 8 bytes, some short frames, some CAN FD 64-byte frames.
    const std::uint64_t pick = rng.next() % 10;
    const std::size_t frame_len = pick < 6 ? 8 : pick < 8 ? 1 + rng.next() % 7 : 9 + rng.next() % 56;
    const std::uint32_t bits = static_cast<std::uint32_t>(frame_len * 8);
    const auto len = static_cast<std::uint32_t>(1 + rng.next() % std::min<std::uint32_t>(64, bits));
    const ByteOrder order = (rng.next() & 1) ? ByteOrder::intel : ByteOrder::motorola;
    const bool sgn = (rng.next() & 1) != 0;
    // Any start bit that fits: draw until the layout lies inside the frame.
    dbc::Signal s;
    for (;;) {
      s = make(static_cast<std::uint32_t>(rng.next() % bits), len, order, sgn);
      if (naive_min_bytes(s) <= frame_len && (order == ByteOrder::motorola || s.start_bit + len <= bits)) break;
    }
    SignalCodec c(s);
    ASSERT_EQ(c.min_bytes(), naive_min_bytes(s)) << n;
    const auto pos = naive_positions(s);
    if (pos.back() / 8 - pos.front() / 8 + 1 > 8 || pos.front() / 8 - pos.back() / 8 + 1 > 8) ++wide;
    if (frame_len < 8) ++short_frames;
    std::vector<std::uint8_t> d(frame_len);
    for (auto& b : d) b = static_cast<std::uint8_t>(rng.next());
    // read
    const auto got = c.read_raw(d);
    ASSERT_TRUE(got.has_value());
    ASSERT_EQ(*got, naive_read(s, d)) << "layout " << n << " start " << s.start_bit << " len " << len;
    // decode (sign extension)
    const std::uint64_t r = naive_read(s, d);
    double expect = static_cast<double>(r);
    if (sgn && len < 64 && ((r >> (len - 1)) & 1u))  // two's complement: set the bits above the sign
      expect = static_cast<double>(static_cast<std::int64_t>(r | (~std::uint64_t{0} << len)));
    if (sgn && len == 64) expect = static_cast<double>(static_cast<std::int64_t>(r));
    ASSERT_EQ(*c.decode(d), expect) << n;
    // write: identical bytes, other bits untouched
    const std::uint64_t raw = rng.next();
    auto a = d, b = d;
    ASSERT_TRUE(c.write_raw(a, raw));
    naive_write(s, b, len == 64 ? raw : raw & ((std::uint64_t{1} << len) - 1));
    ASSERT_EQ(a, b) << "layout " << n;
    // too short spans are refused
    if (c.min_bytes() > 0) {
      std::vector<std::uint8_t> shorter(c.min_bytes() - 1);
      EXPECT_FALSE(c.read_raw(shorter).has_value());
      EXPECT_FALSE(c.write_raw(shorter, 1));
    }
  }
  EXPECT_GT(wide, 100);  // the 9-byte path was exercised
  EXPECT_GT(short_frames, 1000);
}

TEST(CanCodec, HandComputedFrames) {
  // Intel 0|16: bytes 34 12 -> 0x1234
  SignalCodec intel(make(0, 16, ByteOrder::intel, false));
  const std::uint8_t a[8] = {0x34, 0x12, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(*intel.read_raw(a), 0x1234u);
  // Motorola 7|16: bytes 12 34 -> 0x1234
  SignalCodec moto(make(7, 16, ByteOrder::motorola, false));
  const std::uint8_t b[8] = {0x12, 0x34, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(*moto.read_raw(b), 0x1234u);
  // Motorola 3|8: low nibble of byte 0 is the high nibble of the value, high nibble of byte 1 the low one.
  SignalCodec m2(make(3, 8, ByteOrder::motorola, false));
  const std::uint8_t c[2] = {0xA5, 0x3C};
  EXPECT_EQ(*m2.read_raw(c), 0x53u);
  // Signed Intel 12 bits at 4: 0xF80 = -128
  SignalCodec s12(make(4, 12, ByteOrder::intel, true, 0.5, 10));
  std::uint8_t e[2] = {0x00, 0xF8};
  EXPECT_EQ(*s12.decode(e), -128 * 0.5 + 10);
}

TEST(CanCodec, RoundsToNearestAndClamps) {
  SignalCodec c(make(0, 8, ByteOrder::intel, false, 0.1, 0));
  bool clamped = false;
  EXPECT_EQ(c.to_raw(0.26, clamped), 3u);  // 2.6 -> 3 (truncation would give 2)
  EXPECT_FALSE(clamped);
  EXPECT_EQ(c.to_raw(0.24, clamped), 2u);
  EXPECT_EQ(c.to_raw(-1.0, clamped), 0u);
  EXPECT_TRUE(clamped);
  EXPECT_EQ(c.to_raw(1000.0, clamped), 255u);
  EXPECT_TRUE(clamped);
  std::uint8_t d[1] = {0};
  EXPECT_EQ(c.encode(30.0, d), SignalCodec::Status::clamped);
  EXPECT_EQ(c.encode(3.0, d), SignalCodec::Status::ok);
  EXPECT_EQ(c.encode(-3.0, d), SignalCodec::Status::clamped);
  EXPECT_EQ(c.clamp_count(), 2u);
  EXPECT_EQ(d[0], 0u);
  // Signed 8 bit: -128..127; DBC range [-10|10] clamps first.
  auto s = make(0, 8, ByteOrder::intel, true);
  SignalCodec sc(s);
  EXPECT_EQ(sc.to_raw(-200, clamped), 0x80u);
  EXPECT_TRUE(clamped);
  EXPECT_EQ(sc.to_raw(200, clamped), 0x7Fu);
  s.minimum = -10;
  s.maximum = 10;
  SignalCodec sr(s);
  EXPECT_EQ(sr.to_raw(-20, clamped), 0xF6u);
  EXPECT_TRUE(clamped);
  // 64-bit extremes
  SignalCodec u64(make(0, 64, ByteOrder::intel, false));
  EXPECT_EQ(u64.to_raw(1e30, clamped), ~std::uint64_t{0});
  EXPECT_TRUE(clamped);
  SignalCodec i64(make(0, 64, ByteOrder::intel, true));
  EXPECT_EQ(i64.to_raw(-1e30, clamped), std::uint64_t{1} << 63);
  EXPECT_EQ(i64.to_raw(-1, clamped), ~std::uint64_t{0});
  EXPECT_FALSE(clamped);
}

TEST(CanCodec, FloatSignals) {
  auto s = make(0, 32, ByteOrder::intel, false);
  s.value_type = dbc::ValueType::float32;
  SignalCodec c(s);
  std::uint8_t d[4] = {};
  c.encode(1.5, d);  // 1.5f = 0x3FC00000
  EXPECT_EQ(d[3], 0x3F);
  EXPECT_EQ(d[2], 0xC0);
  EXPECT_EQ(*c.decode(d), 1.5);
}

TEST(CanCodec, MessageWithMultiplexing) {
  dbc::Message m;
  m.name = "M";
  m.size = 8;
  auto mux = make(0, 4, ByteOrder::intel, false);
  mux.name = "Mode";
  mux.mux = dbc::MuxRole::multiplexor;
  auto a = make(8, 8, ByteOrder::intel, false);
  a.name = "A";
  a.mux = dbc::MuxRole::multiplexed;
  a.mux_value = 0;
  auto b = make(8, 8, ByteOrder::intel, true);
  b.name = "B";
  b.mux = dbc::MuxRole::multiplexed;
  b.mux_value = 1;
  m.signals = {mux, a, b};
  MessageCodec mc(m);
  std::uint8_t d[8] = {};
  const double v1[3] = {1, 200, -5};
  auto r = mc.encode(v1, d);
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(d[0], 1);
  EXPECT_EQ(d[1], 0xFB);  // B = -5 written, A skipped
  double out[3];
  ASSERT_TRUE(mc.decode(d, out));
  EXPECT_EQ(out[0], 1);
  EXPECT_TRUE(std::isnan(out[1]));
  EXPECT_EQ(out[2], -5);
  const std::uint8_t shortd[4] = {};
  EXPECT_FALSE(mc.decode(shortd, out));
}

TEST(CanCodec, ConstructionRejectsBadLayouts) {
  EXPECT_THROW(SignalCodec(make(0, 0, ByteOrder::intel, false)), std::invalid_argument);
  EXPECT_THROW(SignalCodec(make(0, 65, ByteOrder::intel, false)), std::invalid_argument);
  EXPECT_THROW(SignalCodec(make(0, 8, ByteOrder::intel, false, 0.0)), std::invalid_argument);
  dbc::Message m;
  m.name = "Small";
  m.size = 1;
  m.signals = {make(8, 8, ByteOrder::intel, false)};
  EXPECT_THROW(MessageCodec{m}, std::invalid_argument);
}

TEST(CanCodec, MessagePathMatchesSignalPath) {
  // MessageCodec's one-word path (messages <= 8 bytes) against SignalCodec one signal at a
  // time, on random messages of non-overlapping signals and random (also out-of-range) values.
  lash::Rng rng(99);
  // 1e-300: a signed field's decode scale (factor x 2^-k) would be subnormal, so no fast plan.
  const double factors[] = {0.1, 0.5, 1.0, 2.5, 0.01, -0.25, 1e-3, 7.0, 1e-300};
  // Messages of 1..12 signals: the fast plan has kernels for 1..8 lanes and a loop beyond.
  std::vector<int> seen(13, 0), fits(13, 0);
  for (int n = 0; n < 20000; ++n) {
    dbc::Message m;
    m.name = "R";
    m.size = static_cast<std::uint32_t>(1 + rng.next() % 8);
    std::vector<bool> used(64, false);
    const int want = 1 + static_cast<int>(rng.next() % 12);
    const std::uint32_t max_len = want > 6 ? 8 : 64;
    // Mostly one byte order per message (the fast plan's two-wide kernels), sometimes mixed.
    const bool mixed = rng.next() % 4 == 0;
    const bool intel = (rng.next() & 1) != 0;
    // Half the messages get values inside every field (and [min|max] wide enough), the case
    // the fast plan codes by itself; the other half also values to clamp (the fallback).
    const bool fit = (rng.next() & 1) != 0;
    for (int k = 0; k < want * 8 && static_cast<int>(m.signals.size()) < want; ++k) {
      const auto len = static_cast<std::uint32_t>(1 + rng.next() % std::min<std::uint32_t>(max_len, m.size * 8));
      const bool in = mixed ? (rng.next() & 1) != 0 : intel;
      auto s = make(static_cast<std::uint32_t>(rng.next() % (m.size * 8)), len,
                    in ? ByteOrder::intel : ByteOrder::motorola, (rng.next() & 1) != 0,
                    factors[rng.next() % 9], static_cast<double>(static_cast<int>(rng.next() % 200) - 100));
      if (rng.next() % 3 == 0) {
        s.minimum = fit ? -1e12 : -50;
        s.maximum = fit ? 1e12 : 50;
      }
      if (s.byte_order == ByteOrder::intel && s.start_bit + len > m.size * 8) continue;
      if (naive_min_bytes(s) > m.size) continue;
      const auto pos = naive_positions(s);
      bool clash = false;
      for (auto p : pos) clash = clash || used[p];
      if (clash) continue;
      for (auto p : pos) used[p] = true;
      s.name = "s" + std::to_string(m.signals.size());
      m.signals.push_back(s);
    }
    MessageCodec mc(m);
    ASSERT_TRUE(mc.packed());
    ++seen[m.signals.size()];
    std::vector<SignalCodec> sc;
    for (const auto& s : m.signals) sc.emplace_back(s);
    std::vector<double> vals(m.signals.size());
    for (std::size_t i = 0; i < vals.size(); ++i) {
      const dbc::Signal& s = m.signals[i];
      if (fit) {
        // A raw value of the field, ± up to 0.4, or + 0.5 (a tie, up to the rounding of the
        // scaling), in physical units.
        const std::uint64_t mask = s.length == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << s.length) - 1;
        std::uint64_t u = rng.next() & mask;
        if (s.is_signed && s.length < 64 && (u >> (s.length - 1)) != 0) u |= ~mask;
        const double raw = s.is_signed ? static_cast<double>(static_cast<std::int64_t>(u)) : static_cast<double>(u);
        const double frac = (rng.next() % 5 == 0) ? 0.5 : static_cast<double>(static_cast<int>(rng.next() % 801) - 400) / 1000.0;
        vals[i] = (raw + frac) * s.factor + s.offset;
      } else {
        const double u = static_cast<double>(rng.next() % 2000001) / 1000.0 - 1000.0;  // -1000..1000, step 0.001
        vals[i] = (rng.next() % 5 == 0) ? std::round(u) + 0.5 : u;  // some exact ties
      }
    }
    std::vector<std::uint8_t> a(8), b(8);
    for (std::size_t i = 0; i < 8; ++i) a[i] = b[i] = static_cast<std::uint8_t>(rng.next());
    const std::size_t span = (rng.next() & 1) ? 8 : m.size;
    const auto r = mc.encode(vals, {a.data(), span});
    ASSERT_TRUE(r.ok);
    std::uint32_t clamps = 0;
    for (std::size_t i = 0; i < sc.size(); ++i)
      clamps += sc[i].encode(vals[i], {b.data(), span}) == SignalCodec::Status::clamped ? 1u : 0u;
    ASSERT_EQ(a, b) << "message " << n;
    ASSERT_EQ(r.clamped, clamps);
    fits[m.signals.size()] += clamps == 0 ? 1 : 0;
    std::vector<double> out(vals.size());
    ASSERT_TRUE(mc.decode({a.data(), span}, out));
    for (std::size_t i = 0; i < sc.size(); ++i) ASSERT_EQ(out[i], *sc[i].decode({a.data(), span})) << n;
  }
  for (std::size_t k = 1; k <= 12; ++k) {
    EXPECT_GE(seen[k], 100) << k << " signals";
    EXPECT_GE(fits[k], 50) << k << " signals, no clamp";
  }
}
