#pragma once
/// @file plant.hpp
/// A plant is an ordered chain of blocks (docs/method.md §A1). Timing: only the linear
/// part delays; deadzone, deadband, saturation act on the same sample; the
/// side of every piecewise block is chosen by the sign of the plant input
/// v(k−1); every state starts at 0; t_k = k·T.
#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "lash/blocks.hpp"

namespace lash {

using Block = std::variant<Deadzone, Deadband, FirstOrder, MovingAverage, BackwardDifference, Delay, Saturation>;
static_assert(std::variant_size_v<Block> == 7, "Plant::step switches over the seven kinds in this order");

/// Short name of a block's kind as used in plant files ("deadzone", "linear", …).
const char* block_kind(const Block& b) noexcept;

class Plant {
 public:
  /// Not real-time safe. Throws std::invalid_argument unless dt_s > 0.
  Plant(std::vector<Block> blocks, double dt_s);

  /// Advances one sample: plant input v(k) → output y(k). noexcept, no allocation.
  /// A chain of up to three deadzone / deadband / first-order blocks (every plant of the thesis)
  /// runs a step compiled for its kinds (no dispatch per block); any other chain switches on each
  /// block's kind. bench/plant_ratio.cpp holds it against hand-written eq-34 steps.
  double step(double v) noexcept { return fixed_ ? (this->*fixed_)(v) : step_any(v); }

  /// Output of each block at the last step (same order as blocks()).
  std::span<const double> signals() const noexcept { return signals_; }
  const std::vector<Block>& blocks() const noexcept { return blocks_; }
  double dt_s() const noexcept { return dt_s_; }
  /// Returns every state to 0 (the state at k = 0).
  void reset() noexcept;

 private:
  double step_any(double v) noexcept {
    const Side side = side_of(v_prev_);
    double x = v;
    double* out = signals_.data();
    for (Block& b : blocks_) {
      switch (b.index()) {
        case 0: x = std::get_if<0>(&b)->step(x); break;
        case 1: x = std::get_if<1>(&b)->step(x, side); break;
        case 2: x = std::get_if<2>(&b)->step(x, side); break;
        case 3: x = std::get_if<3>(&b)->step(x); break;
        case 4: x = std::get_if<4>(&b)->step(x); break;
        case 5: x = std::get_if<5>(&b)->step(x); break;
        default: x = std::get_if<6>(&b)->step(x); break;
      }
      *out++ = x;
    }
    v_prev_ = v;
    return x;
  }
  /// One block of kind I (0 deadzone, 1 deadband, 2 first order) without a dispatch.
  template <std::size_t I>
  static double step_kind(Block& b, double x, Side side) noexcept {
    auto* blk = std::get_if<I>(&b);
    // fixed_step_for chose this step for exactly these kinds, and a block never changes its kind
    // (blocks() is const): no check of the variant's index on the sample path
    if (!blk) __builtin_unreachable();
    if constexpr (I == 0) return blk->step(x);
    else return blk->step(x, side);
  }
  /// The step of a chain whose kinds are I... (in order), each block's step inlined.
  template <std::size_t... I>
  double step_fixed(double v) noexcept {
    const Side side = side_of(v_prev_);
    double x = v;
    Block* b = blocks_.data();
    double* out = signals_.data();
    ((x = step_kind<I>(*b++, x, side), *out++ = x), ...);
    v_prev_ = v;
    return x;
  }
  using StepFn = double (Plant::*)(double) noexcept;
  static StepFn fixed_step_for(const std::vector<Block>& blocks) noexcept;

  StepFn fixed_ = nullptr;
  std::vector<Block> blocks_;
  std::vector<double> signals_;
  double dt_s_;
  double v_prev_ = 0.0;
};

}  // namespace lash
