// The plant step against its hand-written floor (issue 28 item 4): runs BM_PlantEq34 and
// BM_PlantEq34_Floor (bench_plant.cpp) in one Google Benchmark run and prints
// "ratio BM_PlantEq34 / floor = R" (goal <= 1.5), by CPU time per step (median of the
// repetitions). Two floors: the hand-written eq-34 step as a local object (the compiler keeps its
// state in registers across the loop) and the same step on an object whose state lives in memory
// between calls, as a Plant's must (one store and one load on the recurrence per step).
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
  std::map<std::string, std::vector<double>> cpu_ns;  // per step, every repetition
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs)
      if (r.run_type == Run::RT_Iteration)
        cpu_ns[r.run_name.function_name].push_back(r.GetAdjustedCPUTime() * 1e9 /
                                                   benchmark::GetTimeUnitMultiplier(r.time_unit));
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
  std::string filter = "--benchmark_filter=^BM_PlantEq34(_Floor|_FloorInMemory)?$";
  args.push_back(filter.data());
  int n = static_cast<int>(args.size());
  benchmark::Initialize(&n, args.data());
  Capture rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  const double p = median(rep.cpu_ns["BM_PlantEq34"]), f = median(rep.cpu_ns["BM_PlantEq34_Floor"]),
               fm = median(rep.cpu_ns["BM_PlantEq34_FloorInMemory"]);
  if (p > 0 && f > 0 && fm > 0) {
    std::printf("BM_PlantEq34 %.2f ns; floor %.2f ns (state in registers); floor %.2f ns (state in memory)\n", p, f, fm);
    std::printf("ratio BM_PlantEq34 / floor = %.3f (goal <= 1.5); / floor with its state in memory = %.3f; "
                "that floor / the register floor = %.3f\n", p / f, p / fm, fm / f);
  }
  benchmark::Shutdown();
  return 0;
}
