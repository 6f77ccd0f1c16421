#pragma once
/// @file simulate.hpp
/// Open-loop simulation of a plant driven by a signal, with optional additive
/// Gaussian measurement noise on y. Not real-time safe (allocates the trace).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lash/plant/plant.hpp"
#include "lash/signals/signal.hpp"

namespace lash {

struct SimulationSpec {
  SignalSpec input;              ///< the plant input v
  double duration_s = 10.0;      ///< samples k = 0 … N−1 with N = round(duration/T)
  double noise_variance = 0.0;   ///< variance of the noise added to y [y unit²]
  std::uint64_t seed = 1;        ///< fixes the randomized input and the noise
};

/// Column-wise trace: t [s], v, y (measured, with noise), y_true (noise-free),
/// and the output of each block in chain order.
struct SimulationTrace {
  std::vector<std::string> names;          ///< "t", "v", "y", "y_true", "x1_deadzone", …
  std::vector<std::vector<double>> cols;   ///< cols[c][k]
  std::size_t samples() const noexcept { return cols.empty() ? 0 : cols[0].size(); }
  const std::vector<double>& col(const std::string& name) const;
};

/// Number of samples for a duration: round(duration / T); throws std::invalid_argument if < 1.
std::size_t sample_count(double duration_s, double dt_s);

/// Seed of the measurement noise derived from the run seed (independent of the input's stream).
std::uint64_t noise_seed(std::uint64_t seed) noexcept;

/// Runs the plant from its zero state (the plant is reset first).
SimulationTrace simulate(Plant& plant, const SimulationSpec& spec);

/// Runs the plant from its zero state over a given input v (one sample per step, t_k = k·T),
/// adding Gaussian noise of `noise_variance` [y unit²] to y from noise_seed(seed).
/// The trace has the columns of simulate(plant, spec); the same v gives the same bits.
SimulationTrace simulate(Plant& plant, std::span<const double> v, double noise_variance = 0.0,
                         std::uint64_t seed = 1);

}  // namespace lash
