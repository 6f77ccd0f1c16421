// lash tune: reproducible search for PID gains matching step-response targets (tune.hpp).
#include <cmath>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "lash/io/atomic_file.hpp"
#include "lash/control/gains_file.hpp"
#include "lash/experiments/tune.hpp"

namespace lash::cli {
namespace {

struct Options {
  std::string target = "rise=0.11,settling=0.25,overshoot=59,ode3_overshoot=32";
  std::string weights;
  double r0 = 0.0, r1 = 1000.0;
  int samples = 30000, restarts = 16;
  bool tune_filter = false;
  std::int64_t seed = 1;
  bool json = false;
  std::string out;
};

int run(const Options& o) {
  TuneOptions t;
  try {
    parse_targets(o.target, t.targets);
    if (o.target.find("ode3_overshoot") == std::string::npos) t.targets.ode3_overshoot_pct.reset();
    if (!o.weights.empty()) parse_weights(o.weights, t.targets);
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, o.weights.empty() ? "--target" : "--target/--weights", e.what());
  }
  if (!std::isfinite(o.r0)) throw InputError("", 0, "--r0", "must be a finite pressure [kPa]");
  if (!std::isfinite(o.r1)) throw InputError("", 0, "--r1", "must be a finite pressure [kPa]");
  if (o.r0 == o.r1) throw InputError("", 0, "--r1", "must differ from --r0 (a step needs two levels)");
  if (!o.out.empty()) check_output_path(o.out, "--output");
  if (o.samples < 1) throw InputError("", 0, "--samples", "must be >= 1");
  if (o.restarts < 1) throw InputError("", 0, "--restarts", "must be >= 1");
  t.step.r0_kPa = o.r0;
  t.step.r1_kPa = o.r1;
  t.samples = o.samples;
  t.restarts = o.restarts;
  t.tune_filter = o.tune_filter;
  t.seed = static_cast<std::uint64_t>(o.seed);
  const TuneResult r = tune_pid(t);
  ControllerConfig c = t.controller;
  c.pid.gains = r.gains;
  const std::string cmd = fmt::format(
      "lash tune --target {} --weights rise={},settling={},overshoot={},ode3={} --r0 {} --r1 {} --samples {} "
      "--restarts {} --seed {}{}",
      o.target, format_double(t.targets.w_rise), format_double(t.targets.w_settling),
      format_double(t.targets.w_overshoot), format_double(t.targets.w_ode3), format_double(o.r0), format_double(o.r1),
      o.samples, o.restarts, o.seed, o.tune_filter ? " --tune-filter" : "");
  if (!o.out.empty()) {
    const std::string comment = fmt::format(
        "Found by: {}\ndiscrete: rise90 {} s, settle10 {} s, overshoot {} %\node3:     rise90 {} s, settle10 {} s, "
        "overshoot {} %\ncost {} after {} evaluations",
        cmd, format_double(r.discrete.rise_s), format_double(r.discrete.settling_s),
        format_double(r.discrete.overshoot_pct), format_double(r.ode3.rise_s), format_double(r.ode3.settling_s),
        format_double(r.ode3.overshoot_pct), format_double(r.cost), r.evaluations);
    AtomicFile f(o.out);
    f.stream() << controller_config_toml(c, comment);
    f.commit();
  }
  if (o.json) {
    nlohmann::json j;
    j["gains"] = {{"kp", r.gains.kp}, {"ki", r.gains.ki_per_s}, {"kd", r.gains.kd_s}, {"n", r.gains.n_per_s}};
    j["discrete"] = {{"rise_s", r.discrete.rise_s}, {"settling_s", r.discrete.settling_s},
                     {"overshoot_pct", r.discrete.overshoot_pct}};
    j["ode3"] = {{"rise_s", r.ode3.rise_s}, {"settling_s", r.ode3.settling_s}, {"overshoot_pct", r.ode3.overshoot_pct}};
    j["cost"] = r.cost;
    j["evaluations"] = r.evaluations;
    fmt::print("{}\n", j.dump());
  } else {
    fmt::print("{}\n", cmd);
    fmt::print("gains: kp = {} mA/kPa, ki = {} mA/(kPa s), kd = {} mA s/kPa, n = {} 1/s\n", format_double(r.gains.kp),
               format_double(r.gains.ki_per_s), format_double(r.gains.kd_s), format_double(r.gains.n_per_s));
    fmt::print("discrete: rise90 {:.4f} s, settle10 {:.4f} s, overshoot {:.2f} %\n", r.discrete.rise_s,
               r.discrete.settling_s, r.discrete.overshoot_pct);
    fmt::print("ode3:     rise90 {:.4f} s, settle10 {:.4f} s, overshoot {:.2f} %\n", r.ode3.rise_s, r.ode3.settling_s,
               r.ode3.overshoot_pct);
    fmt::print("cost {:.5f} after {} evaluations\n", r.cost, r.evaluations);
  }
  return kExitOk;
}

}  // namespace

Command add_tune(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* sub = app.add_subcommand("tune", "Search PID gains whose discrete step response matches targets (reproducible)");
  sub->option_defaults()->always_capture_default();
  sub->add_option("--target", o->target, "rise=S,settling=S,overshoot=PCT[,ode3_overshoot=PCT]");
  sub->add_option("--weights", o->weights, "rise=W,settling=W,overshoot=W,ode3=W (default 1,0.1,1,0.1)");
  sub->add_option("--r0", o->r0, "Step from [kPa], finite, != --r1");
  sub->add_option("--r1", o->r1, "Step to [kPa], finite, != --r0");
  sub->add_option("--samples", o->samples, "Random samples of the gain box, 1..10000000")
      ->check(CLI::Range(1, 10'000'000));
  sub->add_option("--restarts", o->restarts, "Nelder-Mead restarts from the best samples, 1..10000")
      ->check(CLI::Range(1, 10'000));
  sub->add_flag("--tune-filter", o->tune_filter, "Also search the derivative filter N (default N = 0)");
  sub->add_option("--seed", o->seed, "Search seed, >= 0")->check(CLI::Range(std::int64_t{0}, INT64_MAX));
  sub->add_flag("--json", o->json, "Print one JSON object");
  sub->add_option("-o,--output", o->out, "Write the gains as a controller TOML (checked before the search)");
  return {sub, [o] { return run(*o); }};
}

}  // namespace lash::cli
