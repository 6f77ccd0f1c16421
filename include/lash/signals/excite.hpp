#pragma once
/// @file excite.hpp
/// An input signal that identifies the deadzone-deadband model (docs/method.md §A4) given only
/// rough bounds on its deadzone edges (`lash excite`, docs/excite.md). The design rule:
///  - it drives beyond each edge bound by `reach` (2×: the bounds are rough) in both directions,
///    reversing its direction beyond each edge many times (the switching estimator keys its
///    regressions by side *and* direction: every side needs samples moving up and moving down
///    beyond its edge);
///  - it is slow against the sample period, so a direction is held for many samples (the
///    default period is max(2π s, 1000·dt): the thesis's E1 input ω = 1 rad/s at T = 5 ms);
///  - it varies beyond the edges (not two levels), so b1 and the offset of each side separate.
/// Three kinds: `sine` (the default, the thesis's input), `multisine` (random-phase, 25 lines
/// log-spaced over [1/(4P), 1/P]), `prbs` (an amplitude-modulated PRBS: a maximal-length 9-bit
/// LFSR picks the side each hold of P/4, a uniform draw the level between 1.25× and 2× the bound).
/// What each identified in which time is measured in docs/excite.md. Not real-time code.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lash/signals/rng.hpp"

namespace lash {

enum class ExciteKind : std::uint8_t { sine, multisine, prbs };
/// "sine", "multisine", "prbs"; throws std::invalid_argument otherwise.
ExciteKind parse_excite_kind(std::string_view name);
const char* to_string(ExciteKind k) noexcept;

/// The longest signal excite() makes (samples).
inline constexpr std::size_t kExciteMaxSamples = 10'000'000;
/// The shortest: this many periods P (each gives one reversal beyond each edge per direction).
inline constexpr double kExciteMinPeriods = 4.0;

struct ExciteSpec {
  double edge_left = -1.0;    ///< rough bound on c_l (< 0) [input unit]
  double edge_right = 1.0;    ///< rough bound on c_r (> 0) [input unit]
  double dt_s = 0.005;        ///< sample period [s]
  double duration_s = 120.0;  ///< N = round(duration/dt) samples
  ExciteKind kind = ExciteKind::sine;
  std::uint64_t seed = 1;     ///< multisine phases, prbs register and levels
  double period_s = 0.0;      ///< P [s]; 0 = the default max(2π s, 1000·dt)
  double reach = 2.0;         ///< the signal's extremes are reach × the edge bounds
};

/// The period P excite() uses for `spec` [s].
double excite_period(const ExciteSpec& spec) noexcept;

/// What is wrong with a spec: the field ("edges", "dt", "duration", "period") and why.
struct ExciteProblem {
  std::string field;
  std::string message;
};
/// The first problem of `spec`, or nothing: edges finite with c_l < 0 < c_r; dt finite > 0;
/// period 0 or finite ≥ 20·dt; duration finite with kExciteMinPeriods·P ≤ duration and
/// round(duration/dt) ≤ kExciteMaxSamples.
std::optional<ExciteProblem> check_excite(const ExciteSpec& spec);

/// The samples v(k), k = 0 … N−1 at t_k = k·dt, one at a time (memory O(1) in N; the multisine's
/// scale is set in the constructor from its 5 % and 95 % quantiles, taken over every sample up
/// to kQuantileSamples samples and over every ⌈N/kQuantileSamples⌉-th beyond). Throws
/// std::invalid_argument (the message of check_excite) for a bad spec. Every value lies in
/// [reach·c_l, reach·c_r].
class Excitation {
 public:
  static constexpr std::size_t kQuantileSamples = std::size_t{1} << 16;
  explicit Excitation(const ExciteSpec& spec);
  std::size_t samples() const noexcept { return n_; }
  /// v(k) for the next k (k = 0, 1, …).
  double next() noexcept;

 private:
  static constexpr int kLines = 25;
  double raw(std::size_t k) const noexcept;  ///< the multisine's sum of lines at sample k

  ExciteSpec s_;
  std::size_t n_ = 0, k_ = 0;
  double lo_ = 0.0, hi_ = 0.0;
  double w_[kLines] = {}, phi_[kLines] = {};  ///< sine: w_[0]; multisine: the lines [rad/s], phases
  double mn_ = 0.0, span_ = 0.0;              ///< multisine: the 5 % quantile and the 95 % − 5 % span
  Rng rng_{1};                                ///< prbs: levels
  std::uint32_t reg_ = 1;                     ///< prbs: the LFSR
  std::size_t hold_ = 1;                      ///< prbs: samples per level
  double level_ = 0.0;
};

/// All the samples of Excitation(spec) in a vector (8 bytes a sample; `lash excite` streams them).
std::vector<double> excite(const ExciteSpec& spec);

/// A warning for a kind that did not identify the model in the measurements of docs/excite.md
/// (`lash excite` prints it), or nullptr.
const char* excite_warning(ExciteKind kind) noexcept;

}  // namespace lash
