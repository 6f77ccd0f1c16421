#pragma once
/// @file signal.hpp
/// Excitation signals of docs/method.md §A2 (thesis eq. 37 and §1.6.2). Frequencies are
/// in rad/s; t_k = k·T is computed, never accumulated.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lash/signals/rng.hpp"

namespace lash {

enum class Waveform : std::uint8_t { sine, square, triangle, randomized, steps, constant };

/// Parses "sine", "square", "triangle", "randomized" (alias "random"), "steps", "constant";
/// throws std::invalid_argument for anything else.
Waveform parse_waveform(const std::string& name);
const char* to_string(Waveform w) noexcept;

/// One level of a step sequence: `value` from `t_s` on.
struct StepLevel {
  double t_s = 0.0;    ///< time the level starts [s]
  double value = 0.0;  ///< level [input unit]
};

struct SignalSpec {
  Waveform kind = Waveform::sine;
  double amplitude = 1.0;        ///< A [input unit] (sine/square/triangle; constant value)
  double frequency_rad_s = 1.0;  ///< ω [rad/s]
  double offset = 0.0;           ///< added to every sample [input unit]
  double phase_rad = 0.0;        ///< added to ωt [rad]
  /// randomized: variance of the Gaussian drawn every step [unit²] (thesis: 10000)
  double variance = 10000.0;
  double tau_s = 0.5;            ///< randomized: low-pass time constant [s] (thesis: 0.5)
  std::uint64_t seed = 1;        ///< randomized: seed of the Gaussian draws
  std::vector<StepLevel> steps;  ///< steps: levels in increasing time; 0 before the first
};

/// The largest |value| the signal can take (before any check of its parameters): sine, square,
/// triangle |A| + |offset|; constant |A + offset|; steps max|value| + |offset|; randomized
/// |offset| + 12.1·√variance (the polar method's |g| ≤ √(−2 ln s) ≤ 12.01 for its smallest
/// s = 2⁻¹⁰⁴, and the low-pass is a convex combination). NaN when a parameter is NaN.
double max_abs_value(const SignalSpec& spec) noexcept;


/// Generates a signal sample by sample. Not copyable state is cheap; next() is noexcept O(1)
/// (step sequences advance a cursor, so their cost is amortised O(1)).
class Signal {
 public:
  /// Throws std::invalid_argument for a non-finite or non-positive parameter where one is needed.
  Signal(SignalSpec spec, double dt_s);
  /// Value at t_k = k·T for the next k (starting at k = 0).
  double next() noexcept;
  std::int64_t index() const noexcept { return k_; }
  const SignalSpec& spec() const noexcept { return spec_; }

 private:
  SignalSpec spec_;
  double dt_s_;
  std::int64_t k_ = 0;
  std::size_t step_pos_ = 0;
  double lp_ = 0.0;   // randomized: low-pass state
  double lp_a_ = 0.0; // randomized: exp(−T/τ)
  double lp_sigma_ = 0.0;
  Rng rng_;
};

}  // namespace lash
