#include "lash/experiments/campaign.hpp"

#include "lash/identify/auto.hpp"
#include "lash/identify/config_file.hpp"

#include <cmath>
#include <stdexcept>

#include "lash/io/error.hpp"
#include "lash/io/toml_util.hpp"

namespace lash::sweep {

std::uint64_t run_seed(std::uint64_t base, std::size_t index) noexcept {
  std::uint64_t z = base + 0x9e3779b97f4a7c15ULL * (static_cast<std::uint64_t>(index) + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

namespace {

std::vector<double> nonempty_numbers(TomlTable& t, const char* key, bool positive) {
  auto v = t.numbers(key);
  if (v.empty()) t.fail(key, "is empty; the campaign matrix needs at least one value");
  for (double x : v)
    if (positive ? !(x > 0) : false) t.fail(key, "every value must be > 0");
  return v;
}

/// The `[estimator]` table: exactly the layout of `lash estimate --config` files
/// (lash::read_estimator_config, docs/identification.md) over lash's settings for the rig, or over
/// the thesis's with `preset = "thesis"`; then validated as a whole.
void read_estimator(TomlTable& t, EstimatorConfig& e, rigs::RigKind kind) {
  if (auto p = t.string_opt("preset")) {
    Preset preset{};
    try {
      preset = parse_preset(*p);
    } catch (const std::invalid_argument& ex) {
      t.fail("preset", ex.what());
    }
    e = preset == Preset::thesis ? thesis_estimator(kind, e.dt_s) : lash_estimator(kind, e.dt_s);
  }
  read_estimator_config(t, e);
  try {
    e.validate();
  } catch (const std::invalid_argument& ex) {
    throw InputError(t.file(), t.line(), t.path(""), ex.what());
  }
}

}  // namespace

EstimatorConfig thesis_estimator(rigs::RigKind kind, double dt_s) {
  const ModelKind model = kind == rigs::RigKind::motor_cart    ? ModelKind::output_deadzone
                          : kind == rigs::RigKind::pilot_valve ? ModelKind::input_deadzone
                                                               : ModelKind::coupled_carts;
  EstimatorConfig e = EstimatorConfig::thesis(model, dt_s);
  switch (kind) {
    case rigs::RigKind::motor_cart: break;
    case rigs::RigKind::pilot_valve:
      e.guess_left = -500.0;
      e.guess_right = 500.0;
      e.rls.lower = {-1.0, 0.0001, -500.0};
      e.rls.upper = {0.0, 2.0, 500.0};
      break;
    case rigs::RigKind::coupled_carts: break;  // the thesis's |acceleration| <= 1 m/s^2, stage 2 from 7.5 s
  }
  return e;
}

EstimatorConfig lash_estimator(rigs::RigKind kind, double dt_s) {
  return preset_config(thesis_estimator(kind, dt_s).model, Preset::lash, dt_s);
}

Campaign load_campaign(const std::filesystem::path& path) {
  const toml::table root_tbl = parse_toml_file(path);
  TomlTable root(root_tbl, path.string());
  Campaign c;
  c.file = path.string();
  c.name = root.string_opt("name").value_or(path.stem().string());
  const std::string rig_name = root.string("rig");
  rigs::RigKind kind{};
  try {
    kind = rigs::parse_rig_kind(rig_name);
  } catch (const std::invalid_argument& e) {
    root.fail("rig", e.what());
  }
  c.dt_s = root.number("dt_s");
  if (!(c.dt_s > 0)) root.fail("dt_s", "must be > 0 [s]");
  c.duration_s = root.number("duration_s");
  if (!(c.duration_s > 0)) root.fail("duration_s", "must be > 0 [s]");
  if (c.duration_s / c.dt_s > 1e8) root.fail("duration_s", "more than 1e8 samples per run");
  if (auto w = root.numbers_opt("nrmse_window_s")) {
    if (w->size() != 2) root.fail("nrmse_window_s", "needs [start, end] in seconds");
    c.window_start_s = (*w)[0];
    c.window_end_s = (*w)[1];
  } else {
    c.window_start_s = std::min(7.5, 0.25 * c.duration_s);
    c.window_end_s = c.duration_s;
  }
  if (!(c.window_start_s >= 0 && c.window_end_s > c.window_start_s && c.window_start_s < c.duration_s))
    root.fail("nrmse_window_s", "needs 0 <= start < end and start < duration_s");
  c.good_nrmse = root.number_or("good_nrmse", c.good_nrmse);
  if (!(c.good_nrmse > 0)) root.fail("good_nrmse", "must be > 0 (a fraction: 0.10 = 10 %)");
  c.param_tolerance = root.number_or("param_tolerance", c.param_tolerance);
  if (!(c.param_tolerance > 0)) root.fail("param_tolerance", "must be > 0 (a fraction)");
  if (auto s = root.integer_opt("seed")) {
    if (*s < 0) root.fail("seed", "must be >= 0");
    c.seed = static_cast<std::uint64_t>(*s);
  }

  // The matrix: waveforms × amplitudes × frequencies × repeats.
  std::size_t matrix_runs = 0;
  if (auto m = root.table_opt("matrix")) {
    const auto wf_names = m->strings("waveforms");
    if (wf_names.empty()) m->fail("waveforms", "is empty; the campaign matrix needs at least one waveform");
    std::vector<Waveform> wfs;
    for (const auto& w : wf_names) {
      Waveform wf{};
      try {
        wf = parse_waveform(w);
      } catch (const std::invalid_argument& e) {
        m->fail("waveforms", e.what());
      }
      if (wf != Waveform::sine && wf != Waveform::square && wf != Waveform::triangle)
        m->fail("waveforms", "only sine, square and triangle form the matrix (randomized runs go in [randomized])");
      wfs.push_back(wf);
    }
    const auto amps = nonempty_numbers(*m, "amplitudes", true);
    const auto freqs = nonempty_numbers(*m, "frequencies_rad_s", true);
    const auto reps = m->integer("repeats");
    if (reps < 1 || reps > 1000) m->fail("repeats", "must be in 1..1000");
    m->finish();
    for (Waveform wf : wfs)
      for (double a : amps)
        for (double f : freqs)
          for (int r = 1; r <= reps; ++r) {
            RunSpec s;
            s.waveform = wf;
            s.amplitude = a;
            s.frequency_rad_s = f;
            s.repeat = r;
            c.runs.push_back(s);
          }
    matrix_runs = c.runs.size();
  }
  if (auto rt = root.table_opt("randomized")) {
    const auto n = rt->integer("runs");
    if (n < 0 || n > 100000) rt->fail("runs", "must be in 0..100000");
    c.random_variance = rt->number_or("variance", c.random_variance);
    if (!(c.random_variance > 0)) rt->fail("variance", "must be > 0");
    c.random_tau_s = rt->number_or("tau_s", c.random_tau_s);
    if (!(c.random_tau_s > 0)) rt->fail("tau_s", "must be > 0 [s]");
    rt->finish();
    for (int r = 1; r <= n; ++r) {
      RunSpec s;
      s.waveform = Waveform::randomized;
      s.repeat = r;
      c.runs.push_back(s);
    }
  }
  if (c.runs.empty())
    root.fail(matrix_runs == 0 && root.has("matrix") ? "matrix" : "randomized",
              "the campaign has no runs: give a [matrix] and/or [randomized] with runs > 0");
  for (std::size_t i = 0; i < c.runs.size(); ++i) {
    c.runs[i].index = i;
    c.runs[i].seed = run_seed(c.seed, i);
  }

  c.estimator = lash_estimator(kind, c.dt_s);
  c.estimator_from_data = !root.has("estimator");
  if (auto e = root.table_opt("estimator")) {
    read_estimator(*e, c.estimator, kind);
    // The models each rig's runner drives: one output, a deadzone on either side of the linear
    // part (cart, valve), or the two-stage coupled-carts model.
    const ModelKind m = c.estimator.model;
    const bool ok = kind == rigs::RigKind::coupled_carts
                        ? m == ModelKind::coupled_carts
                        : (m == ModelKind::input_deadzone || m == ModelKind::output_deadzone);
    if (!ok)
      e->fail("model", std::string("model '") + to_string(m) + "' does not run on rig '" + rig_name + "' (" +
                           (kind == rigs::RigKind::coupled_carts ? "coupled-carts" : "input-deadzone or output-deadzone") +
                           ")");
  }
  c.estimator.dt_s = c.dt_s;
  if (auto rp = root.table_opt("rig_params")) {
    c.rig = rigs::read_rig_config(kind, &*rp);
  } else {
    c.rig = rigs::read_rig_config(kind, nullptr);
  }
  root.finish();
  return c;
}

}  // namespace lash::sweep
