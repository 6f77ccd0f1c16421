#pragma once
/// @file side.hpp
/// Which side of a piecewise block acts: chosen by the sign of the plant
/// input of the previous sample, v(k−1) ≥ 0 → right, v(k−1) < 0 → left
/// (docs/method.md §A1.3, thesis eq. 34).
#include <cstdint>

namespace lash {

enum class Side : std::uint8_t { right = 0, left = 1 };

/// @see Eq. (34): v ≥ 0 selects the right side.
constexpr Side side_of(double v) noexcept { return v >= 0.0 ? Side::right : Side::left; }

/// The other side.
constexpr Side opposite(Side s) noexcept { return s == Side::right ? Side::left : Side::right; }

constexpr const char* to_string(Side s) noexcept { return s == Side::right ? "right" : "left"; }

/// A value for each side.
template <class T>
struct PerSide {
  T right{};
  T left{};
  constexpr T& operator[](Side s) noexcept { return s == Side::right ? right : left; }
  constexpr const T& operator[](Side s) const noexcept { return s == Side::right ? right : left; }
  static constexpr PerSide both(const T& v) { return {v, v}; }
};

}  // namespace lash
