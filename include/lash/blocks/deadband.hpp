#pragma once
/// @file deadband.hpp
/// Deadband / backlash (thesis eq. 5–6) with half-width d: after a reversal
/// the output holds until the input has travelled 2d. Simulink's Backlash
/// block is parametrised by the full width 2d; lash uses the half-width.
#include "lash/blocks/side.hpp"

namespace lash {

class Deadband {
 public:
  /// Half-widths per side (chosen by the sign of v(k−1)); throws
  /// std::invalid_argument unless both are finite and ≥ 0.
  explicit Deadband(PerSide<double> half_width);

  /// @see Eq. (5)–(6): out = in + d if in < out_prev − d; in − d if in > out_prev + d; else out_prev.
  double step(double in, Side side) noexcept {
    const double d = d_[side];
    if (in < out_ - d) out_ = in + d;
    else if (in > out_ + d) out_ = in - d;
    return out_;
  }
  double step(double in) noexcept { return step(in, Side::right); }
  void reset(double out0 = 0.0) noexcept { out_ = out0; }
  double output() const noexcept { return out_; }
  const PerSide<double>& half_width() const noexcept { return d_; }

 private:
  PerSide<double> d_;
  double out_ = 0.0;
};

}  // namespace lash
