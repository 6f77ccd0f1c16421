// lash simulate: run a plant file open loop and write t,v,y,… as CSV.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>

#include <fmt/core.h>

#include "cli_common.hpp"
#include "column_cursor.hpp"
#include "csv_stream.hpp"
#include "plot.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"
#include "lash/io/table.hpp"

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
  std::string input_file;       // t,v CSV (e.g. from lash excite): v sample by sample
  double duration = 10.0;
  bool duration_given = false;
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

// Every option checked before the first row: a value that makes a sample non-finite is refused
// here, naming the option and its range (exit 2), never written as inf or nan.
std::string g6(double x) { return fmt::format("{:.6g}", x); }

/// Rows of an --input-file held in memory; a longer file is read into a temporary file.
constexpr std::size_t kInputRowsInMemory = std::size_t{1} << 16;

/// file_max_abs: max |v| of the --input-file (< 0: no file).
void check_options(const SimulateOptions& o, const SimulationSpec& spec, const Plant& plant, std::size_t& n,
                   double file_max_abs) {
  auto finite = [](const char* name, double v, const char* unit) {
    if (!std::isfinite(v)) throw InputError("", 0, name, fmt::format("must be a finite number [{}], got {}", unit, v));
  };
  finite("--amplitude", o.amplitude, "input unit");
  finite("--offset", o.offset, "input unit");
  finite("--phase", o.phase, "rad");
  if (!(std::isfinite(o.frequency) && o.frequency >= 0))
    throw InputError("", 0, "--frequency", fmt::format("must be a finite number >= 0 [rad/s], got {}", o.frequency));
  if (spec.input.kind == Waveform::randomized) {
    if (!(std::isfinite(o.variance) && o.variance >= 0))
      throw InputError("", 0, "--variance", fmt::format("must be a finite number >= 0 [input unit^2], got {}", o.variance));
    if (!(std::isfinite(o.tau) && o.tau > 0))
      throw InputError("", 0, "--tau", fmt::format("must be a finite number > 0 [s], got {}", o.tau));
  }
  if (!(std::isfinite(o.noise_variance) && o.noise_variance >= 0))
    throw InputError("", 0, "--noise-variance", fmt::format("must be a finite number >= 0 [y unit^2], got {}", o.noise_variance));
  const double duration = spec.duration_s;
  if (!(std::isfinite(duration) && duration > 0))
    throw InputError("", 0, "--duration", fmt::format("must be a finite number > 0 [s], got {}", duration));
  try {
    n = sample_count(duration, plant.dt_s());
  } catch (const std::invalid_argument& e) {
    throw InputError("", 0, "--duration", fmt::format("{} s at dt = {} s: {} (at most 1e9 samples)", format_double(duration),
                                                      format_double(plant.dt_s()), e.what()));
  }
  // The plant's worst case over n samples (plant/simulate.hpp): the input must keep it below 1e300.
  const double limit = max_input_magnitude(plant, n);
  const double need = file_max_abs >= 0.0 ? file_max_abs + std::fabs(o.offset) : max_abs_value(spec.input);
  if (need <= limit) return;
  const OutputBound b = output_bound(plant, n);
  const std::string why =
      fmt::format("this plant's output over {} samples can reach {}*max|v| + {} (docs/simulate.md), which must stay "
                  "within 1e300",
                  n, g6(b.gain), g6(b.offset));
  if (!(limit > 0))
    throw InputError(o.plant, 0, "blocks",
                     fmt::format("no input is safe: {}; shorten --duration or use a stable plant", why));
  const double off = std::fabs(o.offset);
  if (!(off <= limit))
    throw InputError("", 0, "--offset", fmt::format("|offset| must be at most {} [input unit]: {}; got {}",
                                                    g6(limit), why, g6(o.offset)));
  switch (spec.input.kind) {
    case Waveform::steps:
      throw InputError("", 0, o.input_file.empty() ? "--steps" : "--input-file", fmt::format("every |VALUE| + |offset| must be at most {} [input unit]: {}",
                                                     g6(limit), why));
    case Waveform::randomized: {
      const double s = (limit - off) / 12.1;
      throw InputError("", 0, "--variance",
                       fmt::format("must be at most {} [input unit^2] (12.1 sigma + |offset| within {}): {}; got {}",
                                   g6(s * s), g6(limit), why, g6(o.variance)));
    }
    default:
      throw InputError("", 0, "--amplitude", fmt::format("|amplitude| + |offset| must be at most {} [input unit]: {}; got {}",
                                                         g6(limit), why, g6(o.amplitude)));
  }
}

int run(const SimulateOptions& o) {
  if (o.dt && !(*o.dt > 0 && std::isfinite(*o.dt)))
    throw InputError("", 0, "--dt", "sample period must be a finite number > 0 [s]");
  check_output_path(o.out, "--output");
  if (!o.plot.empty()) check_output_path(o.plot, "--plot");
  Plant plant = load_plant(o.plant, o.dt.value_or(0.0));
  SimulationSpec spec;
  double duration = o.duration;
  // --input-file: its t,v columns in a store (a long file goes to a temporary file, read back in
  // chunks as the simulation goes: memory does not grow with the file)
  Table table;       // a short file's columns (the store views them)
  ColumnStore file;
  double file_max_abs = 0.0;
  if (!o.input_file.empty()) {
    // the file's v, one sample per plant step: its t must step by the plant's dt
    TableOptions to;
    to.columns = {"t", "v"};
    to.strict = true;
    to.spill_after_rows = kInputRowsInMemory;
    table = read_table(o.input_file, to);
    file = table.store();
    const std::size_t rows = file.rows();
    if (rows < 2) throw InputError(o.input_file, 0, "--input-file", "needs at least 2 rows of t,v");
    const double step = (file.back(0) - file.at(0, 0)) / static_cast<double>(rows - 1);
    if (!(std::fabs(step - plant.dt_s()) <= 1e-6 * plant.dt_s()))
      throw InputError(o.input_file, 0, "--input-file",
                       fmt::format("t steps by {} s, the plant's dt is {} s (give --dt {})", format_double(step),
                                   format_double(plant.dt_s()), format_double(step)));
    for_chunks(file, std::array<std::size_t, 1>{1}, 0, rows, [&](std::size_t, const auto& c) {
      for (const double x : c[0]) file_max_abs = std::max(file_max_abs, std::fabs(x));
    });
    spec.input.kind = Waveform::steps;  // what the file is: a level per sample (for the checks' wording)
    if (!o.duration_given) duration = static_cast<double>(rows) * plant.dt_s();
  } else {
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
  }
  if (spec.input.kind == Waveform::steps && o.input_file.empty()) {
    if (o.steps.empty()) throw InputError("", 0, "--steps", "the steps input needs --steps TIME:VALUE,…");
    spec.input.steps = parse_steps(o.steps);
    try {
      Signal check(spec.input, plant.dt_s());
    } catch (const std::invalid_argument& e) {
      throw InputError("", 0, "--steps", e.what());
    }
  }
  spec.duration_s = duration;
  spec.noise_variance = o.noise_variance;
  spec.seed = o.seed;
  std::size_t n = 0;
  check_options(o, spec, plant, n, o.input_file.empty() ? -1.0 : file_max_abs);

  // Rows go to the file as they are produced: memory O(1) in the duration.
  CsvStream csv(o.out, simulation_columns(plant));
  const auto put = [&](std::span<const double> row) { csv.row(row); };
  if (o.input_file.empty()) {
    simulate_rows(plant, spec, put);
  } else {
    // v(k) = the file's row k (+ --offset), its last value after its end; read in chunks
    ColumnCursor v(file, 1);
    const std::size_t last = file.rows() - 1;
    simulate_rows(plant, spec, [&](std::size_t k) { return v.at(std::min(k, last)) + o.offset; }, put);
  }
  csv.commit();
  if (!o.plot.empty()) {
    plot_csv(o.out, o.plot, "lash simulate " + std::filesystem::path(o.plant).filename().string(),
             {{"input v", "t [s]"}, {"output y", "t [s]"}},
             {{"t", "v", "v", 0}, {"t", "y", "y", 1}});
  }
  fmt::print(stderr, "lash simulate: {} samples at dt = {} s -> {}\n", csv.rows(), format_double(plant.dt_s()), o.out);
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
  sub->add_option("--input-file", o->input_file,
                  "t,v CSV (e.g. from lash excite): the input sample by sample, t stepping by the plant's dt; "
                  "replaces --input; after its last row v holds its last value");
  sub->add_option("--duration", o->duration,
                  "Duration [s]; N = round(duration/dt) samples (with --input-file: default its length)");
  sub->add_option("--dt", o->dt, "Sample period [s], overrides the plant file's dt");
  sub->add_option("--noise-variance", o->noise_variance, "Variance of Gaussian noise added to y [y unit^2]");
  sub->add_option("--seed", o->seed, "Seed of the randomized input and the noise");
  sub->add_option("-o,--output", o->out, "Output CSV")->required();
  sub->add_option("--plot", o->plot, "Also render a PNG with gnuplot");
  return {sub, [o, sub] {
            o->duration_given = sub->get_option("--duration")->count() > 0;
            return run(*o);
          }};
}

}  // namespace lash::cli
