#include "lash/can/controller_bus.hpp"

#include <stdexcept>

namespace lash::can {

ControllerBus::ControllerBus(Bus& wire, ControllerConfig cfg) : wire_(wire), cfg_(cfg) {
  if (cfg_.rx_fifo == 0 || cfg_.tx_fifo == 0) throw std::invalid_argument("can controller: FIFO depth must be >= 1");
  if (cfg_.max_reads == 0) throw std::invalid_argument("can controller: max_reads must be >= 1");
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
  // One bounded read of the wire: at most max_reads datagrams/frames and one FIFO's worth of
  // accepted frames. What is left stays queued on the wire for the next pull().
  const std::size_t n = wire_.receive_batch(batch_, cfg_.max_reads);
  for (std::size_t i = 0; i < n; ++i) {
    if (rx_count_ == rx_.size()) {  // full: drop the oldest for the newest
      rx_head_ = (rx_head_ + 1) % rx_.size();
      --rx_count_;
      ++cs_.rx_overflows;
    }
    rx_[(rx_head_ + rx_count_) % rx_.size()] = batch_[i];
    ++rx_count_;
  }
  return n;
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
