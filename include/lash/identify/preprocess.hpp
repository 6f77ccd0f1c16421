#pragma once
/// @file preprocess.hpp
/// Noise handling of docs/method.md §A5 / thesis §1.4.5, one sample at a time:
///   y_f = MA_M(y),  v_f = MA_M(v) (filter_input) or Delay_n(v),
///   ẏ  = MA_M2(BackwardDifference(MA_Mp(y)))       (eq. 26; var(ẏ) = 2 var(y)/T², eq. 33)
///        with Mp = derivative_prefilter_length (0: the regression filter M)
///   regression signals = Delay_align(v_f), Delay_align(y_f) so they line up with ẏ;
///   a plant dead time n delays the regression's v by n more and gives the free run v(k − n).
/// Storage is allocated at construction; step() is noexcept, O(1), allocation-free.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lash/blocks/moving_average.hpp"
#include "lash/identify/config.hpp"

namespace lash {

/// One conditioned sample.
struct Conditioned {
  double v;     ///< input for the regression [v unit]
  double y;     ///< output for the regression [y unit]
  double ydot;  ///< derivative used for switching [y unit/s]
  double vplant;  ///< the raw v delayed by the plant's dead time (the free run's input) [v unit]
};

class Preprocessor {
 public:
  /// Not real-time safe (allocates the filter windows).
  Preprocessor(const NoiseSettings& s, double dt_s);

  Conditioned step(double v, double y) noexcept {
    if (identity_) [[unlikely]] {
      const double d = (y - y_prev_) * inv_dt_;
      y_prev_ = y;
      return {v, y, d, v};
    }
    double yf = y, vf = v;
    if (filter_v_) ma_vy_.step(v, y, vf, yf);  // filter_v_ implies filter_y_ (the same length M)
    else if (filter_y_) yf = ma_y_.step(y);
    const double x = separate_pre_ ? (filter_p_ ? ma_p_.step(y) : y) : yf;  // the derivative's input
    const std::size_t k = k_++ & mask_;
    double* const h = hist_.data();
    h[k] = vf;
    h[cap_ + k] = yf;
    if (separate_pre_) h[2 * cap_ + k] = x;  // otherwise x = y_f, read from y_f's ring
    double vp = v;
    if (dead_ != 0) {  // the raw v's own ring: the free run reads v(k − dead_time)
      h[raw_ring_ + k] = v;
      vp = h[raw_ring_ + ((k - dead_) & mask_)];
    }
    // MA_M2 of the backward difference telescopes: (1/M2)·Σ_{j<M2} (x(k−j) − x(k−j−1))/T
    // = (x(k) − x(k−M2))/(M2·T), with x = 0 before the first sample as in every filter.
    const double d = (x - h[x_ring_ + ((k - lag_d_) & mask_)]) * inv_ddt_;
    return {h[(k - lag_v_) & mask_], h[cap_ + ((k - lag_y_) & mask_)], d, vp};
  }

  void reset() noexcept;
  /// Samples after reset() until every output depends on inputs since the reset only (the
  /// longest path through the filters, difference and delays): the warm-up after a gap.
  std::size_t memory_samples() const noexcept;
  /// Total delay of the regression output against the raw y [samples] (MA group delay + alignment).
  double output_delay_samples() const noexcept;

 private:
  bool identity_;
  bool filter_y_, filter_v_, separate_pre_, filter_p_;
  double inv_dt_;
  double inv_ddt_;  // 1/(M2·T): the derivative's moving average folded into the difference
  double y_prev_ = 0.0;
  NoiseSettings s_;
  MovingAverage ma_y_, ma_p_;
  MovingAveragePair ma_vy_;  // v and y together when both are filtered
  // One history ring per signal (v_f, y_f, derivative input), cap_ (a power of two) slots each:
  // the input and alignment delays and the derivative read from it.
  std::size_t cap_ = 1, mask_ = 0, x_ring_ = 0, raw_ring_ = 0;
  std::size_t lag_v_ = 0, lag_y_ = 0, lag_d_ = 1, dead_ = 0;
  std::uint64_t k_ = 0;
  std::vector<double> hist_;
};

/// Direction of motion from ẏ with a dead band (thesis §1.4.5): +1, −1 or 0.
constexpr int direction(double ydot, double threshold) noexcept {
  return ydot > threshold ? 1 : (ydot < -threshold ? -1 : 0);
}

}  // namespace lash
