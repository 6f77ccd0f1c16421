#include "lash/hil/report.hpp"

#include <cmath>

namespace lash::hil {

std::optional<StepWindow> find_step(const std::vector<double>& r, double dt_s, double min_hold_s,
                                    double max_window_s) {
  std::size_t level_start = 0;
  for (std::size_t k = 1; k < r.size(); ++k) {
    if (r[k] == r[k - 1]) continue;
    const double held = static_cast<double>(k - level_start) * dt_s;
    if (held + 1e-12 >= min_hold_s) {
      StepWindow w;
      w.begin = k;
      w.t_step_s = static_cast<double>(k) * dt_s;
      w.y0 = r[k - 1];
      w.y1 = r[k];
      std::size_t e = k + 1;
      const auto max_n = static_cast<std::size_t>(std::llround(max_window_s / dt_s));
      while (e < r.size() && r[e] == r[k] && e - k < max_n) ++e;
      w.end = e;
      return w;
    }
    level_start = k;
  }
  return std::nullopt;
}

StepResponse step_response(const std::vector<double>& t, const std::vector<double>& y, double t_step, double y0,
                           double y1) {
  StepResponse r;
  const double span = y1 - y0;
  const double dir = span >= 0 ? 1.0 : -1.0;
  // Normalised progress z = (y − y0)/(y1 − y0): rise when z reaches 0.9, band |z − 1| ≤ 0.1.
  auto z = [&](std::size_t i) { return (y[i] - y0) / span; };
  r.rise_s = std::nan("");
  double last_exit = t_step;
  bool ever_out = false;
  double peak = 0.0;
  for (std::size_t i = 0; i < t.size() && i < y.size(); ++i) {
    if (t[i] < t_step) continue;
    const double zi = z(i);
    peak = std::max(peak, zi - 1.0);
    if (std::isnan(r.rise_s) && zi >= 0.9) {
      double tc = t[i];
      if (i > 0 && t[i - 1] >= t_step && z(i - 1) < 0.9) tc = t[i - 1] + (0.9 - z(i - 1)) / (zi - z(i - 1)) * (t[i] - t[i - 1]);
      r.rise_s = tc - t_step;
    }
    const bool out = std::abs(zi - 1.0) > 0.1;
    if (!out && i > 0 && t[i - 1] >= t_step && std::abs(z(i - 1) - 1.0) > 0.1) {
      // Entered the band between i−1 and i: interpolate the crossing of the band edge.
      const double zp = z(i - 1);
      const double edge = zp > 1.0 ? 1.1 : 0.9;
      last_exit = t[i - 1] + (edge - zp) / (zi - zp) * (t[i] - t[i - 1]);
      ever_out = true;
    } else if (out) {
      last_exit = t[i];
      ever_out = true;
    }
  }
  (void)dir;
  r.settling_s = ever_out ? last_exit - t_step : 0.0;
  r.overshoot_pct = 100.0 * peak;
  return r;
}

SimulationDiff compare_with_simulation(const std::vector<std::int64_t>& control_step,
                                       const std::vector<double>& measured_kPa, const std::vector<double>& current_mA,
                                       const std::vector<MasterStepLog>& simulated) {
  SimulationDiff d;
  // Index the simulation by control step.
  std::vector<const MasterStepLog*> by_m;
  for (const auto& s : simulated) {
    if (s.control_step < 0) continue;
    const auto m = static_cast<std::size_t>(s.control_step);
    if (by_m.size() <= m) by_m.resize(m + 1, nullptr);
    by_m[m] = &s;
  }
  for (std::size_t i = 0; i < control_step.size(); ++i) {
    if (control_step[i] < 0) continue;
    const auto m = static_cast<std::size_t>(control_step[i]);
    if (m >= by_m.size() || by_m[m] == nullptr) continue;
    ++d.compared;
    const double dp = std::abs(measured_kPa[i] - by_m[m]->measured_kPa);
    const double di = std::abs(current_mA[i] - by_m[m]->current_mA);
    if ((dp > 0 || di > 0) && !d.first_diff_step) d.first_diff_step = control_step[i];
    d.max_abs_diff_kPa = std::max(d.max_abs_diff_kPa, dp);
    d.max_abs_diff_mA = std::max(d.max_abs_diff_mA, di);
  }
  return d;
}

}  // namespace lash::hil
