#include "lash/experiments/scenario.hpp"

#include <algorithm>
#include <cmath>

#include "lash/identify/any_estimator.hpp"
#include "lash/identify/config_file.hpp"
#include "lash/io/error.hpp"
#include "lash/io/toml_util.hpp"
#include "lash/plant/plant_file.hpp"
#include "lash/plant/simulate.hpp"
#include "lash/io/numeric.hpp"

namespace lash {

namespace {
SideParams read_truth(TomlTable t) {
  SideParams p;
  p.a1 = t.number_or("a1", p.a1);
  p.b1 = t.number_or("b1", p.b1);
  p.c = t.number_or("c", p.c);
  p.d = t.number_or("d", p.d);
  p.identified = true;
  p.reason = Reason::none;
  t.finish();
  return p;
}
}  // namespace

ScenarioSpec load_scenario(const std::filesystem::path& path) {
  const toml::table root = parse_toml_file(path);
  TomlTable t(root, path.string());
  ScenarioSpec s;
  s.file = path.string();
  s.name = t.string("name");
  s.description = t.string_opt("description").value_or("");
  s.plant_file = path.parent_path() / t.string("plant");
  s.duration_s = t.number("duration");
  if (!(s.duration_s > 0)) t.fail("duration", "must be > 0 [s]");
  s.noise_variance = t.number_or("noise_variance", 0.0);
  if (!(s.noise_variance >= 0)) t.fail("noise_variance", "must be >= 0");
  if (auto seeds = t.numbers_opt("seeds")) {
    s.seeds.clear();
    for (double x : *seeds) {
      const auto seed = integral_as<std::uint64_t>(x);
      if (!seed || x != std::floor(x)) t.fail("seeds", "seeds are integers in 0..2^64-1");
      s.seeds.push_back(*seed);
    }
    if (s.seeds.empty()) t.fail("seeds", "at least one seed");
  }
  s.checkpoints_s = t.numbers_opt("checkpoints").value_or(std::vector<double>{});
  for (double c : s.checkpoints_s)
    if (!(c > 0 && c <= s.duration_s)) t.fail("checkpoints", "checkpoints must lie in (0, duration]");
  std::sort(s.checkpoints_s.begin(), s.checkpoints_s.end());
  if (s.checkpoints_s.empty() || s.checkpoints_s.back() != s.duration_s) s.checkpoints_s.push_back(s.duration_s);
  {
    TomlTable in = t.table("input");
    try {
      s.input.kind = parse_waveform(in.string("kind"));
    } catch (const std::invalid_argument& e) {
      in.fail("kind", e.what());
    }
    s.input.amplitude = in.number_or("amplitude", s.input.amplitude);
    s.input.frequency_rad_s = in.number_or("frequency", s.input.frequency_rad_s);
    s.input.offset = in.number_or("offset", 0.0);
    s.input.phase_rad = in.number_or("phase", 0.0);
    s.input.variance = in.number_or("variance", s.input.variance);
    s.input.tau_s = in.number_or("tau", s.input.tau_s);
    in.finish();
  }
  {
    TomlTable tr = t.table("truth");
    s.truth.right = read_truth(tr.table("right"));
    s.truth.left = read_truth(tr.table("left"));
    tr.finish();
  }
  if (auto m = t.table_opt("metrics")) {
    if (auto w = m->numbers_opt("outside_3sigma_window")) {
      if (w->size() != 2) m->fail("outside_3sigma_window", "expected [t0, t1] [s]");
      s.outside_t0_s = (*w)[0];
      s.outside_t1_s = (*w)[1];
    }
    if (auto w = m->numbers_opt("nrmse_window")) {
      if (w->size() != 2) m->fail("nrmse_window", "expected [t0, t1] [s]");
      s.nrmse_t0_s = (*w)[0];
      s.nrmse_t1_s = (*w)[1];
    }
    m->finish();
  }
  {
    TomlTable e = t.table("estimator");
    s.estimator = EstimatorConfig::thesis(ModelKind::deadzone_deadband);  // the file's keys over the thesis's settings
    read_estimator_config(e, s.estimator);
  }
  t.finish();
  // dt from the plant
  Plant plant = load_plant(s.plant_file);
  s.estimator.dt_s = plant.dt_s();
  try {
    s.estimator.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(s.file, t.line("estimator"), "estimator", e.what());
  }
  return s;
}

ScenarioRun run_scenario(const ScenarioSpec& s, std::uint64_t seed) {
  Plant plant = load_plant(s.plant_file);
  SimulationSpec spec;
  spec.input = s.input;
  spec.duration_s = s.duration_s;
  spec.noise_variance = s.noise_variance;
  spec.seed = seed;
  const SimulationTrace tr = simulate(plant, spec);
  const auto& t = tr.col("t");
  const auto& v = tr.col("v");
  const auto& y = tr.col("y");
  AnyEstimator est(s.estimator);
  ScenarioRun run;
  run.seed = seed;
  std::vector<double> ysim(tr.samples());
  std::size_t next = 0;
  for (std::size_t k = 0; k < tr.samples(); ++k) {
    est.step(v[k], y[k]);
    ysim[k] = est.simulated();
    // checkpoint c is reached after the sample whose count is round(c/T)
    while (next < s.checkpoints_s.size() &&
           k + 1 >= round_clamped<std::size_t>(s.checkpoints_s[next] / plant.dt_s(), 0, std::numeric_limits<std::size_t>::max())) {
      run.at.push_back({est.params(Side::right), est.params(Side::left)});
      ++next;
    }
  }
  while (run.at.size() < s.checkpoints_s.size()) run.at.push_back({est.params(Side::right), est.params(Side::left)});
  run.identified = est.identified();
  run.outside_per_1000 = s.noise_variance > 0
                             ? outside_3sigma_per_1000(t, y, ysim, std::sqrt(s.noise_variance), s.outside_t0_s,
                                                       s.outside_t1_s)
                             : std::numeric_limits<double>::quiet_NaN();
  run.nrmse = nrmse(t, y, ysim, s.nrmse_t0_s, s.nrmse_t1_s);
  return run;
}

}  // namespace lash
