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
#include <type_traits>
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
  /// block's kind. bench/plant_ratio.cpp holds it, and run(), against hand-written eq-34 steps.
  double step(double v) noexcept { return compiled_.step ? (this->*compiled_.step)(v) : step_any(v); }

  /// Steps the plant over a chunk of samples: y[k] = step(v[k]) for k = 0 … v.size() − 1, the
  /// same bits as those calls (the same operations in the same order), and the plant is left as
  /// they leave it: its state, and signals() holding the blocks' outputs of the last sample (of
  /// no sample, nothing changes). A chain that step() runs compiled for its kinds runs here with
  /// its blocks copied into locals for the whole chunk (the compiler keeps the state in registers
  /// instead of a store and a load per sample) and written back once at the end; any other chain
  /// calls step() per sample. Chunks may follow each other: run(a) then run(b) = run(a then b).
  /// y may be v (in place). Throws std::invalid_argument (before any step) unless
  /// y.size() == v.size(). No allocation.
  void run(std::span<const double> v, std::span<double> y);
  /// run(v, y) that also keeps every block's output of every sample: x[k·blocks().size() + i] is
  /// signals()[i] after step(v[k]). Throws std::invalid_argument unless
  /// x.size() == v.size()·blocks().size().
  void run(std::span<const double> v, std::span<double> y, std::span<double> x);

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
  /// Block b as its kind I: compiled_for chose the fixed step and run for exactly these kinds, and
  /// a block never changes its kind (blocks() is const): no check of the variant's index.
  template <std::size_t I>
  static std::variant_alternative_t<I, Block>& as_kind(Block& b) noexcept {
    auto* blk = std::get_if<I>(&b);
    if (!blk) __builtin_unreachable();
    return *blk;
  }
  /// One step of a deadzone, deadband or first-order block (the kinds 0, 1, 2).
  template <class B>
  static double step_block(B& blk, double x, Side side) noexcept {
    if constexpr (std::is_same_v<B, Deadzone>) return blk.step(x);
    else return blk.step(x, side);
  }
  /// One block of kind I (0 deadzone, 1 deadband, 2 first order) without a dispatch.
  template <std::size_t I>
  static double step_kind(Block& b, double x, Side side) noexcept {
    return step_block(as_kind<I>(b), x, side);
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
  /// run() of a chain whose kinds are I... over n samples, the blocks copied into locals; with
  /// Keep, every block's output of every sample into x (defined in plant.cpp, its only user).
  template <bool Keep, std::size_t... I>
  void run_fixed(const double* v, double* y, double* x, std::size_t n) noexcept;
  /// run() of any chain: step() per sample (x may be null).
  void run_any(const double* v, double* y, double* x, std::size_t n) noexcept;

  using StepFn = double (Plant::*)(double) noexcept;
  using RunFn = void (Plant::*)(const double*, double*, double*, std::size_t) noexcept;
  struct Compiled {
    StepFn step = nullptr;
    RunFn run = nullptr;       ///< without the blocks' outputs
    RunFn run_keep = nullptr;  ///< with them
  };
  /// The step and runs compiled for the chain's kinds, or nulls (the chain takes the generic path).
  static Compiled compiled_for(const std::vector<Block>& blocks) noexcept;

  Compiled compiled_;  ///< null members: a chain compiled_for has no step for
  std::vector<Block> blocks_;
  std::vector<double> signals_;
  double dt_s_;
  double v_prev_ = 0.0;
};

}  // namespace lash
