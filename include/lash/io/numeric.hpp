#pragma once
/// @file numeric.hpp
/// Floating-point → integer conversions that are range-checked first. A static_cast of a
/// double that is not finite or does not fit the integer type is undefined behaviour (C++20
/// [conv.fpint]); std::llround of such a value returns an unspecified number. Every
/// conversion of a time, a count from an option or a raw value in lash goes through these.
/// Real-time safe (noexcept, no allocation) except steps_or_throw.
#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>

namespace lash {

/// 2^digits of T as a double: the first value above T's largest (exact for every integer type).
template <std::integral T>
constexpr double integer_end() noexcept {
  return std::ldexp(1.0, std::numeric_limits<T>::digits);
}

/// `x` (already integral, e.g. from std::round) as T when it is finite and T holds it.
template <std::integral T>
constexpr std::optional<T> integral_as(double x) noexcept {
  if (!(x >= static_cast<double>(std::numeric_limits<T>::min()) && x < integer_end<T>())) return std::nullopt;
  return static_cast<T>(x);
}

/// Nearest integer (halves away from zero, as std::llround) when it fits T.
template <std::integral T>
std::optional<T> round_to(double x) noexcept {
  return integral_as<T>(std::round(x));
}
/// Smallest integer ≥ x when it fits T.
template <std::integral T>
std::optional<T> ceil_to(double x) noexcept {
  return integral_as<T>(std::ceil(x));
}
/// Largest integer ≤ x when it fits T.
template <std::integral T>
std::optional<T> floor_to(double x) noexcept {
  return integral_as<T>(std::floor(x));
}
/// Nearest integer, clamped into [lo, hi]; NaN gives lo. For a value that only needs to stay
/// within a known range (a deadline, a count capped elsewhere).
template <std::integral T>
T round_clamped(double x, T lo, T hi) noexcept {
  if (!(x >= static_cast<double>(lo))) return lo;
  if (!(x < static_cast<double>(hi))) return hi;
  const auto r = round_to<T>(x);
  return r ? std::min(std::max(*r, lo), hi) : hi;
}

/// round(seconds / dt_s) samples, for a time a person gave (`field` names the option or key).
/// Throws std::invalid_argument naming `field` when the count is not finite, negative or above `max`.
std::size_t steps_or_throw(double seconds, double dt_s, const std::string& field,
                           std::size_t max = std::size_t{1} << 40);

}  // namespace lash
