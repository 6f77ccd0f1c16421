#include "lash/plant/plant.hpp"

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

Plant::Plant(std::vector<Block> blocks, double dt_s) : blocks_(std::move(blocks)), dt_s_(dt_s) {
  if (!(std::isfinite(dt_s) && dt_s > 0)) throw std::invalid_argument("dt must be > 0");
  signals_.assign(blocks_.size(), 0.0);
}

void Plant::reset() noexcept {
  for (auto& b : blocks_) std::visit([](auto& blk) noexcept { blk.reset(); }, b);
  for (auto& s : signals_) s = 0.0;
  v_prev_ = 0.0;
}

}  // namespace lash
