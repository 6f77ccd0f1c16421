#pragma once
/// @file controller_bus.hpp
/// An emulated CAN controller between a node's task and the bus (the "wire").
///
/// On an ECU the control task never touches the bus: the CAN controller's acceptance
/// filters put matching frames into an RX FIFO as they arrive, and the task's writes
/// go into TX mailboxes that the controller transmits on its own. ControllerBus gives
/// an emulated node the same split:
///   - pull()  moves the frames the wire has queued into the RX FIFO (the controller's
///             reception: it drains the wire in batches, and stops after `max_reads` wire
///             reads or `budget_ns` of time, so a babbling node cannot stretch it), before
///             the task runs;
///   - the task calls receive(0) / send() — both O(1) on preallocated FIFOs, no system call;
///   - flush() transmits the TX FIFO on the wire, after the task.
/// The periodic loop times pull()+flush() as I/O and the task alone as TET (docs/hil.md).
///
/// FIFO overflow: a full RX FIFO drops its oldest frame for the new one (the task wants the
/// newest data; the loss is counted and the sequence counters of docs/method.md §B3 see it); a full TX
/// FIFO refuses the frame (send() returns false). Both are counted.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lash/can/bus.hpp"

namespace lash::can {

struct ControllerConfig {
  std::size_t rx_fifo = 64;      ///< RX FIFO depth [frames]
  std::size_t tx_fifo = 16;      ///< TX FIFO depth [frames]
  std::size_t max_reads = 8192;  ///< wire reads per pull() at most (filtered frames included)
  std::int64_t budget_ns = 0;    ///< pull() stops reading once it has taken this long [ns]; 0 = no time limit
};

struct ControllerStats {
  std::uint64_t rx_overflows = 0;   ///< frames lost to a full RX FIFO
  std::uint64_t tx_overflows = 0;   ///< send() refused: TX FIFO full
  std::uint64_t tx_failures = 0;    ///< frames the wire refused at flush()
  std::uint64_t rx_reads = 0;       ///< frames/datagrams read from the wire (filtered ones included)
  std::uint64_t pulls_cut = 0;      ///< pull() calls that stopped at their read or time budget
};

class ControllerBus final : public Bus {
 public:
  /// `wire` must outlive this object. Throws std::invalid_argument on a zero depth or budget.
  ControllerBus(Bus& wire, ControllerConfig cfg = {});

  /// Queues the frame in the TX FIFO; false when it is full. noexcept, no system call.
  bool send(const Frame& frame) noexcept override;
  /// Pops the oldest RX FIFO frame. When the FIFO is empty and timeout > 0 it waits on the
  /// wire directly (a handshake outside the real-time loop).
  std::optional<Frame> receive(std::chrono::nanoseconds timeout) noexcept override;
  void set_filters(std::vector<Filter> filters) override { wire_.set_filters(std::move(filters)); }
  /// The wire's counters (frames on the medium).
  BusStats stats() const noexcept override { return wire_.stats(); }
  std::string address() const override { return wire_.address(); }

  /// Reception: wire → RX FIFO. Returns the frames moved. noexcept, no allocation.
  std::size_t pull() noexcept;
  /// Transmission: TX FIFO → wire, in order. Returns the frames sent. noexcept.
  std::size_t flush() noexcept;

  std::size_t rx_pending() const noexcept { return rx_count_; }
  std::size_t tx_pending() const noexcept { return tx_count_; }
  const ControllerStats& controller_stats() const noexcept { return cs_; }

 private:
  Bus& wire_;
  ControllerConfig cfg_;
  std::vector<Frame> rx_, tx_, batch_;
  std::size_t rx_head_ = 0, rx_count_ = 0, tx_count_ = 0;
  ControllerStats cs_;
};

}  // namespace lash::can
