#pragma once
/// @file controller.hpp
/// The master-side controller of docs/method.md §B2 / thesis Fig 2.12 as one step
/// function: discrete PID → deadzone inverse → saturation 0–2000 mA.
/// This is the exact code the closed-loop simulation (closed_loop.hpp) and the
/// HIL master node call each sample, so emulation and simulation agree bit for bit.
///
///   e(k) = r(k) − y(k)                  [kPa]
///   u(k) = PID(e)(k)                    [mA]  (pid.hpp)
///   v(k) = DZinv(u(k))                  [mA]  (offset 0.97·288 mA in the direction of u)
///   i(k) = clamp(v(k), 0, 2000)         [mA]  (current driver's range)
///
/// Real time: step() is noexcept, allocation-free and O(1).
#include "lash/blocks/saturation.hpp"
#include "lash/control/deadzone_inverse.hpp"
#include "lash/control/pid.hpp"

namespace lash {

struct ControllerConfig {
  PidConfig pid;                        ///< gains, T, integrator method, anti-windup
  DeadzoneInverseParams dz_inverse = DeadzoneInverseParams::from_deadzone(288.0, 0.97);
  double current_min_mA = 0.0;          ///< saturation lower limit [mA]
  double current_max_mA = 2000.0;       ///< saturation upper limit [mA]
};

/// Discrete PID + deadzone inverse + saturation: (reference, measured) → command.
class ClosedLoopDiscrete {
 public:
  /// Throws std::invalid_argument on an invalid PID, deadzone inverse or saturation.
  explicit ClosedLoopDiscrete(const ControllerConfig& config);

  /// One sample: returns the saturated current command i(k) [mA].
  double step(double reference_kPa, double measured_kPa) noexcept {
    const double u = pid_.step(reference_kPa - measured_kPa);
    pid_out_ = u;
    return sat_.step(dzi_.step(u));
  }
  void reset() noexcept { pid_.reset(); pid_out_ = 0.0; }

  /// PID output u(k) of the last step, before the deadzone inverse [mA].
  double pid_output() const noexcept { return pid_out_; }
  Pid& pid() noexcept { return pid_; }
  const Pid& pid() const noexcept { return pid_; }
  DeadzoneInverse& deadzone_inverse() noexcept { return dzi_; }
  const DeadzoneInverse& deadzone_inverse() const noexcept { return dzi_; }
  const Saturation& saturation() const noexcept { return sat_; }
  const ControllerConfig& config() const noexcept { return cfg_; }

 private:
  ControllerConfig cfg_;
  Pid pid_;
  DeadzoneInverse dzi_;
  Saturation sat_;
  double pid_out_ = 0.0;
};

}  // namespace lash
