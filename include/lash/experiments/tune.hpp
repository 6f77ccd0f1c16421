#pragma once
/// @file tune.hpp
/// Reproducible search for PID gains whose discrete closed-loop step response
/// (closed_loop.hpp, noise-free, StepTest) matches target figures — the thesis's
/// 90 % rise 0.11 s, 10 % settling 0.25 s, overshoot 59 % (paper 2, §2.7.2).
///
/// Cost J = Σ w_m·((m − target_m)/target_m)² over rise, settling, overshoot of the
/// discrete loop (+ optionally the ode3 overshoot); a response that never rises
/// or settles, or whose ode3 twin does not (numerically unstable), is penalised.
/// Search, in log-gain space: `samples` points drawn with lash::Rng(seed) over
/// the box, then Nelder–Mead from the `restarts` best. Same seed → same gains on
/// every compiler (no std:: distributions). Not real-time code.
#include <cstdint>
#include <optional>
#include <string>

#include "lash/control/closed_loop.hpp"

namespace lash {

struct TuneTargets {
  double rise_s = 0.11;
  double settling_s = 0.25;
  double overshoot_pct = 59.0;
  std::optional<double> ode3_overshoot_pct = 32.0;  ///< also match the ode3 overshoot (thesis 32 %); nullopt = ignore
  double w_rise = 1.0, w_settling = 0.1, w_overshoot = 1.0, w_ode3 = 0.1;
};

/// Parses "rise=0.11,settling=0.25,overshoot=59[,ode3_overshoot=32]" into `t`
/// (unmentioned fields keep their values). Throws std::invalid_argument.
void parse_targets(const std::string& text, TuneTargets& t);
/// Parses "rise=1,settling=0.25,overshoot=1,ode3=0.25" weights.
void parse_weights(const std::string& text, TuneTargets& t);

struct TuneOptions {
  PilotValveParams plant;      ///< the noise is switched off during the search
  ControllerConfig controller; ///< gains are overwritten; the rest (T, dz inverse, limits) kept
  StepTest step;
  TuneTargets targets;
  bool tune_filter = false;    ///< also search N; false: N = 0 (unfiltered, as the thesis's blocks)
  double kp_min = 1e-3, kp_max = 30.0;
  double ki_min = 0.1, ki_max = 3000.0;
  double kd_min = 1e-5, kd_max = 1.0;
  double n_min = 10.0, n_max = 5000.0;
  int samples = 30000;
  int restarts = 16;
  int iterations = 400;         ///< Nelder–Mead iterations per restart
  std::uint64_t seed = 1;
};

struct TuneResult {
  PidGains gains;
  double cost = 0.0;
  StepMetrics discrete;
  StepMetrics ode3;
  int evaluations = 0;
};

/// Cost of one gain set (exposed for tests and for `lash tune --evaluate`).
double tune_cost(const TuneOptions& o, const PidGains& g, StepMetrics* discrete = nullptr,
                 StepMetrics* ode3 = nullptr);

TuneResult tune_pid(const TuneOptions& options);

}  // namespace lash
