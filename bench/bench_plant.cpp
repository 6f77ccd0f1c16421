// Plant simulation throughput: the eq-34 plant (DZ -> G -> DB), one sample per step(), and a
// chunk of 4096 samples per run(); each against a hand-written floor (bench/plant_ratio.cpp).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <memory>
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

/// The floor: the same plant written by hand for this one chain (deadzone c_l = −300, c_r = 200;
/// first order a1/b1 = −0.96/0.1 right, −0.94/0.15 left; deadband d = 30/50; side from v(k−1)),
/// the blocks' equations inlined, nothing generic and no per-block outputs kept.
struct Eq34ByHand {
  double w = 0.0, u_prev = 0.0, out = 0.0, v_prev = 0.0;
  double step(double v) noexcept {
    const bool right = v_prev >= 0.0;
    const double x = v > 200.0 ? v - 200.0 : v < -300.0 ? v + 300.0 : 0.0;
    w = -(right ? -0.96 : -0.94) * w + (right ? 0.1 : 0.15) * u_prev;
    u_prev = x;
    const double d = right ? 30.0 : 50.0;
    if (w < out - d) out = w + d;
    else if (w > out + d) out = w - d;
    v_prev = v;
    return out;
  }
};

void BM_PlantEq34_Floor(benchmark::State& state) {
  Eq34ByHand plant;
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
BENCHMARK(BM_PlantEq34_Floor);

}  // namespace

namespace {
// The hand-written step with its state kept in memory between calls (an object that outlives
// the call, as any plant object's state does): the floor's own cost once the recurrence goes
// through a store and a load per step.
void BM_PlantEq34_FloorInMemory(benchmark::State& state) {
  auto plant = std::make_unique<Eq34ByHand>();
  benchmark::DoNotOptimize(plant.get());
  std::vector<double> v(4096);
  for (std::size_t k = 0; k < v.size(); ++k) v[k] = 600.0 * std::sin(0.005 * static_cast<double>(k) * 3.0);
  std::size_t i = 0;
  for (auto _ : state) {
    double y = plant->step(v[i]);
    benchmark::DoNotOptimize(y);
    i = (i + 1) & 4095;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PlantEq34_FloorInMemory);
}  // namespace

namespace {
// run(): a chunk of 4096 samples per iteration (as `lash simulate` runs its records), the plant's
// state in locals over the chunk. Items = samples, so 1/items_per_second is the time per sample.
constexpr std::size_t kChunk = 4096;

std::vector<double> sine_chunk() {
  std::vector<double> v(kChunk);
  for (std::size_t k = 0; k < v.size(); ++k) v[k] = 600.0 * std::sin(0.005 * static_cast<double>(k) * 3.0);
  return v;
}

void BM_PlantEq34Run(benchmark::State& state) {
  auto plant = eq34();
  const std::vector<double> v = sine_chunk();
  std::vector<double> y(v.size());
  for (auto _ : state) {
    plant.run(v, y);
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kChunk));
}
BENCHMARK(BM_PlantEq34Run);

/// The floor of run(): the hand-written eq-34 step over the same chunk loop, its state copied into
/// a local for the chunk and written back at the end (the object lives in memory between chunks,
/// as a Plant does).
struct Eq34ByHandRun {
  Eq34ByHand st;
  void run(const double* v, double* y, std::size_t n) noexcept {
    Eq34ByHand s = st;
    for (std::size_t k = 0; k < n; ++k) y[k] = s.step(v[k]);
    st = s;
  }
};

void BM_PlantEq34Run_Floor(benchmark::State& state) {
  auto plant = std::make_unique<Eq34ByHandRun>();
  benchmark::DoNotOptimize(plant.get());
  const std::vector<double> v = sine_chunk();
  std::vector<double> y(v.size());
  for (auto _ : state) {
    plant->run(v.data(), y.data(), v.size());
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kChunk));
}
BENCHMARK(BM_PlantEq34Run_Floor);
}  // namespace
