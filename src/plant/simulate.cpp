#include "lash/plant/simulate.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "lash/signals/rng.hpp"

namespace lash {

const std::vector<double>& SimulationTrace::col(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return cols[i];
  throw std::out_of_range("no column " + name);
}

std::size_t sample_count(double duration_s, double dt_s) {
  if (!(std::isfinite(duration_s) && duration_s > 0)) throw std::invalid_argument("duration must be > 0 [s]");
  if (!(std::isfinite(dt_s) && dt_s > 0)) throw std::invalid_argument("dt must be > 0 [s]");
  const double n = std::round(duration_s / dt_s);
  if (n < 1) throw std::invalid_argument("duration is shorter than one sample");
  if (n > 1e9) throw std::invalid_argument("more than 1e9 samples requested");
  return static_cast<std::size_t>(n);
}

std::uint64_t noise_seed(std::uint64_t seed) noexcept { return seed ^ 0x6c617368'6e6f6973ULL; }

SimulationTrace simulate(Plant& plant, const SimulationSpec& spec) {
  if (!(std::isfinite(spec.noise_variance) && spec.noise_variance >= 0))
    throw std::invalid_argument("noise variance must be >= 0");
  const std::size_t n = sample_count(spec.duration_s, plant.dt_s());
  SignalSpec in = spec.input;
  in.seed = spec.seed;
  Signal sig(in, plant.dt_s());
  std::vector<double> v(n);
  for (auto& x : v) x = sig.next();
  return simulate(plant, v, spec.noise_variance, spec.seed);
}

SimulationTrace simulate(Plant& plant, std::span<const double> v, double noise_variance, std::uint64_t seed) {
  if (!(std::isfinite(noise_variance) && noise_variance >= 0)) throw std::invalid_argument("noise variance must be >= 0");
  const double dt = plant.dt_s();
  const std::size_t n = v.size();
  GaussianNoise noise(noise_variance, noise_seed(seed));
  plant.reset();

  SimulationTrace tr;
  tr.names = {"t", "v", "y", "y_true"};
  for (std::size_t i = 0; i < plant.blocks().size(); ++i)
    tr.names.push_back("x" + std::to_string(i + 1) + "_" + block_kind(plant.blocks()[i]));
  tr.cols.assign(tr.names.size(), std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    const double y = plant.step(v[k]);
    // A finite input must give a finite output: an overflow (an amplitude of 1e308 through a
    // gain) is refused, never written as inf (a non-finite input passes through as given).
    if (!std::isfinite(y) && std::isfinite(v[k])) [[unlikely]]
      throw std::invalid_argument(fmt::format("the plant's output overflows at sample {} (t = {} s) for the input {}: "
                                              "reduce the input's amplitude or the plant's gains",
                                              k, static_cast<double>(k) * dt, v[k]));
    tr.cols[0][k] = static_cast<double>(k) * dt;
    tr.cols[1][k] = v[k];
    tr.cols[2][k] = y + noise.step();
    tr.cols[3][k] = y;
    const auto s = plant.signals();
    for (std::size_t i = 0; i < s.size(); ++i) tr.cols[4 + i][k] = s[i];
  }
  return tr;
}

}  // namespace lash
