#include "lash/metrics/step_response.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace lash {

StepMetrics step_metrics(const std::vector<double>& t_s, const std::vector<double>& y, double t_step_s, double y0,
                         double y1, double rise_fraction, double settle_band) {
  if (t_s.size() != y.size()) throw std::invalid_argument("step_metrics: t and y differ in length");
  if (!(y1 != y0)) throw std::invalid_argument("step_metrics: the step has zero height");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double span = y1 - y0;
  std::size_t first = 0;
  while (first < t_s.size() && t_s[first] < t_step_s) ++first;
  if (first >= t_s.size()) throw std::invalid_argument("step_metrics: no samples after the step");

  StepMetrics m;
  m.rise_s = nan;
  // Normalised response s = (y − y0)/(y1 − y0): rises from 0 towards 1.
  auto s = [&](std::size_t i) { return (y[i] - y0) / span; };
  for (std::size_t i = first; i < t_s.size(); ++i) {
    if (s(i) >= rise_fraction) {
      if (i == first) {
        m.rise_s = t_s[i] - t_step_s;
      } else {
        const double a = s(i - 1), b = s(i);
        const double f = (rise_fraction - a) / (b - a);
        m.rise_s = t_s[i - 1] + f * (t_s[i] - t_s[i - 1]) - t_step_s;
      }
      break;
    }
  }
  double peak_s = -std::numeric_limits<double>::infinity();
  for (std::size_t i = first; i < t_s.size(); ++i)
    if (s(i) > peak_s) {
      peak_s = s(i);
      m.peak = y[i];
    }
  m.overshoot_pct = std::max(0.0, (peak_s - 1.0) * 100.0);
  // Settling: last sample outside the band.
  std::size_t last_out = t_s.size();
  for (std::size_t i = t_s.size(); i-- > first;)
    if (std::fabs(s(i) - 1.0) > settle_band) {
      last_out = i;
      break;
    }
  if (last_out == t_s.size()) {
    m.settling_s = t_s[first] - t_step_s;
  } else if (last_out + 1 >= t_s.size()) {
    m.settling_s = nan;  // still outside at the end of the record
  } else {
    // Entered the band for good between last_out and last_out + 1: interpolate the crossing of
    // the band edge on the side it came from (linear in s, also when the sample jumps across 1).
    const std::size_t i = last_out + 1;
    const double a = s(i - 1), b = s(i);
    const double edge = a > 1.0 ? 1.0 + settle_band : 1.0 - settle_band;
    const double f = (edge - a) / (b - a);
    m.settling_s = t_s[i - 1] + f * (t_s[i] - t_s[i - 1]) - t_step_s;
  }
  return m;
}

}  // namespace lash
