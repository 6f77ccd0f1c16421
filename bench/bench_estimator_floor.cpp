// The floor of the thesis-settings deadzone-deadband estimator (BM_DeadzoneDeadband in
// bench_identify.cpp): the same arithmetic written out by hand for that one model and those
// settings (docs/method.md §A4.3: four RLS keyed l±, r±, λ 0.99, P0 = 1000·I, η0 = [1 1 1], no
// filters, direction held 2 samples, guesses ±350), in one function over plain locals — no
// policy, no variant, no settings read at run time. Before timing, it is checked to give ŷ and
// y_sim bit for bit equal to lash::DeadzoneDeadbandEstimator's on the same data, so it is the
// same computation. bench/estimator_floor_ratio.py prints estimator / floor.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "e1_plant.hpp"

#include "lash/identify/estimators.hpp"

namespace {

constexpr double kDt = 0.005, kGuess = 350.0, kLambda = 0.99, kTraceMax = 1e12, kSettleTol = 0.01,
                 kSingularTol = 1e-6;
constexpr std::uint64_t kMinUpdates = 50, kFitStart = 1500;  // ceil(7.5 s / 5 ms)
constexpr std::uint32_t kDirectionRun = 2, kSettleUpdates = 5;

struct Key {  // one RLS: η = [a1, b1, e], P symmetric
  double eta[3] = {1.0, 1.0, 1.0};
  double p[3][3] = {{1000.0, 0.0, 0.0}, {0.0, 1000.0, 0.0}, {0.0, 0.0, 1000.0}};
  std::uint64_t n = 0;
  double predict(double f0, double f1) const noexcept { return ((0.0 + f0 * eta[0]) + f1 * eta[1]) + 1.0 * eta[2]; }
  double update(double f0, double f1, double y) noexcept {
    const double f[3] = {f0, f1, 1.0};
    const double yhat = predict(f0, f1);
    double pf[3];
    for (int i = 0; i < 3; ++i) pf[i] = ((0.0 + p[i][0] * f[0]) + p[i][1] * f[1]) + p[i][2] * f[2];
    const double d = (p[0][0] * (f[0] * f[0]) + p[1][1] * (f[1] * f[1])) + p[2][2] * (f[2] * f[2]);
    const double o = (p[0][1] * (f[0] * f[1]) + p[0][2] * (f[0] * f[2])) + p[1][2] * (f[1] * f[2]);
    const double r = d + 2.0 * o, err = y - yhat;
    const double tr = ((0.0 + p[0][0]) + p[1][1]) + p[2][2];
    const double inv_l = 1.0 / kLambda;
    const double scale = tr * inv_l > kTraceMax ? 1.0 : inv_l;
    const double inv = 1.0 / (kLambda + r);
    for (int i = 0; i < 3; ++i) eta[i] += pf[i] * inv * err;
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) p[i][j] = p[i][j] * scale - (pf[i] * pf[j] * scale) * inv;
    p[1][0] = p[0][1];
    p[2][0] = p[0][2];
    p[2][1] = p[1][2];
    ++n;
    return yhat;
  }
};

struct Floor {
  Key key[4];  // r+, r−, l+, l−
  double sa1[2] = {0, 0}, sb1[2] = {0, 0}, sd[2] = {0, 0}, sc[2] = {kGuess, -kGuess};
  double prev_c[2] = {0, 0}, prev_d[2] = {0, 0};
  std::uint32_t settled[2] = {0, 0}, since[2] = {0, 0};
  bool usable[2] = {false, false};
  double y_prev = 0, y1 = 0, v1 = 0, vraw1 = 0, w = 0, ysim = 0, yhat = 0;
  int last = 0, sim_last = 0, regime1 = 0;
  std::uint32_t run = 0;
  std::uint64_t k = 0;
  double sum_w = 0, max_w = 0, sum_b = 0, max_b = 0;  // fit window and before it
  double vlo[2] = {INFINITY, INFINITY}, vhi[2] = {-INFINITY, -INFINITY}, ylo[2] = {INFINITY, INFINITY},
         yhi[2] = {-INFINITY, -INFINITY};

  [[gnu::noinline]] void refresh(int s) noexcept {  // eq. 31/32, every 8th update once usable
    const Key &kp = key[2 * s], &km = key[2 * s + 1];
    const double fp = static_cast<double>(kp.n), fm = static_cast<double>(km.n);
    const double t1 = (1.0 + kp.eta[0]) * km.eta[1], t2 = kp.eta[1] * (1.0 + km.eta[0]), det = t1 + t2;
    const bool solvable = std::fabs(det) > kSingularTol * (std::fabs(t1) + std::fabs(t2));
    const double n = fp + fm;
    double inv, inv_n;
    if (det != 0.0 && std::isfinite(det)) {
      const double both = 1.0 / (n * det);
      inv = n * both;
      inv_n = det * both;
    } else {
      inv = NAN;
      inv_n = 1.0 / n;
    }
    const double a1 = (fp * kp.eta[0] + fm * km.eta[0]) * inv_n, b1 = (fp * kp.eta[1] + fm * km.eta[1]) * inv_n;
    const double d = (-km.eta[1] * kp.eta[2] + kp.eta[1] * km.eta[2]) * inv;
    const double c = (-(1.0 + km.eta[0]) * kp.eta[2] - (1.0 + kp.eta[0]) * km.eta[2]) * inv;
    const bool ok0 = kp.n >= kMinUpdates && km.n >= kMinUpdates && solvable && std::isfinite(c) &&
                     std::isfinite(d) && std::isfinite(a1) && std::isfinite(b1) && c > -kGuess && c < kGuess &&
                     d >= 0.0;
    const bool still = std::fabs(c - prev_c[s]) + std::fabs(d - prev_d[s]) <= kSettleTol * (std::fabs(c) + std::fabs(d));
    settled[s] = still ? settled[s] + 1 : 0;
    prev_c[s] = c;
    prev_d[s] = d;
    usable[s] = ok0 && settled[s] >= kSettleUpdates;
    sa1[s] = a1;
    sb1[s] = b1;
    if (usable[s]) {
      sc[s] = c;
      sd[s] = d > 0.0 ? d : 0.0;
    }
  }

  double step(double v, double y) noexcept {
    const double ydot = (y - y_prev) * (1.0 / kDt);
    y_prev = y;
    const int dir = ydot > 0.0 ? 1 : (ydot < -0.0 ? -1 : 0);
    const int side = v1 > kGuess ? 0 : (v1 < -kGuess ? 1 : -1);
    const int regime = dir == 0 ? 0 : dir * (side >= 0 ? 1 + side : 3);
    run = (regime != 0 && regime == regime1) ? run + 1 : 1;
    regime1 = regime;
    if (side >= 0 && dir != 0 && run >= kDirectionRun) {
      Key& r = key[2 * side + (dir > 0 ? 0 : 1)];
      yhat = r.update(-y1, v1, y);
      vlo[side] = std::min(vlo[side], v1);
      vhi[side] = std::max(vhi[side], v1);
      ylo[side] = std::min(ylo[side], y1);
      yhi[side] = std::max(yhi[side], y1);
      if (!usable[side] || (++since[side] & 7u) == 0) [[unlikely]] refresh(side);
      last = side;
    } else {
      const int s = side >= 0 ? side : last;
      const double up = key[2 * s].predict(-y1, v1), down = key[2 * s + 1].predict(-y1, v1);
      yhat = up > y1 ? up : (down < y1 ? down : y1);
    }
    y1 = y;
    v1 = v;
    // free run: DZ(v) → first order of the side → deadband
    const int ss = vraw1 > sc[0] ? 0 : (vraw1 < sc[1] ? 1 : sim_last);
    sim_last = ss;
    const double u = vraw1 > sc[0] ? vraw1 - sc[0] : (vraw1 < sc[1] ? vraw1 - sc[1] : 0.0);
    w = -sa1[ss] * w + sb1[ss] * u;
    if (w < ysim - sd[ss]) ysim = w + sd[ss];
    else if (w > ysim + sd[ss]) ysim = w - sd[ss];
    vraw1 = v;
    const double e = y - ysim;
    if (k++ >= kFitStart) [[likely]] {
      sum_w += e * e;
      max_w = std::max(max_w, std::fabs(y));
    } else {
      sum_b += e * e;
      max_b = std::max(max_b, std::fabs(y));
    }
    return yhat;
  }
};

struct Data {
  std::vector<double> v, y;
};
const Data& data() {
  static const Data d = [] {
    lash::Plant p = lash::bench::e1_plant();
    Data out;
    for (std::size_t k = 0; k < (1u << 16); ++k) {
      const double v = 600.0 * std::sin(0.005 * static_cast<double>(k));
      out.v.push_back(v);
      out.y.push_back(p.step(v));
    }
    return out;
  }();
  return d;
}

/// The floor computes what the estimator computes: ŷ and y_sim bit for bit over 4 passes of the data.
bool same_as_estimator() {
  lash::EstimatorConfig c = lash::EstimatorConfig::thesis(lash::ModelKind::deadzone_deadband, kDt);
  c.guess_left = -kGuess;
  c.guess_right = kGuess;
  lash::DeadzoneDeadbandEstimator est(c);
  Floor f;
  const Data& d = data();
  for (std::size_t k = 0; k < 4 * d.v.size(); ++k) {
    const std::size_t i = k & (d.v.size() - 1);
    const double a = est.step(d.v[i], d.y[i]), b = f.step(d.v[i], d.y[i]);
    if (!(a == b && est.simulated() == f.ysim)) {
      std::fprintf(stderr, "floor differs from the estimator at sample %zu: %a %a, %a %a\n", k, a, b,
                   est.simulated(), f.ysim);
      return false;
    }
  }
  return true;
}

void BM_DeadzoneDeadbandFloor(benchmark::State& state) {
  static const bool same = same_as_estimator();
  if (!same) {
    state.SkipWithError("the floor does not compute what the estimator computes");
    return;
  }
  const Data& d = data();
  const std::size_t mask = d.v.size() - 1;
  Floor f;
  std::size_t i = 0;
  for (auto _ : state) {
    double yhat = f.step(d.v[i], d.y[i]);
    benchmark::DoNotOptimize(yhat);
    i = (i + 1) & mask;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DeadzoneDeadbandFloor);

}  // namespace
