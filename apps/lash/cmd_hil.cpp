// lash hil: real-time HIL emulation of the hydraulic bench (thesis paper 2, docs/method.md §B).
//   lash hil slave    — slave ECU + pilot-valve plant emulator on a bus
//   lash hil master   — master ECU (CCP connect, PID + deadzone inverse + saturation)
//   lash hil latency  — the periodic loop alone
//   lash hil run      — both as separate processes on a private UDP bus, with a report
//   lash hil simulate — the same step functions in a closed-loop simulation
// Options are parsed and checked here; the work is in src/hil (node_run, session, report).
#include "cmd_hil.hpp"

#include <cmath>
#include <filesystem>

#include <fmt/core.h>

#include "lash/experiments/closed_loop_scenario.hpp"
#include "lash/io/csv.hpp"

namespace lash::cli::hilcli {

void add_common(CLI::App* sub, CommonOptions& o) {
  sub->option_defaults()->always_capture_default();
  sub->add_option("--config", o.config, "Node settings (TOML); default config/hil/bench.toml");
  sub->add_option("--bus", o.bus, "Bus address (udp:GROUP:PORT, mem:NAME, socketcan:IF); default from the settings");
  sub->add_option("--step-ms", o.step_ms,
                  "Fixed step [ms], " + format_double(hil::kMinStepMs) + ".." + format_double(hil::kMaxStepMs) +
                      " (0 = from the settings: 5 ms)")
      ->check(CLI::Range(0.0, hil::kMaxStepMs));
  sub->add_option("--fifo", o.fifo, "SCHED_FIFO priority 1..99 (0 = default scheduler)")->check(CLI::Range(0, 99));
  sub->add_option("--cpu", o.cpu, "Pin the loop to this CPU (-1 = no pinning)")->check(CLI::Range(-1, 4095));
  sub->add_option("--spin-us", o.spin_us,
                  "Wake this long before each release and busy-wait to it [us], >= 0 and < the step (0 = sleep only)")
      ->check(CLI::Range(0.0, hil::kMaxStepMs * 1e3));
  sub->add_flag("--lock-memory", o.lock_memory, "mlockall() the process");
  sub->add_flag("--no-dma-latency", o.no_dma_latency,
                "Do not hold /dev/cpu_dma_latency at 0 us while the loop runs (held by default, as cyclictest does)");
  sub->add_option("--overrun-policy", o.overrun_policy, "tolerate | stop")
      ->check(CLI::IsMember({"tolerate", "stop"}));
  sub->add_option("--max-overruns", o.max_overruns, "Policy stop: stop after this many consecutive overruns (>= 1)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1000000}));
}

void add_scenario(CLI::App* sub, CommonOptions& o) {
  sub->add_option("--scenario", o.scenario,
                  "Closed-loop scenario TOML of the pilot valve (docs/compensation.md): the slave runs its rig and "
                  "drifts, the master its controller, compensation and reference (--reference is ignored)");
  sub->add_option("--compensation", o.compensation, "With --scenario: none | fixed | adaptive")
      ->check(CLI::IsMember({"none", "fixed", "adaptive"}))
      ->each([&o](const std::string&) { o.compensation_given = true; });
}

void add_controller(CLI::App* sub, CommonOptions& o) { add_controller_options(sub, o.controller, false); }

CLI::Option* add_duration(CLI::App* sub, double& value, const std::string& what) {
  const double max_s = static_cast<double>(hil::kMaxSteps) * 5e-3;
  return sub
      ->add_option("--duration", value,
                   what + " [s], > 0; at most " + std::to_string(hil::kMaxSteps) + " steps (" +
                       format_double(max_s) + " s at 5 ms; the logs are streamed to disk)")
      ->check(CLI::PositiveNumber);
}

std::string settings_path(const CommonOptions& o) {
  return o.config.empty() ? hil::default_settings_path(source_dir()).string() : o.config;
}

hil::BenchSettings load_settings(const CommonOptions& o) {
  hil::BenchSettings s = hil::load_bench_settings(settings_path(o));
  for (const auto& w : s.warnings) fmt::print(stderr, "lash: warning: {}\n", w);
  if (!o.bus.empty()) s.bus = o.bus;
  if (o.step_ms != 0.0) {
    if (!(o.step_ms >= hil::kMinStepMs) || !std::isfinite(o.step_ms))
      throw InputError("", 0, "--step-ms", "must be in " + format_double(hil::kMinStepMs) + ".." +
                                               format_double(hil::kMaxStepMs) + " [ms]");
    s.set_step(o.step_ms * 1e-3);
  }
  if (o.compensation_given && o.scenario.empty())
    throw InputError("", 0, "--compensation", "needs --scenario (the bench's own controller has its fixed offset)");
  if (!o.controller.empty()) {
    if (!o.scenario.empty())
      throw InputError("", 0, std::string("--") + o.controller.front().field->flag,
                       "with --scenario the scenario's [controller] table sets the controller");
    apply_controller_overrides(s.controller, o.controller);
  }
  if (!o.scenario.empty()) {
    const experiments::ClosedLoopScenario sc = experiments::load_closed_loop_scenario(o.scenario);
    if (o.step_ms != 0.0 && std::fabs(o.step_ms * 1e-3 - sc.dt_s) > 1e-9 * sc.dt_s)
      throw InputError("", 0, "--step-ms", "the scenario " + o.scenario + " runs at its dt_s = " +
                                               format_double(sc.dt_s * 1e3) + " ms; drop --step-ms");
    experiments::apply_to_bench(sc, parse_compensation_mode(o.compensation.c_str()), s);
  }
  return s;
}

hil::LoopOptions loop_options(const CommonOptions& o, const hil::BenchSettings& s) {
  hil::LoopOptions l;
  l.step_s = s.step_s;
  l.fifo = o.fifo;
  l.cpu = o.cpu;
  l.spin_us = o.spin_us;
  l.lock_memory = o.lock_memory;
  l.hold_dma_latency = !o.no_dma_latency;
  l.policy = hil::parse_overrun_policy(o.overrun_policy);
  l.max_overruns = o.max_overruns;
  l.validate();
  return l;
}

InputError with_option_names(const InputError& e) {
  // The library names the fields of its structs (LoopOptions, NodeLaunch, SessionOptions);
  // a person typed these options.
  static const std::pair<const char*, const char*> kFlags[] = {
      {"loop.step_s", "--step-ms"},         {"loop.fifo", "--fifo"},
      {"loop.cpu", "--cpu"},                {"loop.spin_us", "--spin-us"},
      {"loop.max_overruns", "--max-overruns"}, {"loop.policy", "--overrun-policy"},
      {"duration_s", "--duration"},         {"connect_timeout_s", "--connect-timeout"},
      {"dto_timeout_s", "--dto-timeout"},   {"reference", "--reference"},
      {"slave_cpu", "--slave-cpu"},         {"out_dir", "--out-dir"},
      {"isolate", "--no-isolate"}};
  for (const auto& [field, flag] : kFlags)
    if (e.field() == field) return InputError(e.file(), e.line(), flag, e.message());
  return e;
}

}  // namespace lash::cli::hilcli

namespace lash::cli {

Command add_hil(CLI::App& app) {
  auto* hil = app.add_subcommand("hil", "Real-time HIL emulation of the hydraulic bench over CAN (docs/method.md §B)");
  hil->require_subcommand(1);
  auto nodes = std::make_shared<std::function<int()>>();
  auto run = std::make_shared<std::function<int()>>();
  auto a2l = std::make_shared<std::function<int()>>();
  hilcli::add_hil_nodes(hil, *nodes);
  hilcli::add_hil_run(hil, *run);
  hilcli::add_hil_a2l(hil, *a2l);
  return {hil, [=] {
            try {
              int rc = (*nodes)();
              if (rc < 0) rc = (*run)();
              return rc >= 0 ? rc : (*a2l)();
            } catch (const InputError& e) {
              throw hilcli::with_option_names(e);
            }
          }};
}

}  // namespace lash::cli
