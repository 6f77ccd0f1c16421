#pragma once
/// @file plant.hpp
/// A plant is an ordered chain of blocks (docs/method.md §A1). Timing: only the linear
/// part delays; deadzone, deadband, saturation act on the same sample; the
/// side of every piecewise block is chosen by the sign of the plant input
/// v(k−1); every state starts at 0; t_k = k·T.
#include <cstddef>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "lash/blocks.hpp"

namespace lash {

using Block = std::variant<Deadzone, Deadband, FirstOrder, MovingAverage, BackwardDifference, Delay, Saturation>;

/// Short name of a block's kind as used in plant files ("deadzone", "linear", …).
const char* block_kind(const Block& b) noexcept;

class Plant {
 public:
  /// Not real-time safe. Throws std::invalid_argument unless dt_s > 0.
  Plant(std::vector<Block> blocks, double dt_s);

  /// Advances one sample: plant input v(k) → output y(k). noexcept, no allocation.
  double step(double v) noexcept {
    const Side side = side_of(v_prev_);
    double x = v;
    std::size_t i = 0;
    for (auto& b : blocks_) {
      x = std::visit([&](auto& blk) noexcept { return apply(blk, x, side); }, b);
      signals_[i++] = x;
    }
    v_prev_ = v;
    return x;
  }

  /// Output of each block at the last step (same order as blocks()).
  std::span<const double> signals() const noexcept { return signals_; }
  const std::vector<Block>& blocks() const noexcept { return blocks_; }
  double dt_s() const noexcept { return dt_s_; }
  /// Returns every state to 0 (the state at k = 0).
  void reset() noexcept;

 private:
  static double apply(Deadband& b, double x, Side s) noexcept { return b.step(x, s); }
  static double apply(FirstOrder& b, double x, Side s) noexcept { return b.step(x, s); }
  template <class B>
  static double apply(B& b, double x, Side) noexcept { return b.step(x); }

  std::vector<Block> blocks_;
  std::vector<double> signals_;
  double dt_s_;
  double v_prev_ = 0.0;
};

}  // namespace lash
