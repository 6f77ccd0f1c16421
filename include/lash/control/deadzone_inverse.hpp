#pragma once
/// @file deadzone_inverse.hpp
/// Deadzone inverse (thesis paper 2, §2.7.2, Fig 2.12; Tao & Kokotović [27]):
/// the controller output is offset by a value slightly smaller than the
/// deadzone, in the direction of the command:
///   v = u + offset_right   if u > 0
///   v = u − offset_left    if u < 0
///   v = 0                  if u = 0
/// The thesis chose the offset 3 % below the identified deadzone,
/// offset = 0.97 · 288 mA, "to prevent unintended actuation should there be a
/// small error in the deadzone estimate". step() is noexcept and O(1).
namespace lash {

struct DeadzoneInverseParams {
  double offset_right = 0.0;  ///< added when the command is positive [output unit] (≥ 0)
  double offset_left = 0.0;   ///< subtracted when the command is negative [output unit] (≥ 0)

  /// The thesis's choice: fraction·deadzone on both sides (fraction 0.97, deadzone 288 mA).
  static DeadzoneInverseParams from_deadzone(double deadzone, double fraction = 0.97);
};

class DeadzoneInverse {
 public:
  /// Throws std::invalid_argument unless both offsets are finite and ≥ 0.
  explicit DeadzoneInverse(DeadzoneInverseParams p);

  double step(double u) const noexcept {
    if (u > 0.0) return u + p_.offset_right;
    if (u < 0.0) return u - p_.offset_left;
    return 0.0;
  }
  /// Replaces the offsets between samples (e.g. from an online deadzone estimate);
  /// negative or non-finite values are clamped to 0 so the step stays well defined.
  void set_offsets(double right, double left) noexcept {
    p_.offset_right = (right > 0.0) ? right : 0.0;
    p_.offset_left = (left > 0.0) ? left : 0.0;
  }
  void reset() noexcept {}
  const DeadzoneInverseParams& params() const noexcept { return p_; }

 private:
  DeadzoneInverseParams p_;
};

}  // namespace lash
