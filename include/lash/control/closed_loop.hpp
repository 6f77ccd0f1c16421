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
/// step functions the HIL nodes call. ClosedLoopStepper and run_step_comparison() keep no
/// trace: their memory is O(1) in the run's length (plus the bus-delay line, 8 bytes a sample
/// of delay), and a trace goes to a caller's sink as it is produced.
#include <cstddef>
#include <functional>
#include <memory>
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

/// One sample of a closed loop (one row of ClosedLoopTrace).
struct ClosedLoopSample {
  double t_s = 0.0;            ///< k·T [s]
  double reference_kPa = 0.0;  ///< r(k)
  double measured_kPa = 0.0;   ///< y(k): what the controller saw
  double pressure_kPa = 0.0;   ///< noise-free plant pressure at t_k
  double command_mA = 0.0;     ///< i(k) after deadzone inverse and saturation
  double pid_mA = 0.0;         ///< u(k) before the deadzone inverse
};

/// The closed loop of simulate_closed_loop() advanced one sample at a time, from rest. Memory:
/// O(1), plus the bus-delay line of the discrete loop (8·(d + 1) bytes).
class ClosedLoopStepper {
 public:
  /// Throws std::invalid_argument on invalid plant/controller configurations, a controller T
  /// other than the plant's, a bus delay with ode3, or a delay line larger than the machine's memory.
  ClosedLoopStepper(Solver solver, const PilotValveParams& plant, const ControllerConfig& controller,
                    std::size_t bus_delay_steps = 0);
  ClosedLoopStepper(ClosedLoopStepper&&) noexcept;
  ClosedLoopStepper& operator=(ClosedLoopStepper&&) noexcept;
  ~ClosedLoopStepper();
  /// Sample k (0, 1, …) with the reference r(k).
  ClosedLoopSample step(double reference_kPa);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

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

/// Keeps the whole trace (for callers that inspect it, e.g. the tuner's rest check).
StepResult run_step_test(Solver solver, const PilotValveParams& plant, const ControllerConfig& controller,
                         const StepTest& test, std::size_t bus_delay_steps = 0);

/// The figures of one solver's step test, without the trace.
struct StepFigures {
  StepMetrics metrics;           ///< on the noise-free pressure
  StepMetrics measured_metrics;  ///< on the measured pressure
  std::size_t samples = 0;       ///< samples simulated
  std::size_t nonfinite_commands = 0;  ///< samples whose command or PID output was not finite
};

/// Both solvers of `lash closed-loop` on the same step test, in lockstep: discrete (with the bus
/// delay) and ode3. The metrics are computed as the samples are produced; nothing is kept, and
/// `row` (when set) receives every sample of both loops as it is produced (to write a trace to
/// disk). Memory O(1) in the test's length besides the bus-delay line. Same figures, bit for bit,
/// as run_step_test() of each solver. Throws std::invalid_argument as run_step_test().
struct StepComparison {
  StepFigures discrete, ode3;
};
using StepRowFn = std::function<void(const ClosedLoopSample& discrete, const ClosedLoopSample& ode3)>;
StepComparison run_step_comparison(const PilotValveParams& plant, const ControllerConfig& controller,
                                   const StepTest& test, std::size_t bus_delay_steps = 0, const StepRowFn& row = {});

/// Ranges that keep every figure of run_step_comparison() finite, checked before it runs (it
/// calls this): at least one sample before and after the step; |r1 − r0| ≥ 1e-6 kPa; the
/// largest pressure the plant can make, |bias| + gain·max(|min_mA|, |max_mA|), at most 1e6 kPa;
/// T/τ, T/τ₂ and N·T at most 2.5 (the explicit ode3's real stability interval is [−2.51, 0]);
/// the PID output's worst case Kp·E + Ki·E·t_end + (Kd·4E/T or Kd·N·2E) at most 1e300, with E
/// = max(|r0|, |r1|) + the largest pressure + 12.1 σ + 5000 kPa (the sensor code's range).
/// Throws std::invalid_argument naming the field and its `lash closed-loop` option.
void check_step_comparison(const PilotValveParams& plant, const ControllerConfig& controller, const StepTest& test);

/// Samples of a step test at the plant's T (settle + after); throws std::invalid_argument as
/// run_step_test() does for a test it refuses.
std::size_t step_test_samples(const StepTest& test, double dt_s);

}  // namespace lash
