#include "lash/identify/intervals.hpp"

#include <algorithm>
#include <array>
#include <type_traits>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "lash/identify/any_estimator.hpp"
#include "lash/metrics/first_order.hpp"

namespace lash {

Reason interval_verdict(const SideIntervals& ci, Side s) noexcept {
  auto reaches = [](const Interval& i, auto bad) { return i.valid() && (bad(i.lo) || bad(i.hi)); };
  const bool impossible =
      reaches(ci.a1, [](double a) { return !(a < 0.0); }) ||
      reaches(ci.K, [](double k) { return !(k > 0.0); }) ||
      reaches(ci.tau_s, [](double t) { return !(t > 0.0); }) ||
      reaches(ci.c, [s](double c) { return !verdict_rules::physical_edge(c, s); }) ||
      reaches(ci.d, [](double d) { return !(d >= 0.0); });
  return impossible ? Reason::uncertain : Reason::none;
}

WidestInterval widest_interval(const SideIntervals& ci, bool has_c, bool has_d) noexcept {
  WidestInterval w;
  const auto judge = [&w](const char* name, const Interval& i) {  // strict >: the first missing one stays
    const double rel = i.valid() && i.hi + i.lo != 0.0 ? (i.hi - i.lo) / std::fabs(i.hi + i.lo)
                                                       : std::numeric_limits<double>::infinity();
    if (!w.name || rel > w.relative) w = {name, rel};
  };
  judge("K", ci.K);
  judge("tau_s", ci.tau_s);
  if (has_c) judge("c", ci.c);
  if (has_d) judge("d", ci.d);
  return w;
}

Reason precision_verdict(const SideIntervals& ci, double tolerance, bool has_c, bool has_d) noexcept {
  if (!(tolerance > 0.0)) return Reason::none;
  return widest_interval(ci, has_c, has_d).relative <= tolerance ? Reason::none : Reason::uncertain;
}

double student_t975(std::size_t dof) noexcept {
  // t_{0.975, n}, n = 1 … 30 (any statistics table; scipy.stats.t.ppf(0.975, n))
  static constexpr std::array<double, 30> t{12.7062047, 4.30265273, 3.18244631, 2.77644511, 2.57058184, 2.44691185,
                                            2.36462425, 2.30600414, 2.26215716, 2.22813885, 2.20098516, 2.17881283,
                                            2.16036866, 2.14478669, 2.13144955, 2.11990530, 2.10981558, 2.10092204,
                                            2.09302405, 2.08596345, 2.07961384, 2.07387307, 2.06865761, 2.06389856,
                                            2.05953855, 2.05552944, 2.05183052, 2.04840714, 2.04522964, 2.04227246};
  if (dof == 0) return std::numeric_limits<double>::infinity();
  if (dof <= t.size()) return t[dof - 1];
  // Cornish–Fisher expansion around z = 1.959964 (Abramowitz & Stegun 26.7.5, three terms):
  // within 1e-6 of the exact quantile for n > 30
  const double z = 1.959963984540054, n = static_cast<double>(dof);
  const double z3 = z * z * z, z5 = z3 * z * z, z7 = z5 * z * z;
  return z + (z3 + z) / (4 * n) + (5 * z5 + 16 * z3 + 3 * z) / (96 * n * n) +
         (3 * z7 + 19 * z5 + 17 * z3 - 15 * z) / (384 * n * n * n);
}

namespace {
/// Memory of the estimator over `n` samples: exponential forgetting keeps about 1/(1 − λ).
double memory(const EstimatorConfig& c, std::size_t n) {
  const double len = static_cast<double>(n);
  return c.rls.lambda < 1.0 ? std::min(len, 1.0 / (1.0 - c.rls.lambda)) : len;
}

Interval around(double centre, const std::vector<double>& xs, double scale, std::size_t min_n) {
  Interval iv;
  if (!std::isfinite(centre) || xs.size() < min_n || xs.size() < 2) return iv;
  double mean = 0.0;
  for (double x : xs) mean += x;
  mean /= static_cast<double>(xs.size());
  double ss = 0.0;
  for (double x : xs) ss += (x - mean) * (x - mean);
  const double sd = std::sqrt(ss / static_cast<double>(xs.size() - 1));
  const double half = student_t975(xs.size() - 1) * sd * scale;
  if (!std::isfinite(half)) return iv;
  iv.lo = centre - half;
  iv.hi = centre + half;
  return iv;
}

/// The length of each of B consecutive groups (sections) of n samples; 0 when there are too few
/// groups or samples for an interval.
std::size_t group_len(std::size_t n, std::size_t B) { return B < 2 || n / B < 2 ? 0 : n / B; }
}  // namespace

PerSide<SideIntervals> batch_means_intervals(const EstimatorConfig& cfg, std::span<const double> v,
                                             std::span<const double> y, const PerSide<SideParams>& estimate,
                                             const IntervalSettings& s) {
  if (v.size() != y.size()) throw std::invalid_argument("v and y differ in length");
  return batch_means_intervals(cfg, RecordColumns::of(v, y), estimate, s);
}

PerSide<SideIntervals> batch_means_intervals(const EstimatorConfig& cfg, const RecordColumns& rec,
                                             const PerSide<SideParams>& estimate, const IntervalSettings& s) {
  const std::size_t n = rec.size(), B = s.sections, len = group_len(n, B);
  if (len == 0) return {};
  // Each section's estimator starts fresh. Sections b and b + half run in lockstep in one loop:
  // two independent recursions (each RLS update waits on its own last result) that the CPU
  // overlaps, where one after the other they left it waiting. Same samples, same order per
  // estimator: the same bits as one section after the other. Both sections are read in chunks of
  // the same rows within the section (a spilled record streams; in memory: one chunk, views).
  const std::size_t half = (B + 1) / 2;
  std::vector<PerSide<SideParams>> at(B);
  AnyEstimator ea(cfg), eb(cfg);
  ChunkBuffer<2> bx, bz;
  for (std::size_t b = 0; b < half; ++b) {
    ea.reset();
    eb.reset();
    const std::size_t b2 = b + half, a0 = b * len, c0 = b2 * len;
    if (b2 >= B) {
      step_through(ea, rec, a0, a0 + len, s.gap_rows, [](std::size_t, double, const auto&) {});
    } else {
      ea.visit_steps(len, [&](auto& x) {
        eb.visit_steps(len, [&](auto& z) {
          if constexpr (std::is_same_v<decltype(x), decltype(z)>) {
            const auto& g = s.gap_rows;
            auto gx = std::lower_bound(g.begin(), g.end(), a0), gz = std::lower_bound(g.begin(), g.end(), c0);
            const std::size_t chunk = rec.store.in_memory() ? len : ColumnStore::kChunkRows;
            for (std::size_t i0 = 0; i0 < len; i0 += chunk) {
              const std::size_t m = std::min(chunk, len - i0);
              const auto cx = bx.get(rec.store, rec.vy, a0 + i0, m), cz = bz.get(rec.store, rec.vy, c0 + i0, m);
              const std::span<const double> vx = cx[0], yx = cx[1], vz = cz[0], yz = cz[1];
              for (std::size_t j = 0; j < m; ++j) {
                const std::size_t i = i0 + j, kx = a0 + i, kz = c0 + i;
                if (gx != g.end() && *gx == kx) {
                  if (i > 0) x.restart();  // at the section's start the history is already empty
                  ++gx;
                }
                if (gz != g.end() && *gz == kz) {
                  if (i > 0) z.restart();
                  ++gz;
                }
                x.step(vx[j], yx[j]);
                z.step(vz[j], yz[j]);
              }
            }
          } else {
            (void)x;  // one config, one model: never two kinds
            (void)z;
          }
        });
      });
      at[b2] = {eb.params(Side::right), eb.params(Side::left)};
    }
    at[b] = {ea.params(Side::right), ea.params(Side::left)};
  }
  return section_intervals(cfg, at, len, n, estimate, s.min_sections);
}

namespace {
/// The intervals from per-side replicate estimates (sections or jackknife replicates: those of
/// identified sides) with half-width t_{0.975, m−1} · sd · scale, m the replicates used.
PerSide<SideIntervals> replicate_intervals(const EstimatorConfig& cfg, std::span<const PerSide<SideParams>> reps,
                                           const PerSide<SideParams>& estimate, double scale, std::size_t min_n) {
  PerSide<SideIntervals> out;
  // per side, per parameter: the replicate estimates of identified sides
  struct Samples {
    std::vector<double> a1, b1, c, d, K, tau;
  };
  PerSide<Samples> sm;
  for (const PerSide<SideParams>& sec : reps) {
    for (Side side : {Side::right, Side::left}) {
      const SideParams& p = sec[side];
      if (!p.identified) continue;
      Samples& q = sm[side];
      q.a1.push_back(p.a1);
      q.b1.push_back(p.b1);
      if (std::isfinite(p.c)) q.c.push_back(p.c);
      if (std::isfinite(p.d)) q.d.push_back(p.d);
      q.K.push_back(static_gain(p.a1, p.b1));
      const double tau = time_constant_s(p.a1, cfg.dt_s);
      if (std::isfinite(tau)) q.tau.push_back(tau);
    }
  }
  for (Side side : {Side::right, Side::left}) {
    const SideParams& e = estimate[side];
    const Samples& q = sm[side];
    SideIntervals& r = out[side];
    r.a1 = around(e.a1, q.a1, scale, min_n);
    r.b1 = around(e.b1, q.b1, scale, min_n);
    r.c = around(e.c, q.c, scale, min_n);
    r.d = around(e.d, q.d, scale, min_n);
    r.K = around(static_gain(e.a1, e.b1), q.K, scale, min_n);
    r.tau_s = around(time_constant_s(e.a1, cfg.dt_s), q.tau, scale, min_n);
  }
  return out;
}
}  // namespace

PerSide<SideIntervals> section_intervals(const EstimatorConfig& cfg, std::span<const PerSide<SideParams>> sections,
                                         std::size_t len, std::size_t n, const PerSide<SideParams>& estimate,
                                         std::size_t min_sections) {
  return replicate_intervals(cfg, sections, estimate, std::sqrt(memory(cfg, len) / memory(cfg, n)), min_sections);
}

PerSide<SideIntervals> jackknife_intervals(const EstimatorConfig& cfg, const RecordColumns& rec,
                                           const PerSide<SideParams>& estimate, const IntervalSettings& s) {
  const std::size_t n = rec.size(), B = s.sections, len = group_len(n, B);
  if (len == 0) return {};
  std::vector<PerSide<SideParams>> reps(B);
  // Replicate b: the record without group b (the last: to the end). Every replicate's run over
  // [0, g0) is the first g0 rows of one run: `prefix` advances group by group and each replicate
  // starts from a copy of it (the same state, hence the same bits as a run from row 0), so the
  // ten replicates step through 5.4 records' rows instead of 9.
  AnyEstimator prefix(cfg);
  const auto none = [](std::size_t, double, const auto&) {};
  for (std::size_t b = 0; b < B; ++b) {
    const std::size_t g0 = b * len, g1 = b + 1 == B ? n : g0 + len;
    AnyEstimator e = prefix;
    e.restart();  // the samples on both sides of the group are not neighbours
    step_through(e, rec, g1, n, s.gap_rows, none);
    reps[b] = {e.params(Side::right), e.params(Side::left)};
    if (b + 1 < B) {  // the next replicate's prefix: to g1
      // step_through does not restart at its first row: a run from row 0 would restart at a gap there
      if (g0 > 0 && std::binary_search(s.gap_rows.begin(), s.gap_rows.end(), g0)) prefix.restart();
      step_through(prefix, rec, g0, g1, s.gap_rows, none);
    }
  }
  // var = (B − 1)/B · Σ(θ_(b) − θ̄)² = sd² · (B − 1)²/B: sd · (B − 1)/√B; every replicate is needed
  const double fb = static_cast<double>(B);
  return replicate_intervals(cfg, reps, estimate, (fb - 1.0) / std::sqrt(fb), B);
}

}  // namespace lash
