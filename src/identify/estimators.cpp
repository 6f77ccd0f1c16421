#include "lash/identify/estimators.hpp"

#include "lash/io/numeric.hpp"

namespace lash {

namespace detail {
const EstimatorConfig& checked(const EstimatorConfig& cfg) {
  cfg.validate();
  return cfg;
}
std::uint64_t start_index(double s, double dt) noexcept {
  // A start beyond 2^64 samples is never reached.
  return ceil_to<std::uint64_t>(s / dt - 1e-9).value_or(std::numeric_limits<std::uint64_t>::max());
}
}  // namespace detail

EstimatorCore::EstimatorCore(const EstimatorConfig& c) : cfg(c), pre(c.noise, c.dt_s), warmup(detail::warmup_samples(c, pre)) {
  fit.k0 = detail::start_index(c.fit_start_s, c.dt_s);
  start = pre.memory_samples() + 1;  // the regressors use v(k−1), y(k−1)
}

}  // namespace lash
