// Ingest benchmark (issue 12 item 8): read_table on a t,v,y CSV against a minimal hand-written
// reader (std::getline + std::from_chars into three vectors), measured in the same Google
// Benchmark run, and the peak memory of read_table against the needed columns as doubles.
//
//   lash_bench_ingest [--rows N] [google-benchmark flags]      (default N = 10^7)
//
// Prints "ratio read_table / minimal = R" (CPU time of the reading thread; goal ≤ 1.3) and
// "peak RSS of read_table = M MB = X × the needed columns (24 B/row)" (goal ≤ 2).
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "lash/io/table.hpp"

namespace {

std::filesystem::path g_file;
std::size_t g_rows = 10'000'000;

void write_file(const std::filesystem::path& p, std::size_t rows) {
  std::FILE* f = std::fopen(p.c_str(), "wb");
  std::fputs("t,v,y\n", f);
  char buf[128];
  std::uint64_t s = 12345;
  for (std::size_t i = 0; i < rows; ++i) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    const double t = static_cast<double>(i) * 0.005;
    const double v = static_cast<double>(static_cast<std::int64_t>(s >> 40) - (1 << 23)) / 8192.0;
    const double y = v * 0.731 + static_cast<double>(s & 0xFFFF) / 65536.0;
    char* p2 = std::to_chars(buf, buf + 40, t).ptr;
    *p2++ = ',';
    p2 = std::to_chars(p2, p2 + 40, v).ptr;
    *p2++ = ',';
    p2 = std::to_chars(p2, p2 + 40, y).ptr;
    *p2++ = '\n';
    std::fwrite(buf, 1, static_cast<std::size_t>(p2 - buf), f);
  }
  std::fclose(f);
}

/// The reference: what one writes by hand for a known 3-column file.
void minimal_read(const std::filesystem::path& p, std::vector<double>& t, std::vector<double>& v,
                  std::vector<double>& y) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    const char* b = line.data();
    const char* e = b + line.size();
    double a = 0, c = 0, d = 0;
    auto r = std::from_chars(b, e, a);
    r = std::from_chars(r.ptr + 1, e, c);
    std::from_chars(r.ptr + 1, e, d);
    t.push_back(a);
    v.push_back(c);
    y.push_back(d);
  }
}

void BM_Ingest_Minimal(benchmark::State& state) {
  for (auto _ : state) {
    std::vector<double> t, v, y;
    minimal_read(g_file, t, v, y);
    benchmark::DoNotOptimize(t.data());
    if (t.size() != g_rows) state.SkipWithError("minimal reader: wrong row count");
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * g_rows));
}

void BM_Ingest_ReadTable(benchmark::State& state) {
  lash::TableOptions o;
  o.columns = {"t", "v", "y"};
  for (auto _ : state) {
    lash::Table tab = lash::read_table(g_file, o);
    benchmark::DoNotOptimize(tab.cols[0].data());
    if (tab.rows() != g_rows) state.SkipWithError("read_table: wrong row count");
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * g_rows));
}

class Capture : public benchmark::ConsoleReporter {
 public:
  std::map<std::string, double> cpu_ns, real_ns;  // per iteration
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs)
      if (r.run_type == Run::RT_Iteration || r.aggregate_name == "median") {
        const double to_ns = 1e9 / benchmark::GetTimeUnitMultiplier(r.time_unit);
        cpu_ns[r.run_name.function_name] = r.GetAdjustedCPUTime() * to_ns;
        real_ns[r.run_name.function_name] = r.GetAdjustedRealTime() * to_ns;
      }
    ConsoleReporter::ReportRuns(runs);
  }
};

/// Peak resident memory of a child process that only reads the table [bytes].
long peak_rss_of_read_table() {
  const pid_t pid = fork();
  if (pid == 0) {
    lash::TableOptions o;
    o.columns = {"t", "v", "y"};
    const lash::Table tab = lash::read_table(g_file, o);
    _exit(tab.rows() == g_rows ? 0 : 1);
  }
  int status = 0;
  struct rusage ru {};
  wait4(pid, &status, 0, &ru);
  return ru.ru_maxrss * 1024L;
}

}  // namespace

BENCHMARK(BM_Ingest_Minimal)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Ingest_ReadTable)->Unit(benchmark::kMillisecond)->Iterations(3);

int main(int argc, char** argv) {
  std::vector<char*> rest{argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--rows") == 0 && i + 1 < argc) g_rows = std::strtoull(argv[++i], nullptr, 10);
    else rest.push_back(argv[i]);
  }
  g_file = std::filesystem::temp_directory_path() / ("lash_ingest_" + std::to_string(::getpid()) + ".csv");
  write_file(g_file, g_rows);
  const long rss = peak_rss_of_read_table();
  int n = static_cast<int>(rest.size());
  benchmark::Initialize(&n, rest.data());
  Capture rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  std::filesystem::remove(g_file);
  const double needed = 24.0 * static_cast<double>(g_rows);
  std::printf("rows %zu\n", g_rows);
  // CPU time of the (single) reading thread: on a shared machine wall time also counts the
  // time other processes held the core. Both are printed.
  for (auto* m : {&rep.cpu_ns, &rep.real_ns}) {
    if (!m->count("BM_Ingest_Minimal") || !m->count("BM_Ingest_ReadTable")) continue;
    const double a = (*m)["BM_Ingest_Minimal"], r = (*m)["BM_Ingest_ReadTable"];
    const char* what = m == &rep.cpu_ns ? "cpu " : "wall";
    std::printf("%s: minimal reader %.1f ns/row, read_table %.1f ns/row, ratio read_table / minimal = %.3f%s\n",
                what, a / static_cast<double>(g_rows), r / static_cast<double>(g_rows), r / a,
                m == &rep.cpu_ns ? " (goal <= 1.3)" : "");
  }
  std::printf("peak RSS of read_table = %.1f MB = %.2f x the needed columns (24 B/row; goal <= 2)\n", static_cast<double>(rss) / 1e6,
              static_cast<double>(rss) / needed);
  benchmark::Shutdown();
  return 0;
}
