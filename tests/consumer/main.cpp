// Steps the eq-34 plant through the installed library; prints y after 400 samples.
#include <cmath>
#include <cstdio>

#include "lash/plant/plant.hpp"

int main() {
  using namespace lash;
  std::vector<Block> b;
  b.emplace_back(Deadzone({-300.0, 200.0}));
  b.emplace_back(FirstOrder({{-0.96, 0.1}, {-0.94, 0.15}}));
  b.emplace_back(Deadband({30.0, 50.0}));
  Plant p(std::move(b), 0.005);
  double y = 0;
  for (int k = 0; k < 400; ++k) y = p.step(600.0 * std::sin(0.005 * k));
  std::printf("%.17g\n", y);
  return std::isfinite(y) && y > 0 ? 0 : 1;
}
