// CAN codec: encode + decode of a 4-signal message per byte order against the same work
// written by hand (the floor; target <= 1.5x, bench/can_codec_ratio.py prints the ratio),
// log reading, DBC loading and the datagram codec. See docs/can.md.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "lash/can/codec.hpp"
#include "lash/can/datagram.hpp"
#include "lash/can/log.hpp"

namespace {

lash::can::dbc::Message four_signals(lash::can::dbc::ByteOrder order) {
  using namespace lash::can::dbc;
  Message m;
  m.name = "Bench";
  m.id = 0x100;
  m.size = 8;
  auto sig = [&](const char* name, std::uint32_t start, std::uint32_t len, bool sgn, double f, double o) {
    Signal s;
    s.name = name;
    s.start_bit = start;
    s.length = len;
    s.byte_order = order;
    s.is_signed = sgn;
    s.factor = f;
    s.offset = o;
    return s;
  };
  if (order == ByteOrder::intel) {
    m.signals = {sig("current_A", 0, 16, false, 0.1, 0), sig("current_B", 16, 16, false, 0.1, 0),
                 sig("pressure", 32, 12, true, 0.5, -100), sig("counter", 44, 4, false, 1, 0)};
  } else {
    m.signals = {sig("current_A", 7, 16, false, 0.1, 0), sig("current_B", 23, 16, false, 0.1, 0),
                 sig("pressure", 39, 12, true, 0.5, -100), sig("counter", 43, 4, false, 1, 0)};
  }
  return m;
}

void encode_decode(benchmark::State& state, lash::can::dbc::ByteOrder order) {
  lash::can::MessageCodec codec(four_signals(order));
  std::array<std::uint8_t, 8> data{};
  std::array<double, 4> in{1234.5, 987.6, -42.5, 7};
  std::array<double, 4> out{};
  for (auto _ : state) {
    benchmark::DoNotOptimize(in.data());
    codec.encode(in, data);
    codec.decode(data, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
    in[0] = in[0] < 6000.0 ? in[0] + 0.1 : 0.0;  // a new value each round, inside the 16-bit field
  }
  if (out[1] != 987.6 && out[1] != 987.6000000000001) state.SkipWithError("decode mismatch");
}

void BM_CanEncodeDecode4Intel(benchmark::State& s) { encode_decode(s, lash::can::dbc::ByteOrder::intel); }
void BM_CanEncodeDecode4Motorola(benchmark::State& s) { encode_decode(s, lash::can::dbc::ByteOrder::motorola); }
BENCHMARK(BM_CanEncodeDecode4Intel);
BENCHMARK(BM_CanEncodeDecode4Motorola);

/// The raw codes of four_signals() by hand (scale 0.1, 0.1, 0.5 with offset -100, 1; ties to
/// even), masked to their field widths: shared by both hand-written floors.
inline std::array<std::uint64_t, 4> raw_codes(const std::array<double, 4>& in) {
  return {static_cast<std::uint64_t>(lash::can::round_half_even(in[0] * 10.0)) & 0xFFFF,
          static_cast<std::uint64_t>(lash::can::round_half_even(in[1] * 10.0)) & 0xFFFF,
          static_cast<std::uint64_t>(static_cast<std::int64_t>(lash::can::round_half_even((in[2] + 100.0) * 2.0))) &
              0xFFF,
          static_cast<std::uint64_t>(lash::can::round_half_even(in[3])) & 0xF};
}

/// The floor: the Intel layout of four_signals() extracted by hand (constants folded by
/// the compiler), with the same rounding (ties to even) and the same sign extension.
void BM_CanHandWritten4Intel(benchmark::State& state) {
  std::array<std::uint8_t, 8> data{};
  std::array<double, 4> in{1234.5, 987.6, -42.5, 7};
  std::array<double, 4> out{};
  for (auto _ : state) {
    benchmark::DoNotOptimize(in.data());
    const auto [a, b, c, d] = raw_codes(in);
    std::uint64_t w;
    std::memcpy(&w, data.data(), 8);
    w = (w & ~0xFFFFFFFFFFFFull) | a | (b << 16) | (c << 32) | (d << 44);
    std::memcpy(data.data(), &w, 8);
    std::uint64_t r;
    std::memcpy(&r, data.data(), 8);
    out[0] = static_cast<double>(r & 0xFFFF) * 0.1;
    out[1] = static_cast<double>((r >> 16) & 0xFFFF) * 0.1;
    out[2] = static_cast<double>(static_cast<std::int64_t>(r << 20) >> 52) * 0.5 - 100.0;
    out[3] = static_cast<double>((r >> 44) & 0xF);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
    in[0] = in[0] < 6000.0 ? in[0] + 0.1 : 0.0;
  }
  if (out[1] != 987.6 && out[1] != 987.6000000000001) state.SkipWithError("decode mismatch");
}
BENCHMARK(BM_CanHandWritten4Intel);

/// The floor of the Motorola layout: the payload as one big-endian word, fields at bits
/// 48 (16), 32 (16), 20 (12, signed) and 16 (4) of it.
void BM_CanHandWritten4Motorola(benchmark::State& state) {
  std::array<std::uint8_t, 8> data{};
  std::array<double, 4> in{1234.5, 987.6, -42.5, 7};
  std::array<double, 4> out{};
  for (auto _ : state) {
    benchmark::DoNotOptimize(in.data());
    const auto [a, b, c, d] = raw_codes(in);
    std::uint64_t w;
    std::memcpy(&w, data.data(), 8);
    w = __builtin_bswap64((__builtin_bswap64(w) & 0xFFFFull) | (a << 48) | (b << 32) | (c << 20) | (d << 16));
    std::memcpy(data.data(), &w, 8);
    std::uint64_t r;
    std::memcpy(&r, data.data(), 8);
    r = __builtin_bswap64(r);
    out[0] = static_cast<double>((r >> 48) & 0xFFFF) * 0.1;
    out[1] = static_cast<double>((r >> 32) & 0xFFFF) * 0.1;
    out[2] = static_cast<double>(static_cast<std::int64_t>(r << 32) >> 52) * 0.5 - 100.0;
    out[3] = static_cast<double>((r >> 16) & 0xF);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
    in[0] = in[0] < 6000.0 ? in[0] + 0.1 : 0.0;
  }
  if (out[1] != 987.6 && out[1] != 987.6000000000001) state.SkipWithError("decode mismatch");
  if (out[2] != -42.5 || out[3] != 7.0) state.SkipWithError("decode mismatch");
}
BENCHMARK(BM_CanHandWritten4Motorola);

/// Reading logs: 100 000 frames (classic, extended, FD) written once by lash in the
/// format, then read with can::read_log; items/s = frames per second.
void read_log_bench(benchmark::State& state, const char* ext) {
  const auto path = std::filesystem::temp_directory_path() / (std::string("lash_bench_read") + ext);
  std::vector<lash::can::LogEntry> v(100000);
  for (std::size_t i = 0; i < v.size(); ++i) {
    auto& f = v[i].frame;
    f.id = static_cast<std::uint32_t>(i % 0x7FF);
    f.extended = i % 5 == 0;
    f.fd = i % 7 == 0;
    f.len = f.fd ? 16 : 8;
    for (std::size_t k = 0; k < f.len; ++k) f.data[k] = static_cast<std::uint8_t>(i + k);
    f.timestamp_s = 1700000000.0 + static_cast<double>(i) * 1e-4;
    v[i].interface = "1";
  }
  lash::can::write_log(path, v);
  std::size_t n = 0;
  for (auto _ : state) {
    const auto got = lash::can::read_log(path);
    n += got.size();
    benchmark::DoNotOptimize(got.data());
  }
  std::filesystem::remove(path);
  state.SetItemsProcessed(static_cast<std::int64_t>(n));
}
void BM_CanReadAsc(benchmark::State& s) { read_log_bench(s, ".asc"); }
void BM_CanReadBlf(benchmark::State& s) { read_log_bench(s, ".blf"); }
void BM_CanReadTrc(benchmark::State& s) { read_log_bench(s, ".trc"); }
void BM_CanReadCandump(benchmark::State& s) { read_log_bench(s, ".log"); }
BENCHMARK(BM_CanReadAsc)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CanReadBlf)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CanReadTrc)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CanReadCandump)->Unit(benchmark::kMillisecond);

/// Loading a DBC file (read, parse, check every layout): the file named by LASH_BENCH_DBC
/// (bench/dbc_load_vs_canmatrix.py passes the corpus's largest); skipped without it.
void BM_CanLoadDbc(benchmark::State& state) {
  const char* path = std::getenv("LASH_BENCH_DBC");
  if (!path) {
    state.SkipWithError("set LASH_BENCH_DBC to a DBC file");
    return;
  }
  for (auto _ : state) {
    std::vector<lash::can::dbc::Diagnostic> d;
    const auto db = lash::can::dbc::load_dbc(path, {}, &d);
    benchmark::DoNotOptimize(db.messages.data());
  }
}
BENCHMARK(BM_CanLoadDbc)->Unit(benchmark::kMillisecond);

void BM_CanDatagramEncodeDecode(benchmark::State& state) {
  lash::can::Frame f;
  f.id = 0x123;
  f.len = 8;
  std::array<std::uint8_t, 256> buf{};
  lash::can::Frame g;
  for (auto _ : state) {
    const std::size_t n = lash::can::udp::encode_datagram(f, 1.0, buf);
    benchmark::DoNotOptimize(lash::can::udp::decode_datagram({buf.data(), n}, g));
    ++f.data[0];
  }
}
BENCHMARK(BM_CanDatagramEncodeDecode);

}  // namespace
