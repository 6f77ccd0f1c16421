#pragma once
/// @file error.hpp
/// Relative error of an estimate against a known truth — one definition for the scenario
/// tables (E1/E2), the sweeps and the tests.
#include <cmath>
#include <limits>

namespace lash {

/// |estimate − truth| / |truth| (a fraction: 0.05 = 5 %). +∞ when the estimate or the truth is
/// not finite or the truth is 0 (no relative error exists): a missing estimate never looks good.
inline double relative_error(double estimate, double truth) noexcept {
  if (!std::isfinite(estimate) || !std::isfinite(truth) || truth == 0.0)
    return std::numeric_limits<double>::infinity();
  return std::fabs(estimate - truth) / std::fabs(truth);
}

/// 100 · relative_error [%]; NaN when the estimate is not finite (not identified: nothing to
/// compare, printed as "-" in the tables).
inline double error_percent(double estimate, double truth) noexcept {
  if (!std::isfinite(estimate)) return std::numeric_limits<double>::quiet_NaN();
  return 100.0 * relative_error(estimate, truth);
}

}  // namespace lash
