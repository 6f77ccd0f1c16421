#include <cmath>
#include <stdexcept>
#include <string>

#include "lash/blocks.hpp"

namespace lash {
namespace {
void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}
bool finite(double x) { return std::isfinite(x); }
}  // namespace

Deadzone::Deadzone(DeadzoneParams p) : p_(p) {
  require(finite(p.left) && finite(p.right), "deadzone edges must be finite numbers");
  require(p.left <= p.right, "deadzone needs left <= right (c_l <= c_r)");
}

Deadband::Deadband(PerSide<double> d) : d_(d) {
  require(finite(d.left) && finite(d.right), "deadband half-width must be a finite number");
  require(d.left >= 0 && d.right >= 0, "deadband half-width must be >= 0");
}

DeadzoneInverseParams DeadzoneInverseParams::from_deadzone(double deadzone, double fraction) {
  DeadzoneInverseParams p;
  p.offset_right = p.offset_left = fraction * deadzone;
  return p;
}

void DeadzoneInverseParams::validate() const {
  require(finite(offset_right) && offset_right >= 0, "deadzone inverse offset_right (c_r) must be a finite number >= 0");
  require(finite(offset_left) && offset_left >= 0, "deadzone inverse offset_left (-c_l) must be a finite number >= 0");
  require(finite(slope_right) && slope_right > 0, "deadzone inverse slope_right must be a finite number > 0");
  require(finite(slope_left) && slope_left > 0, "deadzone inverse slope_left must be a finite number > 0");
  require(finite(smoothing) && smoothing >= 0, "deadzone inverse smoothing must be a finite number >= 0");
}

DeadzoneInverse::DeadzoneInverse(DeadzoneInverseParams p) : p_(p) { p.validate(); }

void BacklashInverseParams::validate() const {
  require(finite(right) && right >= 0, "backlash inverse right width must be a finite number >= 0");
  require(finite(left) && left >= 0, "backlash inverse left width must be a finite number >= 0");
  require(finite(smoothing) && smoothing >= 0, "backlash inverse smoothing must be a finite number >= 0");
}

BacklashInverse::BacklashInverse(BacklashInverseParams p) : p_(p), o_(p.right) { p.validate(); }

FirstOrderParams FirstOrderParams::from_continuous(double gain, double tau_s, double dt_s) {
  require(finite(gain), "gain must be finite");
  require(finite(tau_s) && tau_s > 0, "tau must be > 0");
  require(finite(dt_s) && dt_s > 0, "dt must be > 0");
  const double x = -dt_s / tau_s;
  return {-std::exp(x), -gain * std::expm1(x)};  // expm1: exact 1 − e^{−T/τ} for T ≪ τ
}

FirstOrder::FirstOrder(PerSide<FirstOrderParams> p) : p_(p) {
  for (Side s : {Side::right, Side::left})
    require(finite(p[s].a1) && finite(p[s].b1), std::string("linear ") + to_string(s) + " a1/b1 must be finite");
}

MovingAverage::MovingAverage(std::size_t length) {
  require(length >= 1, "moving average length must be >= 1");
  buf_.assign(2 * length, 0.0);
  inv_len_ = 1.0 / static_cast<double>(length);
  n_ = length;
}
void MovingAverage::reset() noexcept {
  for (auto& v : buf_) v = 0.0;
  pos_ = 0;
  head_ = 0.0;
}

MovingAveragePair::MovingAveragePair(std::size_t length) {
  require(length >= 1, "moving average length must be >= 1");
  buf_.assign(2 * length, v2{0.0, 0.0});
  inv_len_ = 1.0 / static_cast<double>(length);
  n_ = length;
}
void MovingAveragePair::reset() noexcept {
  for (auto& v : buf_) v = v2{0.0, 0.0};
  pos_ = 0;
  head_ = v2{0.0, 0.0};
}

BackwardDifference::BackwardDifference(double dt_s) {
  require(finite(dt_s) && dt_s > 0, "dt must be > 0");
  dt_ = dt_s;
}

Delay::Delay(std::size_t samples) { buf_.assign(samples, 0.0); }
void Delay::reset() noexcept {
  for (auto& v : buf_) v = 0.0;
  pos_ = 0;
}

Saturation::Saturation(double lower, double upper) : lo_(lower), hi_(upper) {
  require(!std::isnan(lower) && !std::isnan(upper), "saturation limits must be numbers");
  require(lower <= upper, "saturation needs lower <= upper");
}

}  // namespace lash
