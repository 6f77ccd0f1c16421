#pragma once
/// @file simulate.hpp
/// What a closed-loop simulation of the bench returns, and an in-process link between two
/// nodes. The simulation itself (`lash hil simulate`, `lash closed-loop` on a valve scenario) is
/// hil::simulate_bench(layout, master, slave, schedule) of schedule.hpp: with
/// ideal_schedule(N) the master and the slave exchange their frames in the emulation's order —
/// master sends CRO; slave answers with the recorded DTO; then each period slave.step() and
/// master.step() — so the quantisation (current 0.1 mA, sensor uint16 code), the one-step bus
/// delay and the step order are those of the emulation and the traces compare sample for sample.
#include <cstddef>
#include <deque>
#include <memory>

#include "lash/can/bus.hpp"
#include "lash/hil/nodes.hpp"

namespace lash::hil {

/// Two in-process bus endpoints wired to each other: what one sends, the other receives,
/// in order. Deterministic; no threads. Not real-time safe (std::deque), simulation only.
class MemLink {
 public:
  MemLink();
  can::Bus& a() noexcept { return *a_; }
  can::Bus& b() noexcept { return *b_; }

 private:
  std::unique_ptr<can::Bus> a_, b_;
};

struct SimulationResult {
  std::vector<MasterStepLog> master;  ///< every master step (connecting step included)
  std::vector<SlaveStepLog> slave;
  std::vector<MasterEvent> events;
  CompensationState compensation;     ///< the master's scenario compensator at the end (on = false without one)
};

}  // namespace lash::hil
