#pragma once
/// @file fit.hpp
/// How well a simulated output follows a measured one (docs/method.md §A6).
///
/// NRMSE = sqrt(mean((y − y_sim)²)) / max|y| over a window, a fraction (0.05 = 5 %; reports
/// that a person reads show it ×100 as `nrmse_pct`). A non-finite y_sim counts as an infinite
/// error (a diverged free run is the worst fit, never a skipped sample). NaN when the window is
/// empty or y is identically 0 there (no scale).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>

namespace lash {

/// Running NRMSE: add samples one by one (noexcept, O(1), no allocation).
struct NrmseAccumulator {
  double sum_sq = 0.0;   ///< Σ (y − y_sim)²
  double max_abs = 0.0;  ///< max |y|
  std::size_t n = 0;     ///< samples added
  void add(double y, double ysim) noexcept {
    const double e = y - ysim;
    sum_sq += e * e;  // a non-finite error makes the sum inf or NaN; value() reads both as inf
    max_abs = std::max(max_abs, std::fabs(y));
    ++n;
  }
  /// The NRMSE of the samples added so far (a fraction); NaN when none or all y = 0.
  double value() const noexcept {
    if (n == 0 || max_abs == 0.0) return std::numeric_limits<double>::quiet_NaN();
    if (!std::isfinite(sum_sq)) return std::numeric_limits<double>::infinity();
    return std::sqrt(sum_sq / static_cast<double>(n)) / max_abs;
  }
};

/// NRMSE of y_sim against y over all samples (same lengths; extra samples of the longer are ignored).
double nrmse(std::span<const double> y, std::span<const double> ysim) noexcept;

/// NRMSE over the samples with t ∈ [t0_s, t1_s].
double nrmse(std::span<const double> t, std::span<const double> y, std::span<const double> ysim, double t0_s,
             double t1_s) noexcept;

/// Count per 1000 samples of |y − ŷ| > 3σ over t ∈ [t0, t1] (docs/method.md §A6); NaN if the window is empty.
/// A non-finite ŷ counts as outside.
double outside_3sigma_per_1000(std::span<const double> t, std::span<const double> y, std::span<const double> yhat,
                               double sigma, double t0_s, double t1_s) noexcept;

}  // namespace lash
