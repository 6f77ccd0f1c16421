// 02 — build a plant from blocks and simulate it sample by sample.
//
// An input deadzone (edges -300 and 200), a first-order linear part whose pole and gain
// depend on the side of its input (a1, b1 per side), and an output deadband (half-widths
// 50 left, 30 right): the thesis's eq-34 arrangement. The plant is stepped by hand with a
// 600-unit sine at 1 rad/s, T = 5 ms; every 200th sample is printed as CSV.
//
//   build/bin/examples/02_simulate > trace.csv
#include <cmath>
#include <cstdio>
#include <vector>

#include "lash/plant/plant.hpp"

int main() {
  using namespace lash;
  const double dt_s = 0.005;  // sample period T [s]
  std::vector<Block> blocks;
  blocks.emplace_back(Deadzone({.left = -300.0, .right = 200.0}));     // c_l, c_r [input unit]
  blocks.emplace_back(FirstOrder({.right = {-0.96, 0.1}, .left = {-0.94, 0.15}}));  // {a1, b1} per side
  blocks.emplace_back(Deadband(PerSide<double>{.right = 30.0, .left = 50.0}));  // d_r, d_l [output unit]
  Plant plant(std::move(blocks), dt_s);

  std::printf("t_s,v,y\n");
  for (int k = 0; k <= 4000; ++k) {
    const double t = k * dt_s;
    const double v = 600.0 * std::sin(1.0 * t);  // [input unit]
    const double y = plant.step(v);              // step() is noexcept and allocation-free
    if (k % 200 == 0) std::printf("%.3f,%.6g,%.6g\n", t, v, y);
  }
  return 0;
}
