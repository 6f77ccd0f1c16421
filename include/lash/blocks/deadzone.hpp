#pragma once
/// @file deadzone.hpp
/// Deadzone (thesis eq. 1): a band of inputs [c_l, c_r] that gives 0 output.
#include "lash/blocks/side.hpp"

namespace lash {

struct DeadzoneParams {
  double left = 0.0;   ///< c_l, lower edge of the band [input unit]
  double right = 0.0;  ///< c_r, upper edge of the band [input unit], c_l ≤ c_r
};

class Deadzone {
 public:
  /// Throws std::invalid_argument unless both edges are finite and c_l ≤ c_r.
  explicit Deadzone(DeadzoneParams p);

  /// @see Eq. (1): in − c_l below the band, 0 inside, in − c_r above. Stateless.
  double step(double in) const noexcept {
    if (in > p_.right) return in - p_.right;
    if (in < p_.left) return in - p_.left;
    return 0.0;
  }
  void reset() noexcept {}
  const DeadzoneParams& params() const noexcept { return p_; }

 private:
  DeadzoneParams p_;
};

}  // namespace lash
