#include "lash/plant/plant.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

namespace lash {

const char* block_kind(const Block& b) noexcept {
  struct V {
    const char* operator()(const Deadzone&) const noexcept { return "deadzone"; }
    const char* operator()(const Deadband&) const noexcept { return "deadband"; }
    const char* operator()(const FirstOrder&) const noexcept { return "linear"; }
    const char* operator()(const MovingAverage&) const noexcept { return "moving_average"; }
    const char* operator()(const BackwardDifference&) const noexcept { return "difference"; }
    const char* operator()(const Delay&) const noexcept { return "delay"; }
    const char* operator()(const Saturation&) const noexcept { return "saturation"; }
  };
  return std::visit(V{}, b);
}

namespace {
/// Index of a chain of kinds 0..2 (deadzone, deadband, first order) of length 1..3 in the table
/// below, or −1.
int chain_code(const std::vector<Block>& blocks) noexcept {
  if (blocks.empty() || blocks.size() > 3) return -1;
  int code = 0;
  for (const auto& b : blocks) {
    if (b.index() > 2) return -1;
    code = code * 3 + static_cast<int>(b.index());
  }
  return code;
}
}  // namespace

Plant::StepFn Plant::fixed_step_for(const std::vector<Block>& blocks) noexcept {
  const int code = chain_code(blocks);
  if (code < 0) return nullptr;
  // code = Σ kind·3^(len−1−i) for each length; the three lengths' tables
  static constexpr std::array<StepFn, 3> one{&Plant::step_fixed<0>, &Plant::step_fixed<1>, &Plant::step_fixed<2>};
  static constexpr std::array<StepFn, 9> two{
      &Plant::step_fixed<0, 0>, &Plant::step_fixed<0, 1>, &Plant::step_fixed<0, 2>,
      &Plant::step_fixed<1, 0>, &Plant::step_fixed<1, 1>, &Plant::step_fixed<1, 2>,
      &Plant::step_fixed<2, 0>, &Plant::step_fixed<2, 1>, &Plant::step_fixed<2, 2>};
  static constexpr std::array<StepFn, 27> three{
      &Plant::step_fixed<0, 0, 0>, &Plant::step_fixed<0, 0, 1>, &Plant::step_fixed<0, 0, 2>,
      &Plant::step_fixed<0, 1, 0>, &Plant::step_fixed<0, 1, 1>, &Plant::step_fixed<0, 1, 2>,
      &Plant::step_fixed<0, 2, 0>, &Plant::step_fixed<0, 2, 1>, &Plant::step_fixed<0, 2, 2>,
      &Plant::step_fixed<1, 0, 0>, &Plant::step_fixed<1, 0, 1>, &Plant::step_fixed<1, 0, 2>,
      &Plant::step_fixed<1, 1, 0>, &Plant::step_fixed<1, 1, 1>, &Plant::step_fixed<1, 1, 2>,
      &Plant::step_fixed<1, 2, 0>, &Plant::step_fixed<1, 2, 1>, &Plant::step_fixed<1, 2, 2>,
      &Plant::step_fixed<2, 0, 0>, &Plant::step_fixed<2, 0, 1>, &Plant::step_fixed<2, 0, 2>,
      &Plant::step_fixed<2, 1, 0>, &Plant::step_fixed<2, 1, 1>, &Plant::step_fixed<2, 1, 2>,
      &Plant::step_fixed<2, 2, 0>, &Plant::step_fixed<2, 2, 1>, &Plant::step_fixed<2, 2, 2>};
  const auto c = static_cast<std::size_t>(code);
  switch (blocks.size()) {
    case 1: return one[c];
    case 2: return two[c];
    default: return three[c];
  }
}

Plant::Plant(std::vector<Block> blocks, double dt_s) : blocks_(std::move(blocks)), dt_s_(dt_s) {
  if (!(std::isfinite(dt_s) && dt_s > 0)) throw std::invalid_argument("dt must be > 0");
  signals_.assign(blocks_.size(), 0.0);
  fixed_ = fixed_step_for(blocks_);
}

void Plant::reset() noexcept {
  for (auto& b : blocks_) std::visit([](auto& blk) noexcept { blk.reset(); }, b);
  for (auto& s : signals_) s = 0.0;
  v_prev_ = 0.0;
}

}  // namespace lash
