#include "lash/experiments/tune.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "lash/io/csv.hpp"
#include "lash/signals/rng.hpp"

namespace lash {
namespace {

void parse_pairs(const std::string& text, const char* what,
                 const std::function<bool(const std::string&, double)>& set) {
  std::size_t start = 0;
  while (start < text.size()) {
    auto end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    const auto eq = item.find('=');
    double v = 0.0;
    if (eq == std::string::npos || !parse_double(item.substr(eq + 1), v) || !(v >= 0.0))
      throw std::invalid_argument(std::string(what) + ": expected NAME=NUMBER (>= 0), got '" + item + "'");
    if (!set(item.substr(0, eq), v))
      throw std::invalid_argument(std::string(what) + ": unknown name '" + item.substr(0, eq) + "'");
    start = end + 1;
  }
}

bool bad(double x) { return !std::isfinite(x); }

// Is the loop at rest on r0 just before the step and on r1 at the end of the record
// (within 1 % of the step)? A limit cycle (e.g. a discrete loop unstable at the Nyquist
// frequency, held in bounds by the 0–2000 mA saturation) fails this.
bool at_rest(const StepResult& r, const StepTest& st, double dt) {
  const double ts = st.t_step_s(dt), tend = r.trace.t_s.back();
  const double tol = 0.01 * std::fabs(st.r1_kPa - st.r0_kPa);
  for (std::size_t k = 0; k < r.trace.samples(); ++k) {
    const double t = r.trace.t_s[k];
    // A reference below the pressure at zero current cannot be held: the loop rests at the bias.
    const double target = t < ts ? std::max(st.r0_kPa, r.trace.pressure_kPa.front()) : st.r1_kPa;
    const bool window = (t < ts && t >= ts - 0.25) || t >= tend - 0.25;
    if (window && std::fabs(r.trace.pressure_kPa[k] - target) > tol) return false;
  }
  return true;
}

}  // namespace

void parse_targets(const std::string& text, TuneTargets& t) {
  parse_pairs(text, "--target", [&](const std::string& k, double v) {
    if (k == "rise") t.rise_s = v;
    else if (k == "settling") t.settling_s = v;
    else if (k == "overshoot") t.overshoot_pct = v;
    else if (k == "ode3_overshoot") t.ode3_overshoot_pct = v;
    else return false;
    return true;
  });
  if (!(t.rise_s > 0) || !(t.settling_s > 0) || !(t.overshoot_pct > 0))
    throw std::invalid_argument("--target: rise, settling and overshoot must be > 0");
}

void parse_weights(const std::string& text, TuneTargets& t) {
  parse_pairs(text, "--weights", [&](const std::string& k, double v) {
    if (k == "rise") t.w_rise = v;
    else if (k == "settling") t.w_settling = v;
    else if (k == "overshoot") t.w_overshoot = v;
    else if (k == "ode3") t.w_ode3 = v;
    else return false;
    return true;
  });
}

double tune_cost(const TuneOptions& o, const PidGains& g, StepMetrics* discrete, StepMetrics* ode3) {
  PilotValveParams p = o.plant;
  p.noise_sigma_kPa = 0.0;
  ControllerConfig c = o.controller;
  c.pid.gains = g;
  const auto& t = o.targets;
  const StepResult d = run_step_test(Solver::discrete, p, c, o.step);
  if (discrete) *discrete = d.metrics;
  double J = 0.0;
  auto rel2 = [](double m, double target) { return std::pow((m - target) / target, 2); };
  const auto& m = d.metrics;
  if (!at_rest(d, o.step, p.dt_s) || bad(m.rise_s) || bad(m.settling_s)) return 1e3;
  J += t.w_rise * rel2(m.rise_s, t.rise_s) + t.w_settling * rel2(m.settling_s, t.settling_s) +
       t.w_overshoot * rel2(m.overshoot_pct, t.overshoot_pct);
  const StepResult c3 = run_step_test(Solver::ode3, p, c, o.step);
  if (ode3) *ode3 = c3.metrics;
  const auto& m3 = c3.metrics;
  if (!at_rest(c3, o.step, p.dt_s) || bad(m3.rise_s) || bad(m3.settling_s)) return 100.0 + J;
  if (t.ode3_overshoot_pct) J += t.w_ode3 * rel2(m3.overshoot_pct, *t.ode3_overshoot_pct);
  return J;
}

TuneResult tune_pid(const TuneOptions& o) {
  const std::size_t dims = o.tune_filter ? 4 : 3;
  const std::array<double, 4> lo{std::log(o.kp_min), std::log(o.ki_min), std::log(o.kd_min), std::log(o.n_min)};
  const std::array<double, 4> hi{std::log(o.kp_max), std::log(o.ki_max), std::log(o.kd_max), std::log(o.n_max)};
  for (std::size_t i = 0; i < dims; ++i)
    if (!(lo[i] <= hi[i]) || bad(lo[i]) || bad(hi[i])) throw std::invalid_argument("tune: empty or invalid gain box");
  if (o.samples < 1 || o.restarts < 1 || o.iterations < 0) throw std::invalid_argument("tune: samples, restarts >= 1");
  using X = std::array<double, 4>;
  int evals = 0;
  auto gains_of = [&](const X& x) {
    PidGains g;
    g.kp = std::exp(std::clamp(x[0], lo[0], hi[0]));
    g.ki_per_s = std::exp(std::clamp(x[1], lo[1], hi[1]));
    g.kd_s = std::exp(std::clamp(x[2], lo[2], hi[2]));
    g.n_per_s = o.tune_filter ? std::exp(std::clamp(x[3], lo[3], hi[3])) : 0.0;
    return g;
  };
  auto cost = [&](const X& x) {
    ++evals;
    double outside = 0.0;  // keep Nelder–Mead inside the box
    for (std::size_t i = 0; i < dims; ++i) outside += std::max(0.0, lo[i] - x[i]) + std::max(0.0, x[i] - hi[i]);
    return tune_cost(o, gains_of(x)) + 10.0 * outside;
  };
  // 1. Seeded random sampling of the box.
  Rng rng(o.seed);
  std::vector<std::pair<double, X>> pool;
  pool.reserve(static_cast<std::size_t>(o.samples));
  for (int s = 0; s < o.samples; ++s) {
    X x{};
    for (std::size_t i = 0; i < dims; ++i) x[i] = lo[i] + rng.uniform() * (hi[i] - lo[i]);
    pool.emplace_back(cost(x), x);
  }
  std::stable_sort(pool.begin(), pool.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  // 2. Nelder–Mead (standard coefficients 1, 2, 0.5, 0.5) from the best few.
  std::pair<double, X> best = pool.front();
  const int starts = std::min<int>(o.restarts, static_cast<int>(pool.size()));
  for (int r = 0; r < starts; ++r) {
    std::vector<std::pair<double, X>> sx;
    sx.push_back(pool[static_cast<std::size_t>(r)]);
    for (std::size_t i = 0; i < dims; ++i) {
      X x = sx[0].second;
      x[i] += 0.1 * (hi[i] - lo[i]);
      sx.emplace_back(cost(x), x);
    }
    for (int it = 0; it < o.iterations; ++it) {
      std::stable_sort(sx.begin(), sx.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      if (sx.back().first - sx.front().first < 1e-10) break;
      X c{};
      for (std::size_t v = 0; v < dims; ++v)
        for (std::size_t i = 0; i < dims; ++i) c[i] += sx[v].second[i] / static_cast<double>(dims);
      auto along = [&](double f) {
        X x{};
        for (std::size_t i = 0; i < dims; ++i) x[i] = c[i] + f * (sx.back().second[i] - c[i]);
        return std::make_pair(cost(x), x);
      };
      auto refl = along(-1.0);
      if (refl.first < sx.front().first) {
        auto exp = along(-2.0);
        sx.back() = exp.first < refl.first ? exp : refl;
      } else if (refl.first < sx[dims - 1].first) {
        sx.back() = refl;
      } else {
        auto con = refl.first < sx.back().first ? along(-0.5) : along(0.5);
        if (con.first < std::min(refl.first, sx.back().first)) {
          sx.back() = con;
        } else {
          for (std::size_t v = 1; v <= dims; ++v) {
            for (std::size_t i = 0; i < dims; ++i)
              sx[v].second[i] = sx[0].second[i] + 0.5 * (sx[v].second[i] - sx[0].second[i]);
            sx[v].first = cost(sx[v].second);
          }
        }
      }
    }
    for (const auto& v : sx)
      if (v.first < best.first) best = v;
  }
  // 3. Seeded local random search around the best point with a shrinking step
  //    (the cost surface is rugged: saturation and the deadzone inverse switch).
  for (int s = 0; s < o.samples / 2; ++s) {
    const double scale = 0.3 * std::pow(0.01, static_cast<double>(s) / (o.samples / 2));
    X x = best.second;
    for (std::size_t i = 0; i < dims; ++i) x[i] += scale * (hi[i] - lo[i]) * rng.gaussian();
    const double c = cost(x);
    if (c < best.first) best = {c, x};
  }
  TuneResult res;
  res.gains = gains_of(best.second);
  res.cost = tune_cost(o, res.gains, &res.discrete, &res.ode3);
  res.evaluations = evals + 1;
  return res;
}

}  // namespace lash
