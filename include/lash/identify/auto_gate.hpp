#pragma once
/// @file auto_gate.hpp
/// Innovation gate for isolated outliers on the measured output (docs/identification.md,
/// "Outliers"). A sample whose innovation against the one-step extrapolation of the accepted
/// samples exceeds `gate` times a robust running scale of the innovation is replaced by that
/// extrapolation and counted. The scale is a clipped exponentially weighted mean of |innovation|
/// (the clip at `gate`·scale keeps an outlier out of its own yardstick; a Huber-type M-estimate
/// of scale, Huber 1981 §5; gating as in Pearson, "Outliers in process modeling and
/// identification", IEEE TCST 10(1), 2002). Never two samples in a row are replaced: a true
/// step of the output (a square-wave input) is confirmed by the sample after it and passes,
/// costing one replaced sample; an isolated outlier is not confirmed.
///
/// step() is noexcept, O(1) and allocation-free (usable on the sample path).
#include <cmath>
#include <cstdint>

namespace lash {

struct OutlierGateConfig {
  double gate = 12.0;            ///< threshold in units of the running innovation scale; 0 = off
  double alpha = 0.01;           ///< weight of the newest |innovation| in the scale (memory ≈ 1/alpha samples)
  std::uint32_t warmup = 50;     ///< samples before the gate may act (the scale settles)
};

class OutlierGate {
 public:
  explicit OutlierGate(const OutlierGateConfig& c = {}) noexcept : c_(c) {}

  /// Returns y, or its extrapolation when y is an isolated outlier. Non-finite y passes unchanged
  /// (the estimators skip and count it).
  double step(double y) noexcept {
    if (!std::isfinite(y)) [[unlikely]] return y;
    if (n_ < 2) [[unlikely]] {
      y1_ = y;
      ++n_;
      return y;
    }
    const double pred = y1_;  // local-level prediction (a slope term doubles the noise gain)
    const double ae = std::fabs(y - pred);
    const bool warm = n_ >= c_.warmup;
    const double bound = c_.gate * scale_;  // finite while scale_ is; a NaN compares false below
    if (warm && !held_ && c_.gate > 0.0 && scale_ > 0.0 && ae > bound) [[unlikely]] {
      held_ = true;
      ++rejected_;
      return pred;  // y1_ stays: the next sample is compared with the last accepted one
    }
    held_ = false;
    // the scale follows min(|e|, bound) once warm (as std::fmin: ae is never NaN here)
    const double clip = warm && scale_ > 0.0 && bound < ae ? bound : ae;
    const double a = warm ? c_.alpha : 1.0 / static_cast<double>(n_);
    scale_ += a * (clip - scale_);
    ++n_;
    y1_ = y;
    return y;
  }

  std::uint64_t rejected() const noexcept { return rejected_; }
  double scale() const noexcept { return scale_; }

 private:
  OutlierGateConfig c_;
  double y1_ = 0.0, scale_ = 0.0;
  std::uint64_t n_ = 0, rejected_ = 0;
  bool held_ = false;
};

}  // namespace lash
