// Plant simulation throughput: the eq-34 plant (DZ -> G -> DB), one sample per step().
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "lash/plant/plant.hpp"

namespace {

lash::Plant eq34() {
  using namespace lash;
  std::vector<Block> b;
  b.emplace_back(Deadzone({-300.0, 200.0}));
  b.emplace_back(FirstOrder({{-0.96, 0.1}, {-0.94, 0.15}}));
  b.emplace_back(Deadband({30.0, 50.0}));
  return Plant(std::move(b), 0.005);
}

void BM_PlantEq34(benchmark::State& state) {
  auto plant = eq34();
  // A precomputed 600 sin(t) input so the benchmark measures the plant, not std::sin.
  std::vector<double> v(4096);
  for (std::size_t k = 0; k < v.size(); ++k) v[k] = 600.0 * std::sin(0.005 * static_cast<double>(k) * 3.0);
  std::size_t i = 0;
  for (auto _ : state) {
    double y = plant.step(v[i]);
    benchmark::DoNotOptimize(y);
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PlantEq34);

}  // namespace
