// The emulated master past its handshake on a scripted bus, shared by lash_bench (bench_hil.cpp)
// and lash_console_tet (console_tet.cpp): what both time is the master's own step.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "lash/can/bus.hpp"
#include "lash/hil/nodes.hpp"

namespace lash::bench {

/// A bus that hands out one prepared frame per receive cycle and keeps only the last frame
/// sent: no system calls, no allocation — isolates a node's own work.
class ScriptedBus final : public can::Bus {
 public:
  can::Frame next;
  bool pending = false;
  can::Frame last_sent;
  bool send(const can::Frame& f) noexcept override {
    last_sent = f;
    return true;
  }
  std::optional<can::Frame> receive(std::chrono::nanoseconds) noexcept override {
    if (!pending) return std::nullopt;
    pending = false;
    return next;
  }
  void set_filters(std::vector<can::Filter>) override {}
  can::BusStats stats() const noexcept override { return {}; }
  std::string address() const override { return "scripted"; }
};

/// The positive CCP CONNECT reply (DTO) of the bench layout.
inline can::Frame dto() {
  can::Frame f;
  f.id = 0x7E1;
  f.len = 8;
  f.data[0] = 0xFF;
  return f;
}

/// The bench master: PID (1.2, 12, 0.004) on a 500 ± 1000 kPa square reference at `dt_s`.
inline hil::MasterConfig master_cfg(double dt_s) {
  hil::MasterConfig m;
  m.controller.pid.dt_s = dt_s;
  m.controller.pid.gains = {1.2, 12.0, 0.004, 0.0};
  m.reference.kind = Waveform::square;
  m.reference.amplitude = 500;
  m.reference.offset = 1000;
  m.reference.frequency_rad_s = 3.0;
  m.log_capacity = 1 << 16;
  return m;
}

/// A master past its CCP handshake on `bus`.
inline hil::MasterNode connected_master(const hil::BenchLayout& L, ScriptedBus& bus, double dt_s) {
  hil::MasterNode master(L, master_cfg(dt_s));
  master.step(bus, 0.0);  // CRO
  bus.next = dto();
  bus.pending = true;
  master.step(bus, 0.0);  // connected
  return master;
}

}  // namespace lash::bench
