#include "lash/plant/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <variant>

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
  SimulationTrace tr;
  tr.names = simulation_columns(plant);
  tr.cols.resize(tr.names.size());
  if (std::isfinite(spec.noise_variance) && spec.noise_variance >= 0) {  // else simulate_rows says why
    const std::size_t n = sample_count(spec.duration_s, plant.dt_s());
    for (auto& c : tr.cols) c.reserve(n);
  }
  simulate_rows(plant, spec, [&](std::span<const double> r) {
    for (std::size_t c = 0; c < r.size(); ++c) tr.cols[c].push_back(r[c]);
  });
  return tr;
}

std::vector<std::string> simulation_columns(const Plant& plant) {
  std::vector<std::string> names = {"t", "v", "y", "y_true"};
  for (std::size_t i = 0; i < plant.blocks().size(); ++i)
    names.push_back("x" + std::to_string(i + 1) + "_" + block_kind(plant.blocks()[i]));
  return names;
}

namespace {

// Samples per Plant::run: the plant's state stays in registers over a chunk, and memory stays
// bounded (a chunk of inputs, outputs and block outputs, whatever the duration).
constexpr std::size_t kRunChunk = 4096;

// Runs the plant over n samples chunk by chunk: input(k) gives v(k) (k in order), then each sample
// of the chunk goes to put(k, v, y, x) in order of k, x the blocks' outputs. The same bits as
// step() per sample (Plant::run).
template <class Input, class Put>
void run_chunked(Plant& plant, std::size_t n, Input input, Put put) {
  if (n == 0) return;
  const std::size_t nb = plant.blocks().size();
  const std::size_t c = std::min(n, kRunChunk);
  std::vector<double> v(c), y(c), x(c * nb);
  for (std::size_t k0 = 0; k0 < n; k0 += c) {
    const std::size_t m = std::min(c, n - k0);
    for (std::size_t i = 0; i < m; ++i) v[i] = input(k0 + i);
    plant.run(std::span(v).first(m), std::span(y).first(m), std::span(x).first(m * nb));
    for (std::size_t i = 0; i < m; ++i) put(k0 + i, v[i], y[i], x.data() + i * nb);
  }
}

// One sample into row[]: t, v, y (+ noise), y_true, the nb blocks' outputs x[].
inline void put_row(GaussianNoise& noise, std::size_t k, double v, double y, const double* x, std::size_t nb,
                    double dt, double* row) {
  // A finite input must give a finite output: an overflow (an amplitude of 1e308 through a
  // gain) is refused, never written as inf (a non-finite input passes through as given).
  if (!std::isfinite(y) && std::isfinite(v)) [[unlikely]]
    throw std::invalid_argument(fmt::format("the plant's output overflows at sample {} (t = {} s) for the input {}: "
                                            "reduce the input's amplitude or the plant's gains",
                                            k, static_cast<double>(k) * dt, v));
  row[0] = static_cast<double>(k) * dt;
  row[1] = v;
  row[2] = y + noise.step();
  row[3] = y;
  for (std::size_t i = 0; i < nb; ++i) row[4 + i] = x[i];
}

}  // namespace

namespace {
// simulate_rows over any input(k) (a Signal's next(), inlined; or a caller's function).
template <class Input>
std::size_t simulate_rows_of(Plant& plant, const SimulationSpec& spec, Input input, const SimulationRowFn& row) {
  if (!(std::isfinite(spec.noise_variance) && spec.noise_variance >= 0))
    throw std::invalid_argument("noise variance must be >= 0");
  const std::size_t n = sample_count(spec.duration_s, plant.dt_s());
  GaussianNoise noise(spec.noise_variance, noise_seed(spec.seed));
  plant.reset();
  const std::size_t nb = plant.blocks().size();
  std::vector<double> r(4 + nb);
  const double dt = plant.dt_s();
  run_chunked(
      plant, n, input,
      [&](std::size_t k, double v, double y, const double* x) {
        put_row(noise, k, v, y, x, nb, dt, r.data());
        row(r);
      });
  return n;
}
}  // namespace

std::size_t simulate_rows(Plant& plant, const SimulationSpec& spec, const SimulationRowFn& row) {
  SignalSpec in = spec.input;
  in.seed = spec.seed;
  Signal sig(in, plant.dt_s());
  return simulate_rows_of(plant, spec, [&sig](std::size_t) { return sig.next(); }, row);
}

std::size_t simulate_rows(Plant& plant, const SimulationSpec& spec, const SimulationInputFn& input,
                          const SimulationRowFn& row) {
  return simulate_rows_of(plant, spec, std::cref(input), row);
}

SimulationTrace simulate(Plant& plant, std::span<const double> v, double noise_variance, std::uint64_t seed) {
  if (!(std::isfinite(noise_variance) && noise_variance >= 0)) throw std::invalid_argument("noise variance must be >= 0");
  const double dt = plant.dt_s();
  const std::size_t n = v.size();
  GaussianNoise noise(noise_variance, noise_seed(seed));
  plant.reset();

  SimulationTrace tr;
  tr.names = simulation_columns(plant);
  tr.cols.assign(tr.names.size(), std::vector<double>(n));
  std::vector<double> r(tr.names.size());
  const std::size_t nb = plant.blocks().size();
  run_chunked(
      plant, n, [&](std::size_t k) { return v[k]; },
      [&](std::size_t k, double vk, double y, const double* x) {
        put_row(noise, k, vk, y, x, nb, dt, r.data());
        for (std::size_t c = 0; c < r.size(); ++c) tr.cols[c][k] = r[c];
      });
  return tr;
}

namespace {

struct Bound {
  double gain, offset;
};

// Σ_{i<n} A^i: the largest amplification of a first-order lag |w(k)| ≤ A|w(k−1)| + B·max|u|.
double geometric_sum(double A, std::size_t n) {
  const double nd = static_cast<double>(n);
  if (A == 1.0) return nd;
  if (A < 1.0) return std::min(nd, (1.0 - std::pow(A, nd)) / (1.0 - A));
  return (std::pow(A, nd) - 1.0) / (A - 1.0);  // may be inf
}

// a·g with 0·inf = 0 (a zero bound stays zero through any amplification).
double mul(double a, double g) { return a == 0.0 || g == 0.0 ? 0.0 : a * g; }

}  // namespace

OutputBound output_bound(const Plant& plant, std::size_t n) {
  Bound b{1.0, 0.0};
  for (const Block& blk : plant.blocks()) {
    std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, Deadzone>) {
            b.offset += std::max(std::fabs(x.params().left), std::fabs(x.params().right));
          } else if constexpr (std::is_same_v<T, Deadband>) {
            b.offset += std::max(std::fabs(x.half_width().left), std::fabs(x.half_width().right));
          } else if constexpr (std::is_same_v<T, FirstOrder>) {
            const auto& p = x.params();
            const double A = std::max(std::fabs(p.left.a1), std::fabs(p.right.a1));
            const double B = std::max(std::fabs(p.left.b1), std::fabs(p.right.b1));
            const double g = B * geometric_sum(A, n);
            b.gain = mul(b.gain, g);
            b.offset = mul(b.offset, g);
          } else if constexpr (std::is_same_v<T, BackwardDifference>) {
            b.gain = mul(b.gain, 2.0 / x.dt_s());
            b.offset = mul(b.offset, 2.0 / x.dt_s());
          } else if constexpr (std::is_same_v<T, Saturation>) {
            b.gain = 0.0;
            b.offset = std::max(std::fabs(x.lower()), std::fabs(x.upper()));
          }
          // MovingAverage and Delay: |out| ≤ max|in|.
        },
        blk);
  }
  return {b.gain, b.offset};
}

double max_input_magnitude(const Plant& plant, std::size_t n) {
  const OutputBound b = output_bound(plant, n);
  if (!(b.offset <= kMaxSimulatedOutput)) return 0.0;
  if (b.gain == 0.0) return std::numeric_limits<double>::infinity();
  const double m = (kMaxSimulatedOutput - b.offset) / b.gain;
  return std::isfinite(m) ? m : std::numeric_limits<double>::infinity();
}

}  // namespace lash
