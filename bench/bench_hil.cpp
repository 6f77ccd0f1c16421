// HIL node step functions (what the master's TET measures, minus the bus's system calls)
// and the UDP bus's send/receive cost, to split `lash hil run`'s TET into compute and I/O.
#include <benchmark/benchmark.h>

#include <sched.h>

#include <array>
#include <chrono>
#include <memory>
#include <vector>

#include "lash/can/bus.hpp"
#include "lash/hil/nodes.hpp"
#include "lash/hil/netns.hpp"
#include "lash/hil/xcp_server.hpp"
#include "hil_master_fixture.hpp"

#include <atomic>
#include <thread>

namespace {

using namespace lash;
using namespace lash::hil;

using bench::connected_master;
using bench::dto;
using bench::ScriptedBus;

void BM_HilMasterStep(benchmark::State& state) {
  BenchLayout L;
  ScriptedBus bus;
  MasterNode master = connected_master(L, bus, 0.005);
  std::uint16_t c = 0;
  for (auto _ : state) {
    bus.next = L.pack_sensors({static_cast<std::uint16_t>(17000 + (c & 255)), 0, c});
    bus.pending = true;
    ++c;
    benchmark::DoNotOptimize(master.step(bus, 0.0));
  }
  state.SetLabel("master step without bus I/O: drain, plausibility check, decode, PID + DZ inverse + saturation, encode + CRC, log");
}
BENCHMARK(BM_HilMasterStep);

// The same step with the XCP slave attached (issue 26): each step takes the newest calibration
// page (a new one every 1000 steps) and pushes its measurements; a second thread, as the
// master's XCP thread does, pops them, copies them into the slave's image and samples a DAQ list
// of 5 FLOAT64 measurements (6 ODTs, sent to a sink). Goal: mean within +1 us of BM_HilMasterStep.
void BM_HilMasterStepXcp(benchmark::State& state) {
  BenchLayout L;
  ScriptedBus bus;
  MasterNode master = connected_master(L, bus, 0.005);
  auto link = std::make_unique<XcpLink>();
  master.attach(link.get());
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> dtos{0};
  std::thread xcp_thread([&] {
    can::xcp::Slave slave(master_xcp_config(L), [&](const can::Frame&) { dtos.fetch_add(1, std::memory_order_relaxed); });
    auto cmd = [&](std::initializer_list<std::uint8_t> b) {
      can::Frame f;
      f.id = L.xcp_cmd_id;
      f.len = static_cast<std::uint8_t>(b.size());
      std::copy(b.begin(), b.end(), f.data.begin());
      slave.on_frame(f);
    };
    // CONNECT, then one DAQ list: 5 measurements at 0x10200.. (40 bytes: 3 + 6 x 7 over 7 ODTs).
    cmd({0xFF, 0});
    cmd({0xD6});
    cmd({0xD5, 0, 1, 0});
    cmd({0xD4, 0, 0, 0, 7});
    for (std::uint8_t k = 0; k < 7; ++k) cmd({0xD3, 0, 0, 0, k, 1});
    std::uint32_t a = kXcpMeasurementBase;
    for (std::uint8_t k = 0; k < 7; ++k) {
      const std::uint8_t n = k == 0 ? 3 : (k == 6 ? 40 - 3 - 5 * 7 : 7);
      cmd({0xE2, 0, 0, 0, k, 0});
      cmd({0xE1, 0xFF, n, 0, static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(a >> 8),
           static_cast<std::uint8_t>(a >> 16), static_cast<std::uint8_t>(a >> 24)});
      a += n;
    }
    cmd({0xE0, 0x10, 0, 0, 0, 0, 1, 0});
    cmd({0xDE, 0x01, 0, 0});
    MeasurementSample smp;
    while (!stop.load(std::memory_order_relaxed)) {
      while (link->samples.pop(smp)) {
        for (std::size_t i = 0; i < 5; ++i)
          slave.set(slave.config().objects[calibration_fields().size() + i], smp.page.*measurement_fields()[i].member);
        slave.sample_event(0, static_cast<std::uint32_t>(smp.t_us));
      }
      std::this_thread::yield();
    }
  });
  std::uint16_t c = 0;
  CalibrationPage page = master.calibration();
  for (auto _ : state) {
    if ((c % 1000) == 0) {
      page.kp = (c & 1000) ? 1.2 : 1.3;
      link->pages.push(page);
    }
    bus.next = L.pack_sensors({static_cast<std::uint16_t>(17000 + (c & 255)), 0, c});
    bus.pending = true;
    ++c;
    benchmark::DoNotOptimize(master.step(bus, 0.0));
  }
  stop.store(true);
  xcp_thread.join();
  state.counters["dtos_per_step"] = static_cast<double>(dtos.load()) / static_cast<double>(state.iterations());
  state.counters["samples_lost"] = static_cast<double>(link->samples_lost.load());
  state.SetLabel("master step with the XCP link: newest calibration page in, measurements out (lock-free queues)");
}
BENCHMARK(BM_HilMasterStepXcp);

// One plausibility check of a received frame, as a node runs it on every frame with its input
// identifier: DLC, CRC-8 SAE J1850 over data ID + 7 payload bytes, the DBC range of every data
// signal, and the alive counter's continuity (hil/e2e.hpp). Goal (issue 15): <= 20 ns.
void BM_HilPlausibilitySensorFrame(benchmark::State& state) {
  BenchLayout L;
  std::vector<can::Frame> frames;
  for (std::uint16_t c = 0; c < 1024; ++c) frames.push_back(L.pack_sensors({static_cast<std::uint16_t>(17000 + c), 0, c}));
  SeqTracker t;
  std::size_t i = 0;
  for (auto _ : state) {
    const can::Frame& f = frames[i++ & 1023];
    SensorMsg m;
    bool ok = !L.check_sensors(f, m).has_value();
    ok = ok && t.on_counter(m.counter);
    benchmark::DoNotOptimize(ok);
  }
  if (t.accepted + t.drops.total() != static_cast<std::uint64_t>(state.iterations())) state.SkipWithError("frames not counted");
  state.SetLabel("DLC + CRC-8 + 2 ranges + counter of one BenchSensors frame (and its decoding)");
}
BENCHMARK(BM_HilPlausibilitySensorFrame);

void BM_HilPlausibilityCommandFrame(benchmark::State& state) {
  BenchLayout L;
  std::vector<can::Frame> frames;
  for (std::uint16_t c = 0; c < 1024; ++c) frames.push_back(L.pack_command({800.0 + c, 0, 0, c}));
  SeqTracker t;
  t.bits = 8;
  std::size_t i = 0;
  for (auto _ : state) {
    const can::Frame& f = frames[i++ & 1023];
    CommandMsg m;
    bool ok = !L.check_command(f, m).has_value();
    ok = ok && t.on_counter(m.counter);
    benchmark::DoNotOptimize(ok);
  }
  state.SetLabel("DLC + CRC-8 + 3 ranges + counter of one BenchCommand frame (and its decoding to mA)");
}
BENCHMARK(BM_HilPlausibilityCommandFrame);

void BM_Crc8SaeJ1850NineBytes(benchmark::State& state) {
  std::array<std::uint8_t, 9> b{'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  for (auto _ : state) {
    benchmark::DoNotOptimize(b);
    benchmark::DoNotOptimize(Crc8SaeJ1850::compute(b));
  }
  state.SetLabel("table-driven CRC-8 SAE J1850 of 9 bytes (the E2E CRC's length)");
}
BENCHMARK(BM_Crc8SaeJ1850NineBytes);

// The same step with every cache level flushed before it (a 32 MiB buffer rewritten between
// steps, untimed): the worst case of a task woken after 5 ms of other work on the core.
void BM_HilMasterStepColdCache(benchmark::State& state) {
  BenchLayout L;
  ScriptedBus bus;
  MasterNode master = connected_master(L, bus, 0.005);
  std::vector<unsigned char> junk(32u << 20);
  std::uint16_t c = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < junk.size(); i += 64) junk[i] = static_cast<unsigned char>(i + c);
    benchmark::ClobberMemory();
    bus.next = L.pack_sensors({static_cast<std::uint16_t>(17000 + (c & 255)), 0, c});
    bus.pending = true;
    ++c;
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(master.step(bus, 0.0));
    const auto t1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  state.SetLabel("master step, caches flushed before each step");
}
BENCHMARK(BM_HilMasterStepColdCache)->UseManualTime()->Iterations(2000);

void BM_HilSlaveStep(benchmark::State& state) {
  BenchLayout L;
  SlaveConfig sc;
  sc.dto_reply = {dto()};
  sc.log_capacity = 1 << 16;
  SlaveNode slave(L, sc);
  ScriptedBus bus;
  std::uint16_t c = 0;
  for (auto _ : state) {
    bus.next = L.pack_command({800.0 + (c & 255), 0, 0, c});
    bus.pending = true;
    ++c;
    slave.step(bus, 0.0);
  }
  state.SetLabel("slave step without bus I/O: drain, plausibility check, decode, plant (noise, sensor code), encode + CRC, log");
}
BENCHMARK(BM_HilSlaveStep);

// The UDP multicast bus (python-can wire format) inside a private network namespace:
// one frame sent by one endpoint and received by another, and a receive on an empty queue.
bool in_private_netns() {
  static const bool ok = enter_private_netns().ok;
  return ok;
}

void BM_UdpSendReceive(benchmark::State& state) {
  if (!in_private_netns()) {
    state.SkipWithError("no private network namespace (needs root or user namespaces)");
    return;
  }
  auto a = can::open_bus("udp:239.74.163.2:43113");
  auto b = can::open_bus("udp:239.74.163.2:43113");
  BenchLayout L;
  const can::Frame f = L.pack_sensors({17000, 0, 1});
  for (auto _ : state) {
    a->send(f);
    std::optional<can::Frame> g;
    while (!(g = b->receive(std::chrono::nanoseconds(0)))) {
    }
    benchmark::DoNotOptimize(g);
  }
  state.SetLabel("send + receive of one frame between two endpoints");
}
BENCHMARK(BM_UdpSendReceive);

void BM_UdpSend(benchmark::State& state) {
  if (!in_private_netns()) {
    state.SkipWithError("no private network namespace");
    return;
  }
  auto a = can::open_bus("udp:239.74.163.2:43113");
  auto b = can::open_bus("udp:239.74.163.2:43113");
  BenchLayout L;
  const can::Frame f = L.pack_sensors({17000, 0, 1});
  std::size_t n = 0;
  for (auto _ : state) {
    a->send(f);
    if (++n % 64 == 0) {
      state.PauseTiming();
      while (b->receive(std::chrono::nanoseconds(0))) {
      }
      while (a->receive(std::chrono::nanoseconds(0))) {
      }
      state.ResumeTiming();
    }
  }
  state.SetLabel("send only (multicast delivered to the other endpoint)");
}
BENCHMARK(BM_UdpSend);

void BM_UdpReceiveEmpty(benchmark::State& state) {
  if (!in_private_netns()) {
    state.SkipWithError("no private network namespace");
    return;
  }
  auto b = can::open_bus("udp:239.74.163.2:43113");
  for (auto _ : state) benchmark::DoNotOptimize(b->receive(std::chrono::nanoseconds(0)));
  state.SetLabel("receive(0) with nothing queued (the end of every drain)");
}
BENCHMARK(BM_UdpReceiveEmpty);

}  // namespace
