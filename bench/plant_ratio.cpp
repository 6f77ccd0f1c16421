// The plant against its hand-written floor (issue 28 item 4): runs BM_PlantEq34, BM_PlantEq34Run
// and their floors (bench_plant.cpp) in one Google Benchmark run and prints the ratios by CPU time
// per sample (1 / items_per_second; median of the repetitions):
//   - "ratio BM_PlantEq34Run / floor = R (goal <= 1.5)": Plant::run over chunks of 4096 samples
//     against the hand-written eq-34 step over the same chunk loop (its state in a local over the
//     chunk, written back to its object at the end, as run() does);
//   - the per-call Plant::step against two floors: the hand-written step as a local object (the
//     compiler keeps its state in registers across the benchmark loop) and the same step on an
//     object whose state lives in memory between calls, as a Plant's must between step() calls
//     (one store and one load on the recurrence per step).
//
//   lash_bench_plant_ratio [google-benchmark flags, e.g. --benchmark_repetitions=5]
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {
class Capture : public benchmark::ConsoleReporter {
 public:
  std::map<std::string, std::vector<double>> ns_per_sample;  // CPU time, every repetition
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs) {
      if (r.run_type != Run::RT_Iteration) continue;
      const auto it = r.counters.find("items_per_second");  // samples per CPU second
      if (it != r.counters.end() && it->second.value > 0)
        ns_per_sample[r.run_name.function_name].push_back(1e9 / it->second.value);
    }
    ConsoleReporter::ReportRuns(runs);
  }
};
double median(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  return x.empty() ? 0.0 : x[x.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> args(argv, argv + argc);
  std::string filter = "--benchmark_filter=^BM_PlantEq34(_Floor|_FloorInMemory|Run|Run_Floor)?$";
  args.push_back(filter.data());
  int n = static_cast<int>(args.size());
  benchmark::Initialize(&n, args.data());
  Capture rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  auto ns = [&](const char* name) { return median(rep.ns_per_sample[name]); };
  const double p = ns("BM_PlantEq34"), f = ns("BM_PlantEq34_Floor"), fm = ns("BM_PlantEq34_FloorInMemory"),
               r = ns("BM_PlantEq34Run"), fr = ns("BM_PlantEq34Run_Floor");
  if (r > 0 && fr > 0 && f > 0) {
    std::printf("BM_PlantEq34Run %.2f ns/sample; floor %.2f ns/sample (the hand-written step over the same chunk loop)\n",
                r, fr);
    std::printf("ratio BM_PlantEq34Run / floor = %.3f (goal <= 1.5); / the per-call register floor = %.3f\n", r / fr,
                r / f);
  }
  if (p > 0 && f > 0 && fm > 0) {
    std::printf("BM_PlantEq34 %.2f ns; floor %.2f ns (state in registers); floor %.2f ns (state in memory)\n", p, f, fm);
    std::printf("ratio BM_PlantEq34 / floor = %.3f (per call); / floor with its state in memory = %.3f; "
                "that floor / the register floor = %.3f\n", p / f, p / fm, fm / f);
  }
  benchmark::Shutdown();
  return 0;
}
