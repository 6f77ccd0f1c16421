#include "lash/io/numeric.hpp"

#include <stdexcept>

#include <fmt/core.h>

namespace lash {

std::size_t steps_or_throw(double seconds, double dt_s, const std::string& field, std::size_t max) {
  const double n = std::round(seconds / dt_s);
  const auto k = integral_as<std::size_t>(n);
  if (!k || *k > max)
    throw std::invalid_argument(fmt::format("{}: {} s at a step of {} s is {} steps; must be a finite number of 0 to {} steps",
                                            field, seconds, dt_s, n, max));
  return *k;
}

}  // namespace lash
