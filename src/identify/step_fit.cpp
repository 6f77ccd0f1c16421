#include "lash/identify/step_fit.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lash {
namespace {

void steady_stats(const std::vector<double>& p, StepSegment& s) {
  const auto n = static_cast<double>(s.end - s.steady_begin);
  double m = 0.0;
  for (std::size_t i = s.steady_begin; i < s.end; ++i) m += p[i];
  m /= n;
  double v = 0.0;
  for (std::size_t i = s.steady_begin; i < s.end; ++i) v += (p[i] - m) * (p[i] - m);
  s.mean_kPa = m;
  s.std_kPa = n > 1 ? std::sqrt(v / (n - 1)) : 0.0;
}

}  // namespace

StepFit fit_steps(const std::vector<double>& t, const std::vector<double>& cur, const std::vector<double>& p,
                  const StepFitOptions& o) {
  if (t.size() != cur.size() || t.size() != p.size()) throw std::invalid_argument("columns differ in length");
  if (t.size() < 2) throw std::invalid_argument("need at least 2 rows");
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(t[i] > t[i - 1])) throw std::invalid_argument("time must be strictly increasing");
  StepFit fit;
  // 1. Segments of constant current.
  std::size_t b = 0;
  for (std::size_t i = 1; i <= t.size(); ++i)
    if (i == t.size() || std::fabs(cur[i] - cur[b]) > o.current_tolerance_mA) {
      StepSegment s;
      s.begin = b;
      s.end = i;
      s.current_mA = cur[b];
      fit.segments.push_back(s);
      b = i;
    }
  auto& segs = fit.segments;
  double tau = 0.0;
  for (int pass = 0; pass < 3; ++pass) {
    // 2. Steady parts.
    for (auto& s : segs) {
      std::size_t sb = s.begin + (s.end - s.begin) / 2;
      if (tau > 0.0) {
        sb = s.begin;
        while (sb < s.end && t[sb] - t[s.begin] < o.settle_taus * tau) ++sb;
      }
      if (s.begin == 0 && tau > 0.0) sb = s.begin;  // the record starts at rest
      s.steady_begin = sb;
      if (s.end - s.steady_begin >= o.min_steady_samples) steady_stats(p, s);
    }
    auto steady = [&](const StepSegment& s) { return s.end - s.steady_begin >= o.min_steady_samples; };
    // 3. Bias.
    double sum = 0.0;
    std::size_t n = 0;
    for (const auto& s : segs)
      if (steady(s) && std::fabs(s.current_mA) <= o.zero_current_mA)
        for (std::size_t i = s.steady_begin; i < s.end; ++i) sum += p[i], ++n;
    if (n == 0) throw std::invalid_argument("no steady zero-current segment to take the bias from");
    fit.bias_kPa = sum / static_cast<double>(n);
    // 6. σ (pooled about segment means).
    double ss = 0.0;
    std::size_t dof = 0;
    for (const auto& s : segs)
      if (steady(s)) {
        for (std::size_t i = s.steady_begin; i < s.end; ++i) ss += (p[i] - s.mean_kPa) * (p[i] - s.mean_kPa);
        dof += s.end - s.steady_begin - 1;
      }
    fit.noise_sigma_kPa = dof > 0 ? std::sqrt(ss / static_cast<double>(dof)) : 0.0;
    // 4. Line through steady points above the deadzone.
    const double sigma_mean_guard = 5.0 * fit.noise_sigma_kPa;
    for (auto& s : segs) s.on_line = steady(s) && s.mean_kPa - fit.bias_kPa > sigma_mean_guard && s.current_mA > 0;
    double slope = 0.0, icept = 0.0;
    for (int it = 0; it < 20; ++it) {
      double sx = 0, sy = 0, sxx = 0, sxy = 0, m = 0;
      for (const auto& s : segs)
        if (s.on_line) {
          const double x = s.current_mA, y = s.mean_kPa - fit.bias_kPa;
          sx += x, sy += y, sxx += x * x, sxy += x * y, m += 1;
        }
      if (m < 2) throw std::invalid_argument("fewer than 2 steady points above the deadzone to fit the line");
      const double den = m * sxx - sx * sx;
      if (!(std::fabs(den) > 0)) throw std::invalid_argument("steady points above the deadzone share one current");
      slope = (m * sxy - sx * sy) / den;
      icept = (sy - slope * sx) / m;
      if (!(slope > 0)) throw std::invalid_argument("steady pressure does not rise with current");
      const double dz = -icept / slope;
      bool changed = false;
      for (auto& s : segs) {
        const bool want = steady(s) && s.current_mA > dz && s.mean_kPa - fit.bias_kPa > 0.5 * sigma_mean_guard;
        if (want != s.on_line) s.on_line = want, changed = true;
      }
      if (!changed) break;
    }
    fit.gain_kPa_per_mA = slope;
    fit.deadzone_mA = -icept / slope;
    fit.line_points = static_cast<std::size_t>(std::count_if(segs.begin(), segs.end(), [](auto& s) { return s.on_line; }));
    // 5. τ over all transients with a clear level change.
    struct Tr {
      std::size_t i0, i1;
      double ts, p0, pf;
    };
    std::vector<Tr> trs;
    for (std::size_t k = 1; k < segs.size(); ++k) {
      auto& a = segs[k - 1];
      auto& s = segs[k];
      s.transient_used = false;
      if (!steady(a) || !steady(s)) continue;
      if (std::fabs(s.mean_kPa - a.mean_kPa) < 10.0 * fit.noise_sigma_kPa + 1e-9) continue;
      trs.push_back({s.begin, s.end, t[s.begin], a.mean_kPa, s.mean_kPa});
      s.transient_used = true;
    }
    if (trs.empty()) throw std::invalid_argument("no transient between steady levels to fit the time constant");
    fit.transients = trs.size();
    auto sse = [&](double logtau) {
      const double tt = std::exp(logtau);
      double e = 0.0;
      for (const auto& r : trs)
        for (std::size_t i = r.i0; i < r.i1; ++i) {
          const double m = r.pf + (r.p0 - r.pf) * std::exp(-(t[i] - r.ts) / tt);
          e += (p[i] - m) * (p[i] - m);
        }
      return e;
    };
    const double dt = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
    double lo = std::log(dt / 10.0), hi = std::log(t.back() - t.front());
    // Coarse grid, then golden section around the best grid point.
    const int G = 60;
    int bi = 0;
    double be = 1e300;
    for (int g = 0; g <= G; ++g) {
      const double e = sse(lo + (hi - lo) * g / G);
      if (e < be) be = e, bi = g;
    }
    double a = lo + (hi - lo) * std::max(0, bi - 1) / G, c = lo + (hi - lo) * std::min(G, bi + 1) / G;
    const double gr = (std::sqrt(5.0) - 1.0) / 2.0;
    double x1 = c - gr * (c - a), x2 = a + gr * (c - a);
    double f1 = sse(x1), f2 = sse(x2);
    for (int it = 0; it < 100 && c - a > 1e-10; ++it) {
      if (f1 < f2) c = x2, x2 = x1, f2 = f1, x1 = c - gr * (c - a), f1 = sse(x1);
      else a = x1, x1 = x2, f1 = f2, x2 = a + gr * (c - a), f2 = sse(x2);
    }
    tau = std::exp(0.5 * (a + c));
    fit.tau_s = tau;
  }
  return fit;
}

}  // namespace lash
