#pragma once
/// @file closed_loop.hpp
/// Closed-loop simulation of docs/method.md §B2 / thesis Fig 2.13 in the two ways the
/// thesis compared (paper 2, §2.7.2):
/// (a) **discrete**: what runs on the target: the discrete controller
///     (ClosedLoopDiscrete: discrete PID → deadzone inverse → saturation) and
///     the ZOH pilot-valve plant (PilotValvePlant). Each sample k:
///     y(k) = plant.measure(); i(k) = controller.step(r(k), y(k)); plant.apply(i(k − d))
///     with d = bus_delay_steps (0 in the thesis's simulation).
/// (b) **continuous / ode3**: the continuous PID Kp + Ki/s + Kd·N·s/(s + N)
///     and the continuous plant K/(τs + 1) (∘ deadzone) integrated together with
///     the fixed-step Bogacki–Shampine solver (ode3.hpp) at the same step T.
///     Reference and sensor noise are held over each step (Simulink's discrete
///     sources); the deadzone inverse, saturation and sensor code are evaluated
///     at every solver stage. With N = 0 the derivative is Simulink's du/dt block
///     (the thesis's continuous PID): Δe/Δt since the last major step.
/// Not real-time code (allocates the traces); the per-sample work is the same
/// step functions the HIL nodes call.
#include <cstddef>
#include <vector>

#include "lash/control/controller.hpp"
#include "lash/control/step_metrics.hpp"
#include "lash/rigs/pilot_valve_model.hpp"

namespace lash {

struct ClosedLoopTrace {
  std::vector<double> t_s;             ///< sample times k·T [s]
  std::vector<double> reference_kPa;   ///< r(k)
  std::vector<double> measured_kPa;    ///< y(k): what the controller saw (noise, sensor code)
  std::vector<double> pressure_kPa;    ///< noise-free plant pressure at t_k
  std::vector<double> command_mA;      ///< i(k) after deadzone inverse and saturation
  std::vector<double> pid_mA;          ///< u(k) before the deadzone inverse
  std::size_t samples() const noexcept { return t_s.size(); }
};

enum class Solver { discrete, ode3 };
const char* to_string(Solver s) noexcept;

/// Runs the closed loop for reference.size() samples. Throws std::invalid_argument
/// on invalid plant/controller configurations or when the controller's T differs from the plant's.
ClosedLoopTrace simulate_closed_loop(Solver solver, const PilotValveParams& plant, const ControllerConfig& controller,
                                     const std::vector<double>& reference_kPa, std::size_t bus_delay_steps = 0);

/// The step test used for the thesis figures: starting at rest (zero current, pressure
/// at the bias, controller states zero) the reference holds r0 for settle_s, then steps
/// to r1 for after_s. The default is the rising edge of a 0/1000 kPa square wave with
/// 1 s half-period (the thesis tracked square waves; their amplitude is not given):
/// r0 = 0 kPa lies below the 90.1 kPa bias, so during the low half the PID (no
/// anti-windup, as in the thesis) winds its integrator down. Metrics are taken on the
/// noise-free pressure.
struct StepTest {
  double r0_kPa = 0.0;     ///< level before the step [kPa]
  double r1_kPa = 1000.0;  ///< level after the step [kPa]
  double settle_s = 1.0;   ///< time at r0 before the step [s]
  double after_s = 1.0;    ///< time at r1 after the step [s]
  /// Reference samples at T = dt_s.
  std::vector<double> reference(double dt_s) const;
  double t_step_s(double dt_s) const;
};

struct StepResult {
  ClosedLoopTrace trace;
  StepMetrics metrics;  ///< on trace.pressure_kPa (noise-free)
  StepMetrics measured_metrics;  ///< on trace.measured_kPa (what a scope would show)
};

StepResult run_step_test(Solver solver, const PilotValveParams& plant, const ControllerConfig& controller,
                         const StepTest& test, std::size_t bus_delay_steps = 0);

}  // namespace lash
