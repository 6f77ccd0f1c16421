#pragma once
/// @file simulate.hpp
/// Open-loop simulation of a plant driven by a signal, with optional additive
/// Gaussian measurement noise on y. Not real-time safe (allocates the trace).
/// simulate_rows() keeps nothing: the plant runs in chunks of 4096 samples (Plant::run, the
/// same bits as step() per sample) and each sample of a chunk goes to a callback (memory O(1) in
/// the duration), which is how `lash simulate` writes its CSV.
#include <cstdint>
#include <functional>
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

/// Names of the columns of a simulation of `plant`: t, v, y, y_true, x1_<kind>, …
std::vector<std::string> simulation_columns(const Plant& plant);

/// One row of a simulation, in the order of simulation_columns().
using SimulationRowFn = std::function<void(std::span<const double> row)>;

/// simulate(plant, spec) without a trace: `row` gets every sample as it is produced; returns
/// the number of samples. Same bits as simulate(). Throws std::invalid_argument (before the first
/// row) for an invalid spec, and, should the output still overflow, at that sample (no row
/// holding inf or nan is ever passed on).
std::size_t simulate_rows(Plant& plant, const SimulationSpec& spec, const SimulationRowFn& row);

/// The input v(k) of a simulation, asked for in order k = 0, 1, … (e.g. read from a file).
using SimulationInputFn = std::function<double(std::size_t k)>;
/// The same with the input from `input` instead of spec.input (its duration, noise and seed are
/// used); the same bits as a spec.input giving the same values.
std::size_t simulate_rows(Plant& plant, const SimulationSpec& spec, const SimulationInputFn& input,
                          const SimulationRowFn& row);

/// A worst-case bound of the plant's output over n samples: |y(k)| ≤ gain·max|v| + offset for
/// every k < n, for any input v, propagated block by block (deadzone and deadband add their
/// widths, a first-order lag multiplies by max|b1|·Σ max|a1|^i, a difference by 2/T, a
/// saturation caps). gain may be inf (an unstable lag over many samples).
struct OutputBound {
  double gain = 1.0;
  double offset = 0.0;
  double at(double max_abs_input) const noexcept { return max_abs_input == 0.0 ? offset : gain * max_abs_input + offset; }
};
OutputBound output_bound(const Plant& plant, std::size_t n);

/// The bound on |y| that `lash simulate` requires of its options [y unit]: 1e300 leaves a margin
/// below DBL_MAX (1.8e308) for the added noise.
inline constexpr double kMaxSimulatedOutput = 1e300;

/// The largest max|v| for which output_bound(plant, n) stays ≤ kMaxSimulatedOutput (0 when even a
/// zero input can exceed it, inf when any finite input is safe).
double max_input_magnitude(const Plant& plant, std::size_t n);

/// Runs the plant from its zero state over a given input v (one sample per step, t_k = k·T),
/// adding Gaussian noise of `noise_variance` [y unit²] to y from noise_seed(seed).
/// The trace has the columns of simulate(plant, spec); the same v gives the same bits.
SimulationTrace simulate(Plant& plant, std::span<const double> v, double noise_variance = 0.0,
                         std::uint64_t seed = 1);

}  // namespace lash
