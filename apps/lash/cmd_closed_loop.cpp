// lash closed-loop: the closed loop of docs/method.md §B2 (PID + deadzone inverse + saturation around the
// pilot valve of §B1) simulated (a) discretely and (b) continuously with ode3; step metrics of both.
#include <cmath>
#include <optional>
#include <tuple>
#include <utility>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "csv_stream.hpp"
#include "controller_options.hpp"
#include "plot.hpp"
#include "lash/control/closed_loop.hpp"
#include "lash/control/gains_file.hpp"
#include "lash/control/model_based.hpp"

namespace lash::cli {
namespace {

struct Options {
  std::string gains;
  double r0 = 0.0, r1 = 1000.0, settle = 1.0, after = 1.0;
  double deadzone = 288.0, gain = 2.15, tau = 0.07, tau2 = 0.0, bias = 90.1, sigma = 0.0;
  bool no_quantize = false;
  std::uint64_t seed = 1;
  std::size_t bus_delay = 0;
  bool json = false;
  bool online = false;
  std::string out, plot;
  std::string scenario, compensation = "adaptive";
  std::vector<ControllerOverride> controller;  // --kp, --ki-per-s, … (after the gains file)
};

// Why a figure is not a number, in words (docs/control.md, "Figures that are not numbers").
std::string reason_text(FigureStatus st, const StepMetrics& m, const char* what) {
  switch (st) {
    case FigureStatus::ok: return "";
    case FigureStatus::not_reached:
      return fmt::format("not_reached: the {} never reached 90 % of the step in the {:.6g} s after it", what,
                         m.record_s);
    case FigureStatus::not_settled:
      return fmt::format("not_settled: the {} was still outside +-10 % of the step at the end of the record, {:.6g} s after it",
                         what, m.record_s);
    case FigureStatus::not_finite:
      return fmt::format("not_finite: the {} was not a finite number on {} of {} samples from t = {:.6g} s (the simulation "
                         "diverged)",
                         what, m.nonfinite, m.samples, m.first_nonfinite_s);
  }
  return "";
}

nlohmann::json metrics_json(const StepMetrics& m, const char* what = "pressure") {
  nlohmann::json j;
  for (auto [key, x, st] : {std::tuple{"rise_s", m.rise_s, m.rise_status}, std::tuple{"settling_s", m.settling_s, m.settling_status},
                            std::tuple{"overshoot_pct", m.overshoot_pct, m.overshoot_status}}) {
    j[key] = std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
    if (!std::isfinite(x)) j[std::string(key) + "_reason"] = reason_text(st, m, what);
  }
  return j;
}

// A figure for the text table: the number, or why there is none.
std::string cell(double x, FigureStatus st, int decimals) {
  return std::isfinite(x) ? fmt::format("{:.{}f}", x, decimals) : std::string(to_string(st));
}

bool diverged(const StepMetrics& m) { return m.nonfinite > 0; }

// Beyond the thesis: thesis gains vs gains + deadzone inverse from the online RLS estimate,
// on the virtual pilot-valve rig and on the B1 model with a second pole (tau2, default 8 ms).
int run_online(const Options& o, const ControllerConfig& thesis, const StepTest& st) {
  const rigs::PilotValveRigParams rp;
  const double dt = thesis.pid.dt_s;
  const FirstOrderDeadzoneModel m = identify_online_on_rig(rp, dt, o.seed);
  const ControllerConfig online = design_for_rise(m, rp.bias_kPa, 0.11, dt, st);
  PilotValveParams b1;
  b1.tau2_s = o.tau2 > 0 ? o.tau2 : 0.008;
  b1.seed = o.seed;
  b1.dt_s = dt;
  const auto th_rig = run_step_on_rig(rp, thesis, st, o.seed).metrics;
  const auto on_rig = run_step_on_rig(rp, online, st, o.seed).metrics;
  const auto th_b1 = run_step_test(Solver::discrete, b1, thesis, st).metrics;
  const auto on_b1 = run_step_test(Solver::discrete, b1, online, st).metrics;
  if (o.json) {
    nlohmann::json j;
    j["online_model"] = {{"gain_kPa_per_mA", m.gain_kPa_per_mA}, {"tau_s", m.tau_s}, {"deadzone_mA", m.deadzone_mA}};
    j["online_gains"] = {{"kp", online.pid.gains.kp}, {"ki", online.pid.gains.ki_per_s},
                         {"offset_mA", online.dz_inverse.offset_right}};
    j["rig"] = {{"thesis", metrics_json(th_rig)}, {"online", metrics_json(on_rig)}};
    j["b1_second_pole"] = {{"thesis", metrics_json(th_b1)}, {"online", metrics_json(on_b1)}};
    fmt::print("{}\n", j.dump());
    return kExitOk;
  }
  fmt::print("online RLS estimate on the rig: K = {:.4f} kPa/mA, tau = {:.4f} s, c = {:.2f} mA\n", m.gain_kPa_per_mA,
             m.tau_s, m.deadzone_mA);
  fmt::print("designed PI: kp = {:.4f} mA/kPa, ki = {:.4f} mA/(kPa s), deadzone inverse {:.2f} mA, clamp anti-windup\n",
             online.pid.gains.kp, online.pid.gains.ki_per_s, online.dz_inverse.offset_right);
  fmt::print("{:<22} {:>12} {:>14} {:>14}\n", "plant / controller", "rise90 [s]", "settle10 [s]", "overshoot [%]");
  for (auto [name, mm] : {std::pair{"rig / thesis", th_rig}, std::pair{"rig / online", on_rig},
                          std::pair{"B1+pole / thesis", th_b1}, std::pair{"B1+pole / online", on_b1}})
    fmt::print("{:<22} {:>12} {:>14} {:>14}\n", name, cell(mm.rise_s, mm.rise_status, 4),
               cell(mm.settling_s, mm.settling_status, 4), cell(mm.overshoot_pct, mm.overshoot_status, 2));
  return kExitOk;
}

int run(const Options& o) {
  if (!o.scenario.empty()) {
    if (!o.controller.empty())
      throw InputError("", 0, std::string("--") + o.controller.front().field->flag,
                       "with --scenario the scenario's [controller] table sets the controller");
    return run_closed_loop_scenario_cmd(o.scenario, o.compensation, o.json, o.out, o.plot);
  }
  const std::string gains_path = o.gains.empty() ? source_dir() + "/config/control/thesis_gains.toml" : o.gains;
  ControllerConfig c = load_controller_config(gains_path);
  apply_controller_overrides(c, o.controller);
  PilotValveParams p;
  p.deadzone_mA = o.deadzone;
  p.gain_kPa_per_mA = o.gain;
  p.tau_s = o.tau;
  p.tau2_s = o.tau2;
  p.bias_kPa = o.bias;
  p.noise_sigma_kPa = o.sigma;
  p.quantize = !o.no_quantize;
  p.seed = o.seed;
  p.dt_s = c.pid.dt_s;
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, "plant option", e.what());
  }
  // At most an hour each: the trace is streamed (memory O(1)), the limit keeps a typo from running for days.
  for (const auto& [name, v] : {std::pair{"--settle", o.settle}, std::pair{"--after", o.after}})
    if (!(v > 0) || !(v <= 3600.0)) throw InputError("", 0, name, "must be in (0, 3600] [s]");
  StepTest st{o.r0, o.r1, o.settle, o.after};
  if (o.online) return run_online(o, c, st);
  if (!o.plot.empty() && o.out.empty()) throw InputError("", 0, "--plot", "needs -o FILE (the plot is drawn from it)");
  if (!o.out.empty()) check_output_path(o.out, "--output");
  if (!o.plot.empty()) check_output_path(o.plot, "--plot");
  try {
    check_step_comparison(p, c, st);
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, "", e.what());
  }
  // Both loops in lockstep; the trace goes to the file row by row, the figures are computed as
  // the samples come: memory O(1) in the test's length (plus the --bus-delay line).
  std::optional<CsvStream> csv;
  if (!o.out.empty())
    csv.emplace(o.out, std::vector<std::string>{"t", "reference_kPa", "discrete_measured_kPa", "discrete_pressure_kPa",
                                                "discrete_command_mA", "ode3_measured_kPa", "ode3_pressure_kPa",
                                                "ode3_command_mA"});
  StepRowFn row;
  if (csv)
    row = [&csv](const ClosedLoopSample& a, const ClosedLoopSample& b) {
      const double v[8] = {a.t_s, a.reference_kPa, a.measured_kPa, a.pressure_kPa, a.command_mA, b.measured_kPa,
                           b.pressure_kPa, b.command_mA};
      csv->row(v);
    };
  const StepComparison r = run_step_comparison(p, c, st, o.bus_delay, row);
  const StepFigures& d = r.discrete;
  const StepFigures& c3 = r.ode3;
  if (csv) {
    csv->commit();
    if (!o.plot.empty())
      plot_csv(o.out, o.plot, "lash closed-loop: discrete vs ode3", {{"pressure [kPa]", "t [s]"}, {"current [mA]", "t [s]"}},
               {{"t", "reference_kPa", "reference", 0},
                {"t", "discrete_measured_kPa", "discrete", 0},
                {"t", "ode3_measured_kPa", "ode3", 0},
                {"t", "discrete_command_mA", "discrete", 1},
                {"t", "ode3_command_mA", "ode3", 1}});
  }
  const double ratio = c3.metrics.overshoot_pct > 0 ? d.metrics.overshoot_pct / c3.metrics.overshoot_pct : NAN;
  std::string ratio_reason;
  if (!std::isfinite(ratio))
    ratio_reason = diverged(d.metrics) || diverged(c3.metrics)
                       ? "not_finite: a simulation diverged"
                       : "undefined: the ode3 loop does not overshoot (0 %)";
  const bool failed = diverged(d.metrics) || diverged(c3.metrics) || diverged(d.measured_metrics) ||
                      diverged(c3.measured_metrics) || d.nonfinite_commands > 0 || c3.nonfinite_commands > 0;
  if (o.json) {
    nlohmann::json j;
    j["gains"] = {{"kp", c.pid.gains.kp}, {"ki", c.pid.gains.ki_per_s}, {"kd", c.pid.gains.kd_s},
                  {"n", c.pid.gains.n_per_s}, {"dt_s", c.pid.dt_s}};
    j["step"] = {{"r0_kPa", o.r0}, {"r1_kPa", o.r1}};
    j["samples"] = d.samples;
    j["discrete"] = metrics_json(d.metrics);
    j["ode3"] = metrics_json(c3.metrics);
    j["discrete_measured"] = metrics_json(d.measured_metrics, "measured pressure");
    j["ode3_measured"] = metrics_json(c3.measured_metrics, "measured pressure");
    j["overshoot_ratio_discrete_over_ode3"] = std::isfinite(ratio) ? nlohmann::json(ratio) : nlohmann::json(nullptr);
    if (!ratio_reason.empty()) j["overshoot_ratio_discrete_over_ode3_reason"] = ratio_reason;
    j["complete"] = !failed;
    if (failed) j["reason"] = "not_finite: a simulation diverged (non-finite pressure or command); see the figures' reasons";
    fmt::print("{}\n", j.dump());
  } else {
    fmt::print("closed loop, step {} -> {} kPa, T = {} s, gains {}\n", format_double(o.r0), format_double(o.r1),
               format_double(c.pid.dt_s), gains_path);
    fmt::print("{:<10} {:>12} {:>14} {:>14}\n", "solver", "rise90 [s]", "settle10 [s]", "overshoot [%]");
    for (auto [name, m] : {std::pair{"discrete", d.metrics}, std::pair{"ode3", c3.metrics}})
      fmt::print("{:<10} {:>12} {:>14} {:>14}\n", name, cell(m.rise_s, m.rise_status, 4),
                 cell(m.settling_s, m.settling_status, 4), cell(m.overshoot_pct, m.overshoot_status, 2));
    if (std::isfinite(ratio))
      fmt::print("overshoot ratio discrete/ode3 = {:.3f} (thesis 59/32 = {:.3f})\n", ratio, 59.0 / 32.0);
    else
      fmt::print("overshoot ratio discrete/ode3: {}\n", ratio_reason);
    for (auto [name, m] : {std::pair{"discrete", d.metrics}, std::pair{"ode3", c3.metrics}})
      for (auto [fig, status] : {std::pair{"rise90", m.rise_status}, std::pair{"settle10", m.settling_status},
                             std::pair{"overshoot", m.overshoot_status}})
        if (status != FigureStatus::ok) fmt::print("{} {}: {}\n", name, fig, reason_text(status, m, "pressure"));
  }
  if (failed) {
    fmt::print(stderr,
               "lash closed-loop: a simulation diverged (non-finite pressure on {} + {} samples, non-finite command on "
               "{} + {} samples, discrete + ode3): its figures are not valid\n",
               d.metrics.nonfinite, c3.metrics.nonfinite, d.nonfinite_commands, c3.nonfinite_commands);
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace

Command add_closed_loop(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* sub = app.add_subcommand(
      "closed-loop", "Step response of the pilot-valve closed loop: discrete solver vs continuous ode3 (docs/method.md §B2)");
  sub->add_option("--gains", o->gains, "Controller TOML (default config/control/thesis_gains.toml)");
  sub->add_option("--r0", o->r0, "Reference before the step [kPa]");
  sub->add_option("--r1", o->r1, "Reference after the step [kPa]");
  sub->add_option("--settle", o->settle, "Time at r0 before the step, (0, 3600] [s]")->capture_default_str();
  sub->add_option("--after", o->after, "Time at r1 after the step, (0, 3600] [s]")->capture_default_str();
  sub->add_option("--deadzone", o->deadzone, "Plant deadzone [mA]");
  sub->add_option("--gain", o->gain, "Plant gain [kPa/mA]");
  sub->add_option("--tau", o->tau, "Plant time constant [s]");
  sub->add_option("--tau2", o->tau2, "Optional second lag [s] (0 = none)");
  sub->add_option("--bias", o->bias, "Pressure at zero current [kPa]");
  sub->add_option("--noise-sigma", o->sigma, "Sensor noise sigma [kPa] (metrics use the noise-free pressure)");
  sub->add_flag("--no-quantize", o->no_quantize, "Skip the uint16 sensor code");
  sub->add_option("--seed", o->seed, "Noise seed");
  sub->add_option("--bus-delay", o->bus_delay, "Extra command delay of the discrete loop [samples]");
  sub->add_flag("--json", o->json, "Print one JSON object");
  sub->add_flag("--online", o->online,
                "Beyond the thesis: compare the gains with a PI + deadzone inverse designed from the online RLS "
                "estimate, on the virtual pilot-valve rig and on B1 + a second pole");
  sub->add_option("--scenario", o->scenario,
                  "Closed-loop scenario TOML with a drifting rig (docs/compensation.md); the step options are ignored");
  sub->add_option("--compensation", o->compensation, "With --scenario: none | fixed | adaptive | oracle (default adaptive; oracle: the inverse fed the plant's true current parameters)");
  sub->add_option("-o,--output", o->out, "Write both traces as CSV");
  sub->add_option("--plot", o->plot, "Also render a PNG (needs -o)");
  add_controller_options(sub, o->controller, true);
  return {sub, [o] { return run(*o); }};
}

}  // namespace lash::cli
