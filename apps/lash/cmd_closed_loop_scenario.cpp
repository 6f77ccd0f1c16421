// lash closed-loop --scenario FILE.toml --compensation none|fixed|adaptive: a closed-loop
// scenario with a drifting rig (lash/experiments/closed_loop_scenario.hpp); parse, call, print.
#include <cmath>
#include <optional>
#include <span>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "csv_stream.hpp"
#include "plot.hpp"
#include "lash/experiments/closed_loop_scenario.hpp"

namespace lash::cli {

int run_closed_loop_scenario_cmd(const std::string& path, const std::string& compensation, bool json,
                                 const std::string& out, const std::string& plot) {
  CompensationMode mode;
  try {
    mode = parse_compensation_mode(compensation.c_str());
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, "--compensation", e.what());
  }
  const experiments::ClosedLoopScenario s = experiments::load_closed_loop_scenario(path);
  const bool valve = s.rig == rigs::RigKind::pilot_valve;
  const char* unit = valve ? "kPa" : "m";
  const char* punit = valve ? "mA" : "m";
  if (!out.empty()) check_output_path(out, "--output");
  if (!plot.empty()) {
    if (out.empty()) throw InputError("", 0, "--plot", "needs -o FILE (the plot is drawn from it)");
    check_output_path(plot, "--plot");
  }
  const std::string y = valve ? "pressure_kPa" : "free_position_m";
  const std::string ref = valve ? "reference_kPa" : "reference_m";
  const std::string cmd = valve ? "current_mA" : "voltage_V";
  const std::string pr = valve ? "edge_right_mA" : "deadband_right_m";
  const std::string pl = valve ? "edge_left_mA" : "deadband_left_m";
  // The trace goes to the file row by row as the run produces it; nothing is kept for it.
  std::optional<CsvStream> csv;
  experiments::ScenarioRowFn row;
  if (!out.empty()) {
    std::vector<std::string> names{"t", ref, y, cmd, pr, pl};
    if (!valve) names.push_back("motor_position_m");
    csv.emplace(out, names);
    row = [&csv, valve](const experiments::ClosedLoopScenarioRow& r) {
      const double v[7] = {r.t_s, r.reference, r.output, r.command, r.param_right, r.param_left, r.drive};
      csv->row(std::span<const double>(v, valve ? 6 : 7));
    };
  }
  const experiments::ClosedLoopScenarioResult r = experiments::run_closed_loop_scenario(s, mode, row);
  if (csv) {
    csv->commit();
    if (!plot.empty())
      plot_csv(out, plot, fmt::format("lash closed-loop {} ({})", path, compensation),
               {{fmt::format("output [{}]", unit), "t [s]"}, {fmt::format("inverse [{}]", punit), "t [s]"}},
               {{"t", ref, "reference", 0}, {"t", y, "output", 0}, {"t", pr, "right", 1}, {"t", pl, "left", 1}});
  }
  // A figure that is not a number says why, and the run then did not produce what was asked.
  const bool complete = std::isfinite(r.rms_error) && std::isfinite(r.max_abs_error) && std::isfinite(r.final_right) &&
                        std::isfinite(r.final_left);
  const std::string why =
      complete ? "" : "not_finite: the closed loop's output or the inverse's parameters were not finite numbers (it diverged)";
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  if (json) {
    nlohmann::json j;
    j["scenario"] = path;
    j["rig"] = rigs::to_string(s.rig);
    j["compensation_mode"] = to_string(mode);
    j["score_window_s"] = {s.score_t0_s, s.score_t1_s};
    j["samples"] = r.samples;
    j["tracking"] = {{"rms_error", num(r.rms_error)}, {"max_abs_error", num(r.max_abs_error)}, {"unit", unit}};
    j["compensation"] = {{"final", {{"right", num(r.final_right)}, {"left", num(r.final_left)}}}, {"unit", punit}};
    j["complete"] = complete;
    if (!complete) j["reason"] = why;
    j["adaptation"] = {{"updates", r.updates},
                       {"reason", to_string(r.reason)},
                       {"estimator_identified", r.estimator_identified},
                       {"estimator_reason", r.estimator_reason},
                       {"dither_amplitude", s.adaptation.dither_amplitude},
                       {"dither_period_s", s.adaptation.dither_period_s},
                       {"reguesses", {{"right", r.reguesses_right}, {"left", r.reguesses_left}}}};
    // The estimator inside the adaptive compensator and its excitation settings (docs/compensation.md).
    const EstimatorConfig& e = valve ? s.estimator : s.backlash_estimator;
    j["adaptation"]["estimator"] = {{"model", to_string(e.model)},
                                    {"lambda", e.rls.lambda},
                                    {"forgetting", to_string(e.rls.forgetting)},
                                    {"guess_right", e.guess_right},
                                    {"guess_left", e.guess_left},
                                    {"reguess", s.reguess.enabled}};
    {
      // re-guesses and drift events: valve edges [mA], carts gaps [m]; a re-guess's values are the
      // estimator's guesses (carts: on the shifted input w +- s [m])
      nlohmann::json ev = nlohmann::json::array();
      for (std::uint32_t i = 0; i < r.events.n; ++i) {
        const AdaptationEvent& ae = r.events.events[i];
        const bool drift = ae.kind == AdaptationEvent::Kind::drift;
        nlohmann::json x = {{"kind", to_string(ae.kind)},
                            {"t_s", static_cast<double>(ae.sample) * s.dt_s},
                            {"parameter", std::string(drift ? (valve ? "edge_" : "deadband_") : "guess_") +
                                              (ae.side == Side::right ? "right" : "left")},
                            {"old", num(ae.old_value)},
                            {"new", num(ae.new_value)},
                            {"size", num(ae.new_value - ae.old_value)}};
        if (!drift) x["rule"] = to_string(ae.rule);
        ev.push_back(std::move(x));
      }
      j["adaptation"]["events"] = std::move(ev);
      j["adaptation"]["events_dropped"] = r.events.dropped;
    }
    if (mode == CompensationMode::adaptive)
      j["adaptation"]["estimator"]["final_guess"] = {{"right", r.guess_right}, {"left", r.guess_left}};
    if (!valve) j["adaptation"]["estimator"]["input_shift"] = s.backlash_estimator.input_shift;
    if (r.bench) {  // valve: the bench's figures before and after the first drift too
      const auto b = nlohmann::json::parse(hil::scenario_json(*r.bench));
      for (const char* k : {"tracking_before_drift", "tracking_after_drift"})
        if (b.contains(k)) j[k] = b[k];
    }
    fmt::print("{}\n", j.dump());
    return complete ? kExitOk : kExitFailed;
  }
  fmt::print("scenario {} ({}), compensation {}\n", path, rigs::to_string(s.rig), to_string(mode));
  fmt::print("tracking over [{}, {}] s: rms error {:.6g} {}, max |error| {:.6g} {}\n", s.score_t0_s, s.score_t1_s,
             r.rms_error, unit, r.max_abs_error, unit);
  fmt::print("inverse at the end: right {:.6g} {}, left {:.6g} {}; {} parameter updates\n", r.final_right, punit,
             r.final_left, punit, r.updates);
  if (mode == CompensationMode::adaptive) {
    fmt::print("adaptation: {} (estimator: {})\n", to_string(r.reason), r.estimator_reason);
    fmt::print("re-guesses: right {}, left {}; guesses at the end: right {:.6g} {}, left {:.6g} {}\n",
               r.reguesses_right, r.reguesses_left, r.guess_right, punit, r.guess_left, punit);
  }
  for (std::uint32_t i = 0; i < r.events.n; ++i) {
    const AdaptationEvent& e = r.events.events[i];
    const char* side = e.side == Side::right ? "right" : "left";
    if (e.kind == AdaptationEvent::Kind::drift)
      fmt::print("  {:8.3f} s drift of the {} {}: {:.6g} -> {:.6g} {} (size {:+.6g})\n",
                 static_cast<double>(e.sample) * s.dt_s, side, valve ? "edge" : "deadband", e.old_value,
                 e.new_value, punit, e.new_value - e.old_value);
    else
      fmt::print("  {:8.3f} s re-guess ({}) of the {} guess: {:.6g} -> {:.6g}\n",
                 static_cast<double>(e.sample) * s.dt_s, to_string(e.rule), side, e.old_value, e.new_value);
  }
  if (r.events.dropped > 0) fmt::print("  ({} more events not recorded)\n", r.events.dropped);
  if (!complete) {
    fmt::print("figures incomplete: {}\n", why);
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace lash::cli
