#include "lash/metrics/fit.hpp"

namespace lash {

double nrmse(std::span<const double> y, std::span<const double> ysim) noexcept {
  NrmseAccumulator acc;
  const std::size_t n = std::min(y.size(), ysim.size());
  for (std::size_t k = 0; k < n; ++k) acc.add(y[k], ysim[k]);
  return acc.value();
}

double nrmse(std::span<const double> t, std::span<const double> y, std::span<const double> ysim, double t0_s,
             double t1_s) noexcept {
  NrmseAccumulator acc;
  const std::size_t n = std::min({t.size(), y.size(), ysim.size()});
  for (std::size_t k = 0; k < n; ++k)
    if (t[k] >= t0_s && t[k] <= t1_s) acc.add(y[k], ysim[k]);
  return acc.value();
}

double outside_3sigma_per_1000(std::span<const double> t, std::span<const double> y, std::span<const double> yhat,
                               double sigma, double t0_s, double t1_s) noexcept {
  std::size_t n = 0, out = 0;
  const std::size_t m = std::min({t.size(), y.size(), yhat.size()});
  for (std::size_t k = 0; k < m; ++k) {
    if (t[k] < t0_s || t[k] > t1_s) continue;
    ++n;
    if (!(std::fabs(y[k] - yhat[k]) <= 3.0 * sigma)) ++out;
  }
  return n == 0 ? std::numeric_limits<double>::quiet_NaN() : 1000.0 * static_cast<double>(out) / static_cast<double>(n);
}

}  // namespace lash
