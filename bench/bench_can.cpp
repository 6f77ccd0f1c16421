// CAN codec: encode + decode of a 4-signal message (target <= 20 ns), per byte order,
// and the datagram codec. See docs/can.md.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>

#include "lash/can/codec.hpp"
#include "lash/can/datagram.hpp"

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
    in[0] += 0.1;  // a new value each round
  }
  if (out[1] != 987.6 && out[1] != 987.6000000000001) state.SkipWithError("decode mismatch");
}

void BM_CanEncodeDecode4Intel(benchmark::State& s) { encode_decode(s, lash::can::dbc::ByteOrder::intel); }
void BM_CanEncodeDecode4Motorola(benchmark::State& s) { encode_decode(s, lash::can::dbc::ByteOrder::motorola); }
BENCHMARK(BM_CanEncodeDecode4Intel);
BENCHMARK(BM_CanEncodeDecode4Motorola);

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
