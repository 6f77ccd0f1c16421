#pragma once
/// @file step_fit.hpp
/// Offline step-test identification of the pilot valve (docs/method.md §B6, thesis paper 2
/// §2.7.1, Fig 2.8–2.10): from open-loop stepped-current data
///  1. split the record into segments of constant current;
///  2. steady part of a segment = samples later than `settle_taus`·τ after its
///     start (first pass: its second half; τ from step 5 then refines it);
///  3. bias = mean steady pressure of the zero-current segments;
///  4. fit a line to the steady (current, pressure − bias) points above the
///     deadzone: gain = slope, deadzone = x-intercept (points whose current is
///     not above the current x-intercept are dropped and the line refitted until
///     the set stops changing);
///  5. τ: one time constant for all transients, least squares of
///     p(t) = p_f + (p_0 − p_f)·exp(−(t − t_step)/τ) with p_0, p_f the steady
///     means of the adjacent segments (golden-section search on log τ);
///  6. σ: pooled standard deviation of the steady samples about their segment means.
/// Not real-time code.
#include <cstddef>
#include <vector>

namespace lash {

struct StepFitOptions {
  double current_tolerance_mA = 0.5;  ///< a change larger than this starts a new segment
  double zero_current_mA = 1.0;       ///< |current| ≤ this counts as zero (bias segments)
  double settle_taus = 8.0;           ///< steady part starts this many τ after a step (e^{−8} ≈ 3e−4 of the jump left)
  std::size_t min_steady_samples = 5; ///< shorter steady parts are ignored
};

struct StepSegment {
  std::size_t begin = 0, end = 0;        ///< rows [begin, end)
  std::size_t steady_begin = 0;          ///< first steady row
  double current_mA = 0.0;
  double mean_kPa = 0.0;                 ///< mean of the steady rows
  double std_kPa = 0.0;                  ///< standard deviation of the steady rows
  bool on_line = false;                  ///< used for the gain/deadzone line
  bool transient_used = false;           ///< its leading transient entered the τ fit
};

struct StepFit {
  double bias_kPa = 0.0;
  double deadzone_mA = 0.0;       ///< x-intercept
  double gain_kPa_per_mA = 0.0;   ///< slope
  double tau_s = 0.0;
  double noise_sigma_kPa = 0.0;
  std::size_t line_points = 0;
  std::size_t transients = 0;
  std::vector<StepSegment> segments;
};

/// Throws std::invalid_argument (with a reason) when the record cannot be fitted:
/// sizes differ, fewer than 2 rows, time not increasing, no zero-current steady
/// segment, fewer than 2 steady points above the deadzone, or no usable transient.
StepFit fit_steps(const std::vector<double>& t_s, const std::vector<double>& current_mA,
                  const std::vector<double>& pressure_kPa, const StepFitOptions& options = {});

}  // namespace lash
