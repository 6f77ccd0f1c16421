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
/// noisy measured levels).
///
/// StepMetricsAccumulator computes them sample by sample in O(1) memory (a run of any length
/// is scored as it is produced); step_metrics() over a whole trace is the same code.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace lash {

/// Why a figure of StepMetrics is not a number.
enum class FigureStatus : std::uint8_t {
  ok,           ///< the figure is a finite number
  not_reached,  ///< rise: the response never reached the rise level within the record
  not_settled,  ///< settling: still outside the band at the end of the record
  not_finite,   ///< the response itself had non-finite samples: no figure can be trusted
};
/// "ok", "not_reached", "not_settled", "not_finite".
const char* to_string(FigureStatus s) noexcept;

struct StepMetrics {
  double rise_s = 0.0;          ///< 90 % rise time [s]; NaN if never reached
  double settling_s = 0.0;      ///< 10 % settling time [s]; NaN if never settled
  double overshoot_pct = 0.0;   ///< peak overshoot [%]; NaN when the response was not finite
  double peak = 0.0;            ///< extreme value after the step [output unit]
  FigureStatus rise_status = FigureStatus::ok;
  FigureStatus settling_status = FigureStatus::ok;
  FigureStatus overshoot_status = FigureStatus::ok;
  std::size_t samples = 0;      ///< samples at or after the step that were scored
  std::size_t nonfinite = 0;    ///< of those, samples that were NaN or ±inf
  double record_s = 0.0;        ///< time from the step to the last scored sample [s]
  double first_nonfinite_s = 0.0;  ///< time of the first non-finite sample [s] (when nonfinite > 0)
};

/// The figures of StepMetrics, one sample at a time (t increasing). O(1) memory and time per
/// sample; samples before t_step_s are ignored. Not real-time code only because result() may throw.
class StepMetricsAccumulator {
 public:
  /// Throws std::invalid_argument if y0 == y1 (or either is not finite).
  StepMetricsAccumulator(double t_step_s, double y0, double y1, double rise_fraction = 0.9,
                         double settle_band = 0.1);
  void add(double t_s, double y) noexcept;
  /// Throws std::invalid_argument if no sample at or after the step was added.
  StepMetrics result() const;

 private:
  double t_step_, y0_, span_, rise_fraction_, band_;
  StepMetrics m_;
  bool have_first_ = false;
  double t_first_ = 0.0;
  double t_prev_ = 0.0, s_prev_ = 0.0;  // previous scored sample (rise interpolation)
  bool risen_ = false;
  double peak_s_;
  bool have_out_ = false, have_next_ = false;  // settling: last sample outside the band, and the one after it
  double t_out_ = 0.0, s_out_ = 0.0, t_next_ = 0.0, s_next_ = 0.0;
  double t_last_ = 0.0;
};

/// Metrics of samples (t[i], y[i]) with t[i] ≥ t_step_s (earlier samples ignored).
/// Throws std::invalid_argument if the sizes differ, y0 == y1 or there are no samples after the step.
StepMetrics step_metrics(const std::vector<double>& t_s, const std::vector<double>& y, double t_step_s, double y0,
                         double y1, double rise_fraction = 0.9, double settle_band = 0.1);

}  // namespace lash
