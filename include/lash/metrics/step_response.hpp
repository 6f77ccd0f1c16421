#pragma once
/// @file step_response.hpp
/// Step-response figures as the thesis reports them (paper 2, §2.7.2):
/// - 90 % rise time: time from the step until the response first reaches
///   y0 + 0.9·(y1 − y0) (linear interpolation between samples);
/// - 10 % settling time: time from the step until the response enters the band
///   |y − y1| ≤ 0.1·|y1 − y0| for good (the crossing of the band edge it last came
///   in through, interpolated linearly; NaN if still outside at the end);
/// - overshoot: max over the window of (y − y1)/(y1 − y0), in percent, ≥ 0.
/// y0 and y1 are the reference levels before and after the step (not the
/// noisy measured levels). Not real-time code (scans a trace).
#include <cstddef>
#include <vector>

namespace lash {

struct StepMetrics {
  double rise_s = 0.0;          ///< 90 % rise time [s]; NaN if never reached
  double settling_s = 0.0;      ///< 10 % settling time [s]; NaN if never settled
  double overshoot_pct = 0.0;   ///< peak overshoot [%]
  double peak = 0.0;            ///< extreme value after the step [output unit]
};

/// Metrics of samples (t[i], y[i]) with t[i] ≥ t_step_s (earlier samples ignored).
/// Throws std::invalid_argument if the sizes differ, y0 == y1 or there are no samples after the step.
StepMetrics step_metrics(const std::vector<double>& t_s, const std::vector<double>& y, double t_step_s, double y0,
                         double y1, double rise_fraction = 0.9, double settle_band = 0.1);

}  // namespace lash
