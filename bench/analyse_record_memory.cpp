// analyse_record's own peak memory and time on a record of N rows held in arrays (issue 29):
//
//   lash_analyse_record_memory [N=1000000] [R=3]
//
// v = 600·sin(0.005·k), y = a first-order lag of v plus Gaussian noise (σ = 2; seed 1): every
// quantile's sequence takes many distinct values. Prints the peak resident memory the call added
// above the arrays (getrusage ru_maxrss after the call − before it, the arrays already touched)
// and the median wall time of R calls, and the quantiles (so runs can be compared).
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "lash/identify/auto.hpp"

namespace {
long max_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}
}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = argc > 1 ? static_cast<std::size_t>(std::atof(argv[1])) : 1000000;
  const int repeat = argc > 2 ? std::atoi(argv[2]) : 3;
  std::vector<double> v(n), y(n);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 2.0);
  double state = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    v[k] = 600.0 * std::sin(0.005 * static_cast<double>(k));
    state += 0.01 * (v[k] - state);
    y[k] = state + noise(rng);
  }
  const long before = max_rss_kib();
  std::vector<double> ms;
  lash::DataTraits d;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    d = lash::analyse_record(v, y, 0.005);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  const long after = max_rss_kib();
  std::sort(ms.begin(), ms.end());
  std::printf("rows %zu: analyse_record peak memory above the arrays %ld KiB (process peak %ld KiB, arrays %zu KiB), "
              "median time %.2f ms of %d\n",
              n, after - before, after, 2 * n * sizeof(double) / 1024, ms[ms.size() / 2], repeat);
  std::printf("v_lo %a v_hi %a y_span %a noise_sigma %a ydot_p90 %a yddot_p90 %a\n", d.v_lo, d.v_hi, d.y_span,
              d.noise_sigma, d.ydot_p90, d.yddot_p90);
  return 0;
}
