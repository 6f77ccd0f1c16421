// lash simulate: run a plant file open loop and write t,v,y,… as CSV.
#include <cstdint>
#include <filesystem>
#include <optional>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "plot.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"

namespace lash::cli {
namespace {

struct SimulateOptions {
  std::string plant;
  std::string input = "sine";
  double amplitude = 1.0;
  double frequency = 1.0;
  double offset = 0.0;
  double phase = 0.0;
  double variance = 10000.0;
  double tau = 0.5;
  std::string steps;
  double duration = 10.0;
  std::optional<double> dt;
  double noise_variance = 0.0;
  std::uint64_t seed = 1;
  std::string out;
  std::string plot;
};

std::vector<StepLevel> parse_steps(const std::string& text) {
  // "t0:v0,t1:v1,…" [s]:[input unit]
  std::vector<StepLevel> out;
  std::size_t start = 0;
  while (start < text.size()) {
    auto end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    const auto colon = item.find(':');
    StepLevel s;
    if (colon == std::string::npos || !parse_double(item.substr(0, colon), s.t_s) ||
        !parse_double(item.substr(colon + 1), s.value))
      throw InputError("", 0, "--steps", "expected TIME:VALUE pairs separated by commas, got '" + item + "'");
    out.push_back(s);
    start = end + 1;
  }
  return out;
}

int run(const SimulateOptions& o) {
  if (o.dt && !(*o.dt > 0)) throw InputError("", 0, "--dt", "sample period must be > 0 [s]");
  Plant plant = load_plant(o.plant, o.dt.value_or(0.0));
  SimulationSpec spec;
  try {
    spec.input.kind = parse_waveform(o.input);
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, "--input", e.what());
  }
  spec.input.amplitude = o.amplitude;
  spec.input.frequency_rad_s = o.frequency;
  spec.input.offset = o.offset;
  spec.input.phase_rad = o.phase;
  spec.input.variance = o.variance;
  spec.input.tau_s = o.tau;
  if (spec.input.kind == Waveform::steps) {
    if (o.steps.empty()) throw InputError("", 0, "--steps", "the steps input needs --steps TIME:VALUE,…");
    spec.input.steps = parse_steps(o.steps);
  }
  spec.duration_s = o.duration;
  spec.noise_variance = o.noise_variance;
  spec.seed = o.seed;
  if (!(o.noise_variance >= 0)) throw InputError("", 0, "--noise-variance", "must be >= 0");
  if (!(o.duration > 0)) throw InputError("", 0, "--duration", "must be > 0 [s]");
  SimulationTrace tr = simulate(plant, spec);

  std::vector<const std::vector<double>*> cols;
  for (const auto& c : tr.cols) cols.push_back(&c);
  write_columns_csv(o.out, tr.names, cols);
  if (!o.plot.empty()) {
    plot_csv(o.out, o.plot, "lash simulate " + std::filesystem::path(o.plant).filename().string(),
             {{"input v", "t [s]"}, {"output y", "t [s]"}},
             {{"t", "v", "v", 0}, {"t", "y", "y", 1}});
  }
  fmt::print(stderr, "lash simulate: {} samples at dt = {} s -> {}\n", tr.samples(), format_double(plant.dt_s()),
             o.out);
  return kExitOk;
}

}  // namespace

Command add_simulate(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  auto* sub = app.add_subcommand("simulate", "Simulate a plant file open loop and write t,v,y,... as CSV");
  sub->add_option("plant", o->plant, "Plant file (TOML, see docs/plant-files.md)")->required();
  sub->add_option("--input", o->input, "sine | square | triangle | randomized | steps | constant");
  sub->add_option("--amplitude", o->amplitude, "Amplitude A [input unit]");
  sub->add_option("--frequency", o->frequency, "Frequency w [rad/s]");
  sub->add_option("--offset", o->offset, "Constant added to the input [input unit]");
  sub->add_option("--phase", o->phase, "Phase added to w t [rad]");
  sub->add_option("--variance", o->variance, "randomized: variance of the Gaussian drawn each step");
  sub->add_option("--tau", o->tau, "randomized: low-pass time constant [s]");
  sub->add_option("--steps", o->steps, "steps: TIME:VALUE,TIME:VALUE,... [s]:[input unit]");
  sub->add_option("--duration", o->duration, "Duration [s]; N = round(duration/dt) samples");
  sub->add_option("--dt", o->dt, "Sample period [s], overrides the plant file's dt");
  sub->add_option("--noise-variance", o->noise_variance, "Variance of Gaussian noise added to y [y unit^2]");
  sub->add_option("--seed", o->seed, "Seed of the randomized input and the noise");
  sub->add_option("-o,--output", o->out, "Output CSV")->required();
  sub->add_option("--plot", o->plot, "Also render a PNG with gnuplot");
  return {sub, [o] { return run(*o); }};
}

}  // namespace lash::cli
