#include "lash/can/controller_bus.hpp"

#include <stdexcept>

#include "lash/rt/periodic.hpp"

namespace lash::can {

ControllerBus::ControllerBus(Bus& wire, ControllerConfig cfg) : wire_(wire), cfg_(cfg) {
  if (cfg_.rx_fifo == 0 || cfg_.tx_fifo == 0) throw std::invalid_argument("can controller: FIFO depth must be >= 1");
  if (cfg_.max_reads == 0) throw std::invalid_argument("can controller: max_reads must be >= 1");
  if (cfg_.budget_ns < 0) throw std::invalid_argument("can controller: the time budget must be >= 0");
  rx_.resize(cfg_.rx_fifo);
  tx_.resize(cfg_.tx_fifo);
  batch_.resize(cfg_.rx_fifo);
}

bool ControllerBus::send(const Frame& frame) noexcept {
  if (!frame.valid()) return false;
  if (tx_count_ == tx_.size()) {
    ++cs_.tx_overflows;
    return false;
  }
  tx_[tx_count_++] = frame;
  return true;
}

std::optional<Frame> ControllerBus::receive(std::chrono::nanoseconds timeout) noexcept {
  if (rx_count_ == 0) {
    if (timeout.count() > 0) return wire_.receive(timeout);
    return std::nullopt;
  }
  const Frame f = rx_[rx_head_];
  rx_head_ = (rx_head_ + 1) % rx_.size();
  --rx_count_;
  return f;
}

std::size_t ControllerBus::pull() noexcept {
  // Drain the wire in batches of up to one FIFO's worth until it is empty, the read budget is
  // spent or the time budget is up; what is left stays queued on the wire for the next pull().
  const std::int64_t t0 = cfg_.budget_ns > 0 ? rt::monotonic_ns() : 0;
  std::size_t moved = 0, reads = 0;
  for (;;) {
    const BatchResult r = wire_.receive_batch(batch_, cfg_.max_reads - reads);
    reads += r.reads;
    for (std::size_t i = 0; i < r.stored; ++i) {
      if (rx_count_ == rx_.size()) {  // full: drop the oldest for the newest
        rx_head_ = (rx_head_ + 1) % rx_.size();
        --rx_count_;
        ++cs_.rx_overflows;
      }
      rx_[(rx_head_ + rx_count_) % rx_.size()] = batch_[i];
      ++rx_count_;
    }
    moved += r.stored;
    if (r.drained) break;
    if (reads >= cfg_.max_reads || (cfg_.budget_ns > 0 && rt::monotonic_ns() - t0 >= cfg_.budget_ns)) {
      ++cs_.pulls_cut;
      break;
    }
  }
  cs_.rx_reads += reads;
  return moved;
}

std::size_t ControllerBus::flush() noexcept {
  std::size_t sent = 0;
  for (std::size_t i = 0; i < tx_count_; ++i) {
    if (wire_.send(tx_[i]))
      ++sent;
    else
      ++cs_.tx_failures;
  }
  tx_count_ = 0;
  return sent;
}

}  // namespace lash::can
