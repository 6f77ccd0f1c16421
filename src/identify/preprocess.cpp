#include "lash/identify/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lash {

Preprocessor::Preprocessor(const NoiseSettings& s, double dt_s)
    : identity_(s.filter_length == 1 && !s.filter_input && s.input_delay == 0 && s.dead_time == 0 &&
                s.derivative_filter_length == 1 &&
                s.align_delay == 0 && (s.derivative_prefilter_length == 0 || s.derivative_prefilter_length == 1)),
      filter_y_(s.filter_length > 1),
      filter_v_(s.filter_input && s.filter_length > 1),
      separate_pre_(s.derivative_prefilter_length != 0 && s.derivative_prefilter_length != s.filter_length),
      filter_p_(s.derivative_prefilter_length > 1),
      inv_dt_(1.0 / dt_s),
      inv_ddt_(1.0 / (static_cast<double>(s.derivative_filter_length) * dt_s)),
      s_(s),
      ma_y_(s.filter_length),
      ma_p_(s.derivative_prefilter_length == 0 ? 1 : s.derivative_prefilter_length),
      ma_vy_(s.filter_input && s.filter_length > 1 ? s.filter_length : 1),
      lag_v_(s.input_delay + s.align_delay + s.dead_time),
      lag_y_(s.align_delay),
      lag_d_(s.derivative_filter_length),
      dead_(s.dead_time) {
  if (!(std::isfinite(dt_s) && dt_s > 0.0)) throw std::invalid_argument("dt must be > 0");
  const std::size_t need = std::max({lag_v_, lag_y_, lag_d_}) + 1;
  while (cap_ < need) cap_ *= 2;
  mask_ = cap_ - 1;
  x_ring_ = separate_pre_ ? 2 * cap_ : cap_;
  raw_ring_ = 3 * cap_;
  hist_.assign((dead_ != 0 ? 4 : 3) * cap_, 0.0);
}

void Preprocessor::reset() noexcept {
  y_prev_ = 0.0;
  ma_y_.reset();
  ma_vy_.reset();
  ma_p_.reset();
  k_ = 0;
  for (auto& h : hist_) h = 0.0;
}

std::size_t Preprocessor::memory_samples() const noexcept {
  if (identity_) return 1;  // ẏ = (y − y_prev)/T
  const std::size_t m = filter_y_ ? s_.filter_length : 1;
  const std::size_t regression = std::max(m, filter_v_ ? s_.filter_length : 1) + s_.input_delay + s_.align_delay +
                                  s_.dead_time;
  const std::size_t pre = separate_pre_ ? (filter_p_ ? s_.derivative_prefilter_length : 1) : m;
  const std::size_t derivative = pre + 1 + (s_.derivative_filter_length > 1 ? s_.derivative_filter_length : 1);
  return std::max(regression, derivative);
}

double Preprocessor::output_delay_samples() const noexcept {
  return (filter_y_ ? ma_y_.delay_samples() : 0.0) + static_cast<double>(s_.align_delay);
}

}  // namespace lash
