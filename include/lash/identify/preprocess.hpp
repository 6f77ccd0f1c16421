#pragma once
/// @file preprocess.hpp
/// Noise handling of SPEC A5 / thesis §1.4.5, one sample at a time:
///   y_f = MA_M(y),  v_f = MA_M(v) (filter_input) or Delay_n(v),
///   ẏ  = MA_M2(BackwardDifference(MA_Mp(y)))       (eq. 26; var(ẏ) = 2 var(y)/T², eq. 33)
///        with Mp = derivative_prefilter_length (0: the regression filter M)
///   regression signals = Delay_align(v_f), Delay_align(y_f) so they line up with ẏ.
/// Storage is allocated at construction; step() is noexcept, O(1), allocation-free.
#include <cstddef>

#include "lash/blocks/delay.hpp"
#include "lash/blocks/difference.hpp"
#include "lash/blocks/moving_average.hpp"
#include "lash/identify/config.hpp"

namespace lash {

/// One conditioned sample.
struct Conditioned {
  double v;     ///< input for the regression [v unit]
  double y;     ///< output for the regression [y unit]
  double ydot;  ///< derivative used for switching [y unit/s]
};

class Preprocessor {
 public:
  /// Not real-time safe (allocates the filter windows).
  Preprocessor(const NoiseSettings& s, double dt_s);

  Conditioned step(double v, double y) noexcept {
    if (identity_) {
      const double d = (y - y_prev_) * inv_dt_;
      y_prev_ = y;
      return {v, y, d};
    }
    const double yf = filter_y_ ? ma_y_.step(y) : y;
    double vf = filter_v_ ? ma_v_.step(v) : v;
    vf = delay_v_.step(vf);
    double d = diff_.step(separate_pre_ ? (filter_p_ ? ma_p_.step(y) : y) : yf);
    if (filter_d_) d = ma_d_.step(d);
    return {align_v_.step(vf), align_y_.step(yf), d};
  }

  void reset() noexcept;
  /// Samples after reset() until every output depends on inputs since the reset only (the
  /// longest path through the filters, difference and delays): the warm-up after a gap.
  std::size_t memory_samples() const noexcept;
  /// Total delay of the regression output against the raw y [samples] (MA group delay + alignment).
  double output_delay_samples() const noexcept;

 private:
  bool identity_;
  bool filter_y_, filter_v_, filter_d_, separate_pre_, filter_p_;
  double inv_dt_;
  double y_prev_ = 0.0;
  NoiseSettings s_;
  MovingAverage ma_y_, ma_v_, ma_d_, ma_p_;
  BackwardDifference diff_;
  Delay delay_v_, align_v_, align_y_;
};

/// Direction of motion from ẏ with a dead band (thesis §1.4.5): +1, −1 or 0.
constexpr int direction(double ydot, double threshold) noexcept {
  return ydot > threshold ? 1 : (ydot < -threshold ? -1 : 0);
}

}  // namespace lash
