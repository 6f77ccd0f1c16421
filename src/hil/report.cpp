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
