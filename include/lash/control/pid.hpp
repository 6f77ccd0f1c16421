#pragma once
/// @file pid.hpp
/// Discrete PID controller in parallel form (thesis paper 2, §2.7.2, Fig 2.12):
///   u(k) = Kp·e(k) + I(k) + D(k)
/// The thesis replaced Simulink's continuous integrator and derivative by the
/// *Discrete-Time Integrator* (forward Euler by default) and the *Discrete
/// Derivative* (backward difference); those are the defaults here.
///   integrator, forward Euler  : I(k) = I(k−1) + Ki·T·e(k−1)
///   integrator, backward Euler : I(k) = I(k−1) + Ki·T·e(k)
///   integrator, trapezoidal    : I(k) = I(k−1) + Ki·T·(e(k) + e(k−1))/2
///   derivative, N = 0          : D(k) = Kd·(e(k) − e(k−1))/T
///   derivative, N > 0          : D(k) = (D(k−1) + Kd·N·(e(k) − e(k−1))) / (1 + N·T)
///                                (backward-Euler discretisation of Kd·N·s/(s + N);
///                                 tends to the backward difference as N → ∞)
/// Anti-windup (optional): the output is clamped to [output_min, output_max]
/// and the integrator is frozen while the clamped output and the error push
/// the same way (conditional integration).
///
/// Real time: step() is noexcept, allocation-free and O(1). Configuration is
/// validated at construction (std::invalid_argument names the field).
#include <limits>

namespace lash {

struct PidGains {
  double kp = 0.0;        ///< proportional gain [output unit / error unit]
  double ki_per_s = 0.0;  ///< integral gain Ki [output unit / (error unit·s)]
  double kd_s = 0.0;      ///< derivative gain Kd [output unit·s / error unit]
  double n_per_s = 0.0;   ///< derivative filter bandwidth N [1/s]; 0 = unfiltered derivative
};

enum class IntegratorMethod { forward_euler, backward_euler, trapezoidal };
enum class AntiWindup { none, clamp };

/// "forward_euler" | "backward_euler" | "trapezoidal"; throws std::invalid_argument otherwise.
IntegratorMethod parse_integrator_method(const char* text);
const char* to_string(IntegratorMethod m) noexcept;

struct PidConfig {
  PidGains gains;
  double dt_s = 0.005;  ///< sample period T [s]
  IntegratorMethod integrator = IntegratorMethod::forward_euler;
  AntiWindup anti_windup = AntiWindup::none;
  double output_min = -std::numeric_limits<double>::infinity();  ///< used by AntiWindup::clamp
  double output_max = std::numeric_limits<double>::infinity();   ///< used by AntiWindup::clamp
};

class Pid {
 public:
  /// Throws std::invalid_argument unless gains are finite, Kp, Ki, Kd, N ≥ 0,
  /// T > 0 and output_min ≤ output_max.
  explicit Pid(const PidConfig& config);

  /// One sample: error e(k) = reference − measurement → controller output u(k).
  double step(double error) noexcept {
    const double T = cfg_.dt_s;
    const auto& g = cfg_.gains;
    // Integrator state for this sample.
    double inc = 0.0;
    switch (cfg_.integrator) {
      case IntegratorMethod::forward_euler: inc = g.ki_per_s * T * e_prev_; break;
      case IntegratorMethod::backward_euler: inc = g.ki_per_s * T * error; break;
      case IntegratorMethod::trapezoidal: inc = 0.5 * g.ki_per_s * T * (error + e_prev_); break;
    }
    double i_new = i_ + inc;
    // Derivative.
    const double de = error - e_prev_;
    if (g.n_per_s > 0.0)
      d_ = (d_ + g.kd_s * g.n_per_s * de) / (1.0 + g.n_per_s * T);
    else
      d_ = g.kd_s * de / T;
    double u = g.kp * error + i_new + d_;
    if (cfg_.anti_windup == AntiWindup::clamp) {
      if (u > cfg_.output_max) {
        if (inc > 0.0) i_new = i_;  // freeze: integrating further would deepen saturation
        u = g.kp * error + i_new + d_;
        if (u > cfg_.output_max) u = cfg_.output_max;
      } else if (u < cfg_.output_min) {
        if (inc < 0.0) i_new = i_;
        u = g.kp * error + i_new + d_;
        if (u < cfg_.output_min) u = cfg_.output_min;
      }
    }
    i_ = i_new;
    e_prev_ = error;
    u_ = u;
    return u;
  }

  /// Zeroes integrator, derivative and stored error.
  void reset() noexcept { i_ = d_ = e_prev_ = u_ = 0.0; }
  /// Sets the integrator state I (e.g. for bumpless start at a known operating point).
  void set_integrator(double value) noexcept { i_ = value; }
  /// Replaces the gains between samples (real-time safe: no allocation, no validation;
  /// the caller guarantees finite non-negative values, e.g. from a validated PidGains).
  void set_gains(const PidGains& g) noexcept { cfg_.gains = g; }

  double integrator() const noexcept { return i_; }
  double derivative() const noexcept { return d_; }
  double output() const noexcept { return u_; }
  const PidConfig& config() const noexcept { return cfg_; }

 private:
  PidConfig cfg_;
  double i_ = 0.0;
  double d_ = 0.0;
  double e_prev_ = 0.0;
  double u_ = 0.0;
};

/// Throws std::invalid_argument unless the gains are finite and non-negative.
void validate(const PidGains& g);

}  // namespace lash
