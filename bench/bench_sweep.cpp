// The whole E3 campaign (147 runs × 30 s at 1 kHz, virtual-rig simulation and estimation included)
// on 2 worker threads — the budget is ≤ 2 s wall on the 2-core machine. Reports runs/s.
#include <benchmark/benchmark.h>

#include <string>

#include "lash/experiments/campaign.hpp"
#include "lash/experiments/sweep.hpp"

namespace {

void campaign(benchmark::State& state, const char* file) {
  const lash::sweep::Campaign c = lash::sweep::load_campaign(std::string(LASH_BENCH_SOURCE_DIR) + "/config/campaigns/" + file);
  const unsigned jobs = static_cast<unsigned>(state.range(0));
  std::size_t runs = 0;
  for (auto _ : state) {
    auto r = lash::sweep::run_campaign(c, jobs);
    benchmark::DoNotOptimize(r.data());
    runs += r.size();
  }
  state.counters["runs/s"] = benchmark::Counter(static_cast<double>(runs), benchmark::Counter::kIsRate);
  state.counters["samples/s"] =
      benchmark::Counter(static_cast<double>(runs) * c.duration_s / c.dt_s, benchmark::Counter::kIsRate);
}

void BM_SweepE3Thesis(benchmark::State& s) { campaign(s, "e3_motor_cart.toml"); }
void BM_SweepE3Lash(benchmark::State& s) { campaign(s, "e3_motor_cart_lash.toml"); }

}  // namespace

BENCHMARK(BM_SweepE3Thesis)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_SweepE3Lash)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
