#pragma once
// The E1 plant of the thesis (eq. 34) that the estimator benchmarks drive with v = 600 sin(0.005 k):
// deadzone [-300, 200], first-order lag per side, deadband half-widths 30 (right) and 50 (left),
// dt = 0.005 s. bench/python_bench.py builds the same plant through lash.Plant.
#include <utility>
#include <vector>

#include "lash/plant/plant.hpp"

namespace lash::bench {

inline Plant e1_plant() {
  std::vector<Block> b;
  b.emplace_back(Deadzone({-300.0, 200.0}));
  b.emplace_back(FirstOrder({{-0.96, 0.1}, {-0.94, 0.15}}));
  b.emplace_back(Deadband({30.0, 50.0}));
  return Plant(std::move(b), 0.005);
}

}  // namespace lash::bench
