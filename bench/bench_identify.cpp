// Estimator throughput: one (v, y) sample per step() (docs/method.md §A4; goal: deadzone-deadband >= 50 M samples/s).
// Data: the E1 plant (thesis eq. 34), v = 600 sin(t), precomputed so only the estimator is timed.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "e1_plant.hpp"

#include "lash/identify/auto.hpp"
#include "lash/identify/auto_gate.hpp"
#include "lash/identify/estimators.hpp"
#include "lash/identify/rls.hpp"
#include "lash/plant/plant.hpp"

namespace {

struct Data {
  std::vector<double> v, y;
};

const Data& e1_data() {
  static const Data d = [] {
    lash::Plant p = lash::bench::e1_plant();
    Data out;
    const std::size_t n = 1 << 16;  // 327 s: a whole number of input periods is not needed
    for (std::size_t k = 0; k < n; ++k) {
      const double v = 600.0 * std::sin(0.005 * static_cast<double>(k));
      out.v.push_back(v);
      out.y.push_back(p.step(v));
    }
    return out;
  }();
  return d;
}

lash::EstimatorConfig thesis(lash::ModelKind m) {
  lash::EstimatorConfig c = lash::EstimatorConfig::thesis(m, 0.005);
  c.guess_left = -350;
  c.guess_right = 350;
  return c;
}

template <class E>
void run(benchmark::State& state, const lash::EstimatorConfig& cfg) {
  const Data& d = e1_data();
  const std::size_t mask = d.v.size() - 1;
  E est(cfg);
  std::size_t i = 0;
  for (auto _ : state) {
    double yhat = est.step(d.v[i], d.y[i]);
    benchmark::DoNotOptimize(yhat);
    i = (i + 1) & mask;
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_DeadzoneDeadband(benchmark::State& s) {
  run<lash::DeadzoneDeadbandEstimator>(s, thesis(lash::ModelKind::deadzone_deadband));
}
BENCHMARK(BM_DeadzoneDeadband);

void BM_DeadzoneDeadbandE2Settings(benchmark::State& s) {
  // E2's method (config/scenarios/e2.toml) = lash's static default for the model
  auto c = lash::preset_config(lash::ModelKind::deadzone_deadband, lash::Preset::lash, 0.005);
  c.guess_left = -350;
  c.guess_right = 350;
  run<lash::DeadzoneDeadbandEstimator>(s, c);
}
BENCHMARK(BM_DeadzoneDeadbandE2Settings);

// What `lash estimate rec.csv --model deadzone-deadband` runs per sample: lash's settings tuned to
// the record (lash::tune_to_data), the guesses searched (lash::search_guesses, done once before),
// and the outlier gate in front of the estimator.
void BM_DeadzoneDeadbandDefault(benchmark::State& state) {
  const Data& d = e1_data();
  auto c = lash::preset_config(lash::ModelKind::deadzone_deadband, lash::Preset::lash, 0.005);
  lash::tune_to_data(c, lash::analyse_record(d.v, d.y, 0.005));
  const auto g = lash::search_guesses(c, d.v, d.y);
  c.guess_right = g[0];
  c.guess_left = g[1];
  lash::DeadzoneDeadbandEstimator est(c);
  lash::OutlierGate gate;
  const std::size_t mask = d.v.size() - 1;
  std::size_t i = 0;
  for (auto _ : state) {
    double yhat = est.step(d.v[i], gate.step(d.y[i]));
    benchmark::DoNotOptimize(yhat);
    i = (i + 1) & mask;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DeadzoneDeadbandDefault);

void BM_InputDeadzone(benchmark::State& s) {
  run<lash::InputDeadzoneEstimator>(s, thesis(lash::ModelKind::input_deadzone));
}
BENCHMARK(BM_InputDeadzone);

void BM_Linear(benchmark::State& s) { run<lash::LinearEstimator>(s, thesis(lash::ModelKind::linear)); }
BENCHMARK(BM_Linear);

void BM_Rls3Update(benchmark::State& state) {
  lash::RlsConfig<3> c;
  c.lambda = 0.99;
  lash::Rls<3> r(c);
  const Data& d = e1_data();
  const std::size_t mask = d.v.size() - 1;
  std::size_t i = 1;
  for (auto _ : state) {
    double yhat = r.update({-d.y[i - 1], d.v[i - 1], 1.0}, d.y[i]);
    benchmark::DoNotOptimize(yhat);
    i = ((i + 1) & mask) | 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Rls3Update);

}  // namespace
