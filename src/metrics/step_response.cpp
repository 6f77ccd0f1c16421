#include "lash/metrics/step_response.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace lash {

const char* to_string(FigureStatus s) noexcept {
  switch (s) {
    case FigureStatus::ok: return "ok";
    case FigureStatus::not_reached: return "not_reached";
    case FigureStatus::not_settled: return "not_settled";
    case FigureStatus::not_finite: return "not_finite";
  }
  return "?";
}

StepMetricsAccumulator::StepMetricsAccumulator(double t_step_s, double y0, double y1, double rise_fraction,
                                               double settle_band)
    : t_step_(t_step_s),
      y0_(y0),
      span_(y1 - y0),
      rise_fraction_(rise_fraction),
      band_(settle_band),
      peak_s_(-std::numeric_limits<double>::infinity()) {
  if (!(y1 != y0)) throw std::invalid_argument("step_metrics: the step has zero height");
  if (!std::isfinite(span_)) throw std::invalid_argument("step_metrics: the step's levels must be finite");
  m_.rise_s = std::numeric_limits<double>::quiet_NaN();
}

void StepMetricsAccumulator::add(double t, double y) noexcept {
  if (t < t_step_) return;
  // Normalised response s = (y − y0)/(y1 − y0): rises from 0 towards 1.
  const double s = (y - y0_) / span_;
  ++m_.samples;
  if (!std::isfinite(s) && m_.nonfinite++ == 0) m_.first_nonfinite_s = t;
  if (!have_first_) {
    have_first_ = true;
    t_first_ = t;
    if (s >= rise_fraction_) {
      m_.rise_s = t - t_step_;
      risen_ = true;
    }
  } else if (!risen_ && s >= rise_fraction_) {
    const double f = (rise_fraction_ - s_prev_) / (s - s_prev_);
    m_.rise_s = t_prev_ + f * (t - t_prev_) - t_step_;
    risen_ = true;
  }
  if (s > peak_s_) {
    peak_s_ = s;
    m_.peak = y;
  }
  if (std::fabs(s - 1.0) > band_) {
    have_out_ = true;
    have_next_ = false;
    t_out_ = t;
    s_out_ = s;
  } else if (have_out_ && !have_next_) {
    have_next_ = true;
    t_next_ = t;
    s_next_ = s;
  }
  t_prev_ = t;
  s_prev_ = s;
  t_last_ = t;
}

StepMetrics StepMetricsAccumulator::result() const {
  if (!have_first_) throw std::invalid_argument("step_metrics: no samples after the step");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  StepMetrics m = m_;
  m.record_s = t_last_ - t_step_;
  m.overshoot_pct = std::max(0.0, (peak_s_ - 1.0) * 100.0);
  if (!have_out_) {
    m.settling_s = t_first_ - t_step_;
  } else if (!have_next_) {
    m.settling_s = nan;  // still outside at the end of the record
  } else {
    // Entered the band for good between the last sample outside and the next: interpolate the
    // crossing of the band edge on the side it came from (linear in s, also when the sample
    // jumps across 1).
    const double a = s_out_, b = s_next_;
    const double edge = a > 1.0 ? 1.0 + band_ : 1.0 - band_;
    const double f = (edge - a) / (b - a);
    m.settling_s = t_out_ + f * (t_next_ - t_out_) - t_step_;
  }
  if (m.nonfinite > 0) {
    // A NaN compares false everywhere: the figures above would silently skip it. None is reported.
    m.rise_s = m.settling_s = m.overshoot_pct = m.peak = nan;
    m.rise_status = m.settling_status = m.overshoot_status = FigureStatus::not_finite;
    return m;
  }
  if (std::isnan(m.rise_s)) m.rise_status = FigureStatus::not_reached;
  if (std::isnan(m.settling_s)) m.settling_status = FigureStatus::not_settled;
  return m;
}

StepMetrics step_metrics(const std::vector<double>& t_s, const std::vector<double>& y, double t_step_s, double y0,
                         double y1, double rise_fraction, double settle_band) {
  if (t_s.size() != y.size()) throw std::invalid_argument("step_metrics: t and y differ in length");
  StepMetricsAccumulator acc(t_step_s, y0, y1, rise_fraction, settle_band);
  for (std::size_t i = 0; i < t_s.size(); ++i) acc.add(t_s[i], y[i]);
  return acc.result();
}

}  // namespace lash
