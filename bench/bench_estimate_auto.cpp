// Whole-record estimation on 10^6 samples held in arrays: the peer of Python's lash.estimate
// (bench/python_bench.py, docs/python.md). Per sample; the data are the arrays bench/python_bench.py
// builds: the E1 plant (thesis eq. 34) driven by v = 600 sin(0.005 k), t = k * 0.005 s, no noise.
//
//  BM_EstimateArrays      the library calls lash.estimate makes (lash::estimate_arrays): t checked,
//                         sampling analysed (gaps, median step), settings resolved, estimate_auto,
//                         NRMSE of the free run, the JSON report. Thesis preset, guesses given, outlier
//                         gate off, no intervals (python_bench.py's first figure).
//  BM_RunEstimator        only the estimator pass of it (run_estimator: step + yhat/ysim stored).
//  BM_EstimatorLoop       only est.step over the same 10^6 samples (BM_DeadzoneDeadband's loop, whose
//                         65536 samples stay in cache; here they stream from memory).
//  BM_AnalyseSampling     only the sampling analysis of t (sample_period + analyse_sampling).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "e1_plant.hpp"

#include "lash/identify/config_sources.hpp"
#include "lash/identify/estimate.hpp"
#include "lash/identify/estimators.hpp"
#include "lash/io/table.hpp"
#include "lash/plant/plant.hpp"
#include "lash/plant/simulate.hpp"

namespace {

constexpr std::size_t kSamples = 1000000;

struct Arrays {
  std::vector<double> t, v, y;
};

const Arrays& arrays() {
  static const Arrays a = [] {
    using namespace lash;
    Plant p = bench::e1_plant();
    std::vector<double> v(kSamples);
    for (std::size_t k = 0; k < kSamples; ++k) v[k] = 600.0 * std::sin(0.005 * static_cast<double>(k));
    SimulationTrace tr = simulate(p, v, 0.0, 1);
    return Arrays{std::move(tr.cols[0]), std::move(tr.cols[1]), std::move(tr.cols[2])};
  }();
  return a;
}

// python_bench.py's settings: lash.estimate(t, v, y, preset="thesis", outlier_gate=0, intervals=False,
// guess_left=-350, guess_right=350)
const toml::table& keys() {
  static const toml::table k{{"guess_left", -350.0}, {"guess_right", 350.0}};
  return k;
}

lash::SettingsSources sources() {
  lash::SettingsSources s;
  s.model = lash::ModelKind::deadzone_deadband;
  s.preset = lash::Preset::thesis;
  s.keys = &keys();
  return s;
}

void per_sample(benchmark::State& state) {
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kSamples));
  state.counters["ns_per_sample"] = benchmark::Counter(static_cast<double>(state.iterations() * kSamples),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_EstimateArrays(benchmark::State& state) {
  const Arrays& a = arrays();
  const lash::SettingsSources src = sources();
  lash::ArrayEstimateOptions o;
  o.outlier_gate = 0.0;
  o.intervals = false;
  for (auto _ : state) {
    lash::ArrayEstimate e = lash::estimate_arrays(src, a.t, a.v, a.y, o);
    benchmark::DoNotOptimize(e.json.data());
  }
  per_sample(state);
}
BENCHMARK(BM_EstimateArrays)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The settings estimate_arrays resolves for the record (preset lash, tuned to the data).
const lash::EstimatorConfig& resolved_config() {
  static const lash::EstimatorConfig c = lash::resolve_settings(sources(), 0.005, arrays().v, arrays().y).cfg;
  return c;
}

void BM_RunEstimator(benchmark::State& state) {
  const Arrays& a = arrays();
  const lash::EstimatorConfig& cfg = resolved_config();
  for (auto _ : state) {
    lash::EstimationRun run = lash::run_estimator(cfg, a.v, a.y);
    benchmark::DoNotOptimize(run.ysim.data());
  }
  per_sample(state);
}
BENCHMARK(BM_RunEstimator)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EstimatorLoop(benchmark::State& state) {
  const Arrays& a = arrays();
  const lash::EstimatorConfig& cfg = resolved_config();
  for (auto _ : state) {
    lash::DeadzoneDeadbandEstimator est(cfg);
    for (std::size_t k = 0; k < kSamples; ++k) {
      double yhat = est.step(a.v[k], a.y[k]);
      benchmark::DoNotOptimize(yhat);
    }
  }
  per_sample(state);
}
BENCHMARK(BM_EstimatorLoop)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_AnalyseSampling(benchmark::State& state) {
  const Arrays& a = arrays();
  for (auto _ : state) {
    benchmark::DoNotOptimize(lash::sample_period(a.t));
    lash::Sampling s = lash::analyse_sampling(a.t);
    benchmark::DoNotOptimize(s.median_dt);
  }
  per_sample(state);
}
BENCHMARK(BM_AnalyseSampling)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
