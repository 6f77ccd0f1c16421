#pragma once
/// @file adaptive_compensator.hpp
/// Adaptive inverses: an online estimator of SPEC A4 runs inside the controller at the sample
/// rate on closed-loop data, and its parameters reach the inverse only through safeguards
/// (docs/compensation.md):
///  - **verdict**: a side's estimate is used only while the estimator's verdict says that side
///    is identified (`params(s).identified`, the update-time checks 1–5 of identify/verdict.hpp:
///    updated, excited, stable, physical, edge inside the guesses), while the command varied
///    enough on that side (min_excitation_ratio), and only if it lies within
///    [min_ratio, max_ratio] × the nominal value;
///  - **settle**: the verdict must have held for `settle_s` before its values are used;
///  - **dead band**: the inverse starts to move only when the estimate differs from it by
///    more than `tolerance_ratio` × nominal (then it follows until it has caught up);
///  - **rate limit**: the inverse's parameter moves towards the estimate by at most
///    `rate_limit_per_s`·T per sample (a jump in the estimate becomes a ramp);
///  - **hold**: when the verdict is lost the last adapted value is held for `hold_s`, then
///    the parameter returns (rate-limited) to the nominal value — the fixed inverse.
/// Optional excitation: a square-wave dither of amplitude A and period P added to the desired
/// output u before the inverse (closed-loop data at a constant set point hold v constant, and
/// the estimator then refuses to identify: b1 and the offset are inseparable).
///
/// Adaptation law in one line, per parameter θ (edge c_r, c_l or deadband d):
///   θ(k) = θ(k−1) + clamp(θ*(k) − θ(k−1), −ρT, ρT),   θ* = θ̂ if valid for settle_s,
///          θ* = θ(k−1) within hold_s of the last valid sample, θ* = θ_nominal after that.
/// Real time: command() and observe() are noexcept, O(1) and allocation-free.
#include <cstdint>

#include "lash/blocks/backlash_inverse.hpp"
#include "lash/blocks/deadzone_inverse.hpp"
#include "lash/identify/estimators.hpp"

namespace lash {

/// none: no inverse; fixed: the nominal inverse; adaptive: nominal, adapted online.
enum class CompensationMode : std::uint8_t { none, fixed, adaptive };
/// "none" | "fixed" | "adaptive"; throws std::invalid_argument otherwise.
CompensationMode parse_compensation_mode(const char* text);
const char* to_string(CompensationMode m) noexcept;

struct AdaptationSettings {
  double rate_limit_per_s = 100.0;  ///< ρ: max change of an inverse parameter [parameter unit/s]
  double settle_s = 0.5;            ///< the verdict must hold this long before its values are used [s]
  double hold_s = 2.0;              ///< adapted values held this long after the verdict is lost [s]
  double min_ratio = 0.25;          ///< plausible estimates ≥ min_ratio × nominal [-]
  double max_ratio = 4.0;           ///< plausible estimates ≤ max_ratio × nominal [-]
  double dither_amplitude = 0.0;    ///< A: square-wave dither on u [unit of u]; 0 = off
  double dither_period_s = 0.1;     ///< P: dither period [s] (even number of samples is best)
  /// Excitation check: a side's estimate counts only while the standard deviation of the
  /// command on that side's recent updates (exponential window of the estimator's λ) is at
  /// least this fraction of the nominal parameter [-]. A set point held by feedback alone
  /// moves v by sensor noise × Kp only, which does not separate b1 from the offset.
  double min_excitation_ratio = 0.1;
  /// Dead band of the adaptation: the inverse starts to follow the estimate only when they
  /// differ by more than this fraction of the nominal value, then follows it until it has
  /// caught up. Keeps an estimate's small bias out of a correct nominal inverse [-].
  double tolerance_ratio = 0.08;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// Why the inverse holds the values it holds (the compensator's own verdict).
enum class AdaptationReason : std::uint8_t {
  adapting,        ///< the estimate is identified, plausible and settled: the inverse follows it
  settling,        ///< identified, waiting for settle_s
  not_identified,  ///< the estimator's verdict: not identified (see estimator_reason())
  not_excited,     ///< identified, but the command varied too little on that side's updates
  implausible,     ///< identified but outside [min_ratio, max_ratio] × nominal
  holding,         ///< verdict lost: the last adapted values are held
  nominal          ///< never adapted or fell back: the nominal inverse
};
const char* to_string(AdaptationReason r) noexcept;

/// One inverse parameter between its estimate and the inverse (see the law above).
class ParameterGate {
 public:
  /// nominal [parameter unit]; s must be valid (validated by the owner).
  ParameterGate(double nominal, double dt_s, const AdaptationSettings& s) noexcept;
  /// One sample: `identified` is the verdict for this parameter, `estimate` its value.
  /// Returns the value the inverse uses from now on.
  double step(bool identified, double estimate) noexcept;
  double value() const noexcept { return value_; }
  double nominal() const noexcept { return nominal_; }
  AdaptationReason reason() const noexcept { return reason_; }
  /// Samples on which the value changed.
  std::uint64_t changes() const noexcept { return changes_; }

 private:
  double nominal_, value_, max_step_, lo_, hi_, tol_;
  bool moving_ = false;
  std::uint64_t settle_n_, hold_n_, valid_run_ = 0, since_valid_ = 0;
  bool adapted_ = false;
  AdaptationReason reason_ = AdaptationReason::nominal;
  std::uint64_t changes_ = 0;
};

/// Square-wave dither ±A with period P (first half +A). A = 0: always 0.
class Dither {
 public:
  Dither(double amplitude, double period_s, double dt_s) noexcept;
  double step() noexcept {
    if (amplitude_ == 0.0) return 0.0;
    const double out = k_ < half_ ? amplitude_ : -amplitude_;
    if (++k_ >= 2 * half_) k_ = 0;
    return out;
  }

 private:
  double amplitude_;
  std::uint64_t half_, k_ = 0;
};

namespace detail {
/// Exponentially weighted mean and variance of the command on one side's updates.
struct Excitation {
  double lambda = 0.99, mean = 0.0, var = 0.0, weight = 0.0;
  void add(double v) noexcept {
    weight = lambda * weight + 1.0;
    const double a = 1.0 / weight;
    const double d = v - mean;
    mean += a * d;
    var = (1.0 - a) * (var + a * d * d);
  }
  double stddev() const noexcept { return var > 0.0 ? std::sqrt(var) : 0.0; }
};
}  // namespace detail

/// Input deadzone (pilot valve): InputDeadzoneEstimator → per-side gates → DeadzoneInverse.
struct DeadzoneCompensationConfig {
  CompensationMode mode = CompensationMode::fixed;
  DeadzoneInverseParams nominal;  ///< the fixed inverse; the start of the adaptive one
  EstimatorConfig estimator;      ///< model must be input_deadzone; dt_s is the loop's
  AdaptationSettings adaptation;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

class DeadzoneCompensator {
 public:
  /// Throws std::invalid_argument (see DeadzoneCompensationConfig::validate).
  explicit DeadzoneCompensator(const DeadzoneCompensationConfig& c);
  /// Desired deadzone output u(k) → command v(k) (dither added to u first, adaptive only).
  double command(double u) noexcept {
    switch (cfg_.mode) {
      case CompensationMode::none: return u;
      case CompensationMode::fixed: return inv_.step(u);
      case CompensationMode::adaptive: break;
    }
    return inv_.step(u + dither_.step());
  }
  /// After the command was applied: the sample (v(k) as applied, y(k) measured before it).
  /// Adaptive mode steps the estimator and moves the inverse's edges through the gates.
  void observe(double v_applied, double y) noexcept;

  const DeadzoneInverse& inverse() const noexcept { return inv_; }
  const InputDeadzoneEstimator& estimator() const noexcept { return est_; }
  const ParameterGate& gate(Side s) const noexcept { return s == Side::right ? gate_r_ : gate_l_; }
  /// Samples on which the inverse's parameters changed.
  std::uint64_t updates() const noexcept { return updates_; }
  /// The worse of the two sides' reasons (adapting only when both adapt).
  AdaptationReason reason() const noexcept;
  /// Why a side is not used: the estimator's verdict reason (identify/verdict.hpp) or the
  /// compensator's excitation check (a fixed text, no allocation).
  const char* estimator_reason(Side s) const noexcept;
  const DeadzoneCompensationConfig& config() const noexcept { return cfg_; }

 private:
  DeadzoneCompensationConfig cfg_;
  DeadzoneInverse inv_;
  InputDeadzoneEstimator est_;
  ParameterGate gate_r_, gate_l_;
  Dither dither_;
  detail::Excitation exc_r_, exc_l_;
  double v1_ = 0.0;
  bool not_excited_r_ = false, not_excited_l_ = false;
  std::uint64_t updates_ = 0;
};

/// Online estimate of a backlash's gaps from the driving position w and the driven position y
/// (coupled carts: motor cart and free cart). While the two move together (engaged: both
/// velocities agree within 10 % and exceed `speed_min` for `run` samples), w − y is the gap of
/// that direction: +c_r moving up, −c_l' moving down (the backlash of backlash_inverse.hpp).
/// Each direction keeps an exponentially weighted mean and spread with forgetting λ; a
/// direction is identified after `min_updates` engaged samples with spread ≤ 20 % of the mean
/// and a positive mean. step() is noexcept and O(1).
struct GapEstimatorConfig {
  double dt_s = 0.001;         ///< sample period [s]
  double lambda = 0.999;       ///< forgetting factor per engaged sample [-]
  double speed_min = 0.005;    ///< engaged only above this speed [position unit/s]
  std::uint32_t run = 3;       ///< engaged samples in a row before the gap counts [-]
  std::uint64_t min_updates = 200;  ///< engaged samples per direction before identified [-]
  void validate() const;
};

class GapEstimator {
 public:
  explicit GapEstimator(const GapEstimatorConfig& c);
  void step(double w, double y) noexcept {
    const double wd = (w - w1_) / c_.dt_s, yd = (y - y1_) / c_.dt_s;
    w1_ = w;
    y1_ = y;
    const int dir = yd > c_.speed_min ? 1 : (yd < -c_.speed_min ? -1 : 0);
    const bool together = dir != 0 && std::fabs(wd - yd) <= 0.1 * std::fabs(yd);
    run_ = (together && dir == dir1_) ? run_ + 1 : (together ? 1 : 0);
    dir1_ = dir;
    if (!first_ && run_ >= c_.run) {
      auto& g = dir > 0 ? up_ : down_;
      g.add(dir > 0 ? w - y : y - w);
      ++n_[dir > 0 ? 0 : 1];
    }
    first_ = false;
  }
  /// Gap of one side (right = pushing up, c_r; left = pushing down, c_l') [position unit].
  double gap(Side s) const noexcept { return (s == Side::right ? up_ : down_).mean; }
  std::uint64_t updates(Side s) const noexcept { return n_[s == Side::right ? 0 : 1]; }
  bool identified(Side s) const noexcept {
    const auto& g = s == Side::right ? up_ : down_;
    return updates(s) >= c_.min_updates && g.mean > 0.0 && g.stddev() <= 0.2 * g.mean;
  }
  bool identified() const noexcept { return identified(Side::right) && identified(Side::left); }

 private:
  GapEstimatorConfig c_;
  detail::Excitation up_, down_;
  std::uint64_t n_[2] = {0, 0};
  double w1_ = 0.0, y1_ = 0.0;
  int dir1_ = 0;
  std::uint32_t run_ = 0;
  bool first_ = true;
};

/// Backlash between a driving and a driven position (coupled carts): GapEstimator on
/// (w, y) → one gate per side → BacklashInverse.
struct BacklashCompensationConfig {
  CompensationMode mode = CompensationMode::fixed;
  BacklashInverseParams nominal;  ///< the fixed inverse; the start of the adaptive one
  GapEstimatorConfig estimator;
  AdaptationSettings adaptation;
  void validate() const;
};

class BacklashCompensator {
 public:
  explicit BacklashCompensator(const BacklashCompensationConfig& c);
  /// Desired driven position u(k) → driving position w(k).
  double command(double u) noexcept {
    switch (cfg_.mode) {
      case CompensationMode::none: return u;
      case CompensationMode::fixed: return inv_.step(u);
      case CompensationMode::adaptive: break;
    }
    return inv_.step(u + dither_.step());
  }
  /// Starts the inverse at rest at u0 (engaged pushing up), as BacklashInverse::reset.
  void reset(double u0) noexcept { inv_.reset(u0, true); }
  /// Each sample: the driving position w(k) and the driven position y(k) as measured.
  void observe(double w, double y) noexcept;

  const BacklashInverse& inverse() const noexcept { return inv_; }
  const GapEstimator& estimator() const noexcept { return est_; }
  const ParameterGate& gate(Side s) const noexcept { return s == Side::right ? gate_r_ : gate_l_; }
  std::uint64_t updates() const noexcept { return updates_; }
  AdaptationReason reason() const noexcept;
  const char* estimator_reason() const noexcept;
  const BacklashCompensationConfig& config() const noexcept { return cfg_; }

 private:
  BacklashCompensationConfig cfg_;
  BacklashInverse inv_;
  GapEstimator est_;
  ParameterGate gate_r_, gate_l_;
  Dither dither_;
  std::uint64_t updates_ = 0;
};

}  // namespace lash
