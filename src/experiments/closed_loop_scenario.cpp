#include "lash/experiments/closed_loop_scenario.hpp"

#include <algorithm>
#include <concepts>
#include <cmath>
#include <stdexcept>

#include "lash/control/controller_fields.hpp"
#include "lash/hil/node_run.hpp"
#include "lash/hil/schedule.hpp"
#include "lash/identify/config_file.hpp"
#include "lash/identify/verdict.hpp"
#include "lash/io/error.hpp"
#include "lash/io/toml_util.hpp"
#include "lash/rigs/coupled_carts.hpp"
#include "lash/rigs/drift.hpp"
#include "lash/rigs/pilot_valve_rig.hpp"
#include "lash/io/numeric.hpp"

namespace lash::experiments {
namespace {

std::int64_t step_of(double t_s, double dt_s) { return std::llround(t_s / dt_s); }

void read_reference(TomlTable& in, SignalSpec& s) {
  try {
    s.kind = parse_waveform(in.string("kind"));
  } catch (const std::invalid_argument& e) {
    in.fail("kind", e.what());
  }
  s.amplitude = in.number_or("amplitude", s.amplitude);
  s.frequency_rad_s = in.number_or("frequency", s.frequency_rad_s);
  s.offset = in.number_or("offset", 0.0);
  s.phase_rad = in.number_or("phase", 0.0);
  s.variance = in.number_or("variance", s.variance);
  s.tau_s = in.number_or("tau", s.tau_s);
  if (auto seed = in.integer_opt("seed")) s.seed = static_cast<std::uint64_t>(*seed);
  in.finish();
}

void read_controller(TomlTable& c, ClosedLoopScenario& s) {
  for (const char* k : {"dt_s", "dt"})
    if (c.has(k)) c.fail(k, "the controller runs at the scenario's dt_s; remove it here");
  s.feedforward = c.number_or("feedforward", 0.0);
  s.command_min = c.number_or("min", s.command_min);
  s.command_max = c.number_or("max", s.command_max);
  if (!(s.command_min <= s.command_max)) c.fail("max", "needs min <= max (the rig input's saturation)");
  // The PID: the [pid] keys of a gains file (control/controller_fields.hpp; ki, kd, n are the
  // deprecated aliases of ki_per_s, kd_s, n_per_s), in the rig's units; the anti-windup limits
  // default to the saturation.
  s.pid.output_min = s.command_min;
  s.pid.output_max = s.command_max;
  read_pid_fields(c, s.pid);
  c.finish();
}

double edge(TomlTable& t, std::string_view key, double fallback, double sign, const char* unit) {
  const double v = t.number_or(key, fallback);
  if (sign > 0 && !(v >= 0)) t.fail(key, std::string("must be >= 0 [") + unit + "] (wrong sign?)");
  if (sign < 0 && !(v <= 0)) t.fail(key, std::string("must be <= 0 [") + unit + "] (wrong sign?)");
  return v;
}

void read_compensation(TomlTable& c, ClosedLoopScenario& s) {
  AdaptationSettings& a = s.adaptation;
  const bool valve = s.rig == rigs::RigKind::pilot_valve;
  if (valve) {
    const auto& p = s.rig_config.pilot_valve;
    s.deadzone.offset_right = edge(c, "deadzone_right", p.deadzone_right_mA, +1, "mA");
    s.deadzone.offset_left = -edge(c, "deadzone_left", p.deadzone_left_mA, -1, "mA");
    s.deadzone.slope_right = c.number_or("slope_right", 1.0);
    if (!(s.deadzone.slope_right > 0)) c.fail("slope_right", "must be > 0");
    s.deadzone.slope_left = c.number_or("slope_left", 1.0);
    if (!(s.deadzone.slope_left > 0)) c.fail("slope_left", "must be > 0");
    s.deadzone.smoothing = edge(c, "smoothing", 0.0, +1, "mA");
    for (const char* k : {"deadband_right", "deadband_left"})
      if (c.has(k)) c.fail(k, "belongs to the coupled_carts rig; the valve has deadzone_right/deadzone_left");
  } else {
    const double d = s.rig_config.coupled_carts.half_clearance_m;
    s.backlash.right = edge(c, "deadband_right", d, +1, "m");
    s.backlash.left = edge(c, "deadband_left", d, +1, "m");
    s.backlash.smoothing = edge(c, "smoothing", 0.0, +1, "m");
    for (const char* k : {"deadzone_right", "deadzone_left", "slope_right", "slope_left"})
      if (c.has(k)) c.fail(k, "belongs to the pilot_valve rig; the carts have deadband_right/deadband_left");
  }
  a.rate_limit_per_s = c.number_or("rate_limit", a.rate_limit_per_s);
  a.settle_s = c.number_or("settle_s", a.settle_s);
  a.hold_s = c.number_or("hold_s", a.hold_s);
  a.min_ratio = c.number_or("min_ratio", a.min_ratio);
  a.max_ratio = c.number_or("max_ratio", a.max_ratio);
  a.dither_amplitude = c.number_or("dither_amplitude", a.dither_amplitude);
  a.dither_period_s = c.number_or("dither_period_s", a.dither_period_s);
  a.min_excitation_ratio = c.number_or("min_excitation_ratio", a.min_excitation_ratio);
  a.tolerance_ratio = c.number_or("tolerance_ratio", a.tolerance_ratio);
  if (auto rg = c.boolean_opt("reguess")) s.reguess.enabled = *rg;
  try {
    a.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(c.file(), c.line(), c.path(""), e.what());
  }
  if (!valve) {
    // The estimator's known input shift (BacklashEstimatorConfig); the guesses follow it.
    BacklashEstimatorConfig& b = s.backlash_estimator;
    b.input_shift = c.number_or("input_shift", b.input_shift);
    if (!(b.input_shift > 0) || !std::isfinite(b.input_shift)) c.fail("input_shift", "must be > 0 [m]");
    b.guess_right = 1.5 * b.input_shift;
    b.guess_left = -1.5 * b.input_shift;
  } else if (c.has("input_shift")) {
    c.fail("input_shift", "belongs to the coupled_carts rig");
  }
  if (auto e = c.table_opt("estimator")) {
    EstimatorConfig& ec = valve ? s.estimator : s.backlash_estimator;
    try {
      read_estimator_config(*e, ec);
      ec.dt_s = s.dt_s;
      if (valve) ec.validate();
      else s.backlash_estimator.validate();
    } catch (const std::invalid_argument& ex) {
      throw InputError(e->file(), e->line(), e->path(""), ex.what());
    }
  }
  s.backlash_estimator.dt_s = s.dt_s;
  s.estimator.dt_s = s.dt_s;
  c.finish();
}

// The estimator defaults of each rig (overridable key by key in [compensation.estimator]).
EstimatorConfig default_estimator(const ClosedLoopScenario& s) {
  EstimatorConfig e = EstimatorConfig::thesis(ModelKind::deadzone_deadband, s.dt_s);
  if (s.rig == rigs::RigKind::pilot_valve) {
    e.model = ModelKind::input_deadzone;
    // Updates only well beyond the nominal edges: samples near the edge mix deadzone and slope.
    e.guess_right = 1.5 * s.rig_config.pilot_valve.deadzone_right_mA;
    e.guess_left = 1.5 * s.rig_config.pilot_valve.deadzone_left_mA;
    e.rls.lambda = 0.995;
    // Closed loop: the feedback makes v(k−1) and the sensor noise in y(k−1) correlated, which
    // biases least squares; the delayed-output instrument removes that bias (measured: the
    // drifted edge 380 mA is estimated as 368 mA by LS and 376 mA by IV).
    e.method = EstimationMethod::iv;
  }
  return e;
}

// The carts' estimator (docs/compensation.md): deadzone-deadband on (w ± s, y), s = 2 × the rig's
// half clearance, guesses ±1.5 s (updates where |w| > s/2), directional forgetting λ = 0.999:
// the engaged carts excite only some directions of [a1, b1, e] (y − w is constant), and
// exponential forgetting let the others wind up until the estimate left the physical range
// after the clearance drift (measured: unphysical on both sides from 25 s on).
BacklashEstimatorConfig default_backlash_estimator(const ClosedLoopScenario& s) {
  BacklashEstimatorConfig e;
  static_cast<EstimatorConfig&>(e) = EstimatorConfig::thesis(ModelKind::deadzone_deadband, s.dt_s);
  e.input_shift = 2.0 * s.rig_config.coupled_carts.half_clearance_m;
  e.guess_right = 1.5 * e.input_shift;
  e.guess_left = -1.5 * e.input_shift;
  e.rls.lambda = 0.999;
  e.rls.forgetting = Forgetting::directional;
  return e;
}

}  // namespace

ClosedLoopScenario load_closed_loop_scenario(const std::filesystem::path& path) {
  const toml::table root = parse_toml_file(path);
  TomlTable t(root, path.string());
  ClosedLoopScenario s;
  s.file = path.string();
  t.string_opt("name");
  try {
    s.rig = rigs::parse_rig_kind(t.string("rig"));
  } catch (const std::invalid_argument& e) {
    t.fail("rig", e.what());
  }
  if (s.rig == rigs::RigKind::motor_cart) t.fail("rig", "closed-loop scenarios support pilot_valve and coupled_carts");
  s.dt_s = t.number("dt_s");
  if (!(s.dt_s > 0)) t.fail("dt_s", "must be > 0 [s]");
  s.duration_s = t.number("duration_s");
  if (!(s.duration_s >= s.dt_s)) t.fail("duration_s", "must be at least one sample [s]");
  // Step numbers (of the run and of its drifts, which lie inside it) are uint32 in the plant.
  if (!round_to<std::uint32_t>(s.duration_s / s.dt_s))
    t.fail("duration_s", "must be at most 4294967295 samples of dt_s = " + std::to_string(s.dt_s) + " s");
  if (auto seed = t.integer_opt("seed")) s.seed = static_cast<std::uint64_t>(*seed);
  {
    auto rp = t.table_opt("rig_params");
    s.rig_config = rigs::read_rig_config(s.rig, rp ? &*rp : nullptr);
  }
  s.estimator = default_estimator(s);
  s.backlash_estimator = default_backlash_estimator(s);
  // Re-guessing (identify/reguess.hpp) is on for the valve. The carts' estimator sees the known
  // input shift: its edges sit at ±s + (c_r − c_l')/2 whatever the clearance, so the guesses
  // ±1.5 s stay outside them; its 8 s reference period is also longer than the in rule's memory.
  s.reguess.enabled = s.rig == rigs::RigKind::pilot_valve;
  // Drifts: each key is checked by the rig reader itself (unknown keys, invalid values).
  rigs::RigConfig current = s.rig_config;
  double last_at = -1.0, last_end = -1.0;
  for (TomlTable& d : t.tables("drift")) {
    Drift e;
    e.at_s = d.number("at_s");
    if (!(e.at_s > 0 && e.at_s < s.duration_s))
      d.fail("at_s", "must lie inside the run: 0 < at_s < duration_s = " + std::to_string(s.duration_s) + " s");
    if (e.at_s < last_at) d.fail("at_s", "drifts must be in time order");
    if (e.at_s < last_end)
      d.fail("at_s", "a drift starts after the previous ramp ended (at " + std::to_string(last_end) + " s)");
    e.ramp_s = d.number_or("ramp_s", 0.0);
    if (!(e.ramp_s >= 0 && e.at_s + e.ramp_s <= s.duration_s))
      d.fail("ramp_s", "must be >= 0 [s] and end inside the run (at_s + ramp_s <= duration_s = " +
                           std::to_string(s.duration_s) + " s)");
    last_at = e.at_s;
    last_end = e.ramp_s > 0 ? e.at_s + e.ramp_s : -1.0;
    e.param = d.string("param");
    e.value = d.number("value");
    if (s.rig == rigs::RigKind::coupled_carts && e.param != "free_mass_kg" && e.param != "free_coulomb_N" &&
        e.param != "free_static_N" && e.param != "half_clearance_m" && e.param != "restitution" &&
        e.param != "lock_speed_m_s")
      d.fail("param", "the coupled carts can drift free_mass_kg, free_coulomb_N, free_static_N, half_clearance_m, "
                      "restitution or lock_speed_m_s, not '" + e.param + "'");
    if (s.rig == rigs::RigKind::pilot_valve && (e.param == "substeps" || e.param == "bias_window_s"))
      d.fail("param", "'" + e.param + "' cannot change during a run");
    toml::table one;
    one.insert(e.param, e.value);
    try {
      TomlTable view(one, d.file());
      e.after = rigs::overlay_rig_config(current, &view);  // unknown key or invalid value → InputError
    } catch (const InputError& ex) {
      d.fail("param", "drift of '" + e.param + "' to " + std::to_string(e.value) + ": " + ex.message());
    }
    e.before = current;
    current = e.after;
    d.finish();
    s.drift.push_back(std::move(e));
  }
  {
    TomlTable r = t.table("reference");
    read_reference(r, s.reference);
  }
  {
    TomlTable c = t.table("controller");
    read_controller(c, s);
  }
  s.pid.dt_s = s.dt_s;
  {
    auto c = t.table_opt("compensation");
    if (c) read_compensation(*c, s);
  }
  const auto w = t.numbers("score_window_s");
  if (w.size() != 2) t.fail("score_window_s", "expected [t0, t1] [s]");
  s.score_t0_s = w[0];
  s.score_t1_s = w[1];
  if (!(0 <= s.score_t0_s && s.score_t0_s < s.score_t1_s && s.score_t1_s <= s.duration_s))
    t.fail("score_window_s", "must satisfy 0 <= t0 < t1 <= duration_s = " + std::to_string(s.duration_s) + " s");
  {
    // At least one sample k·dt_s inside the window, or the tracking figures have nothing to score.
    const double k0 = std::ceil(s.score_t0_s / s.dt_s - 1e-9), k1 = std::floor(s.score_t1_s / s.dt_s + 1e-9);
    if (!(k0 <= k1))
      t.fail("score_window_s", "holds no sample of dt_s = " + std::to_string(s.dt_s) + " s: widen it");
  }
  t.finish();
  try {
    Pid check(s.pid);
    Signal sig(s.reference, s.dt_s);
  } catch (const std::invalid_argument& e) {
    throw InputError(s.file, 0, "", e.what());
  }
  return s;
}

}  // namespace lash::experiments

namespace lash::experiments {
namespace {

double clamp(double x, double lo, double hi) noexcept { return x < lo ? lo : (x > hi ? hi : x); }

// A drift's length in control steps (0 = a step).
std::int64_t ramp_n(const Drift& d, double dt_s) { return std::llround(d.ramp_s / dt_s); }

// The scenario's drifts of one rig's parameters as segments (rigs/drift.hpp): a ramp is one
// segment, interpolated at each step (it was one entry per control step of the ramp).
template <class Params>
std::vector<rigs::DriftSegment<Params>> segments(const ClosedLoopScenario& s, Params rigs::RigConfig::*rig) {
  std::vector<rigs::DriftSegment<Params>> out;
  for (const Drift& d : s.drift) out.push_back({step_of(d.at_s, s.dt_s), ramp_n(d, s.dt_s), d.before.*rig, d.after.*rig});
  return out;
}

// ---------------------------------------------------------------------------------- the runner
// One loop for both rigs (run() below): each control step k the rig's policy runs its law, its
// plant and its sensor and reports one sample; the runner scores it (hil::ScenarioScore: the
// window, before and after the first drift), hands it to the trace, and at the end reads the
// compensator's state (hil::compensation_state). What differs between the rigs is only inside
// the policies: the valve runs on the bench's nodes (the HIL master's law, the slave's rig), the
// carts in process.

// One control step's sample (a row of the trace).
struct StepSample {
  double r = 0.0, y = 0.0, command = 0.0, right = 0.0, left = 0.0, drive = 0.0;
};

template <class Rig>
concept ScenarioRig = requires(Rig& rig, std::size_t k) {
  { rig.step(k) } -> std::same_as<StepSample>;
  { rig.compensation() } -> std::same_as<hil::CompensationState>;
};

// pilot_valve: the bench's master and slave nodes over the in-process link with the ideal
// schedule (hil::BenchSimulation, one control step per step()): the same step code, timing and
// bus quantisation as `lash hil run --scenario`, so that the figures agree bit for bit. The
// slave applies the drifts and the master feeds the oracle from the same segments
// (RigPlant::drift, CompensatedLaw::oracle). O(1) memory: the nodes keep one row each.
class ValveBench {
 public:
  ValveBench(const ClosedLoopScenario& s, CompensationMode mode, std::size_t n)
      : settings_(bench(s, mode)),
        schedule_(hil::lazy_ideal_schedule(n)),
        sink_{[this](const hil::MasterStepLog& l) { master_ = l; },
              [this](const hil::SlaveStepLog& l) { slave_ = l; }},
        sim_(layout_, hil::master_config(settings_, ""), hil::slave_config(settings_, layout_), schedule_, sink_) {}

  // Control step k pairs the master's row of control step k with slave step k's pressure (the
  // noise-free rig pressure, the y(k) the master's sensor frame carried with noise).
  StepSample step(std::size_t k) {
    if (!sim_.advance() || master_.control_step != static_cast<std::int64_t>(k) || slave_.step != k)
      throw std::logic_error("closed-loop scenario: the bench simulation left the ideal schedule at control step " +
                             std::to_string(k));
    return {master_.reference_kPa, slave_.pressure_kPa, master_.current_mA,
            master_.inverse_right_mA, master_.inverse_left_mA, 0.0};
  }
  hil::CompensationState compensation() { return sim_.finish().compensation; }
  const hil::BenchScenario& scenario() const { return *settings_.scenario; }

 private:
  static hil::BenchSettings bench(const ClosedLoopScenario& s, CompensationMode mode) {
    hil::BenchSettings b;
    apply_to_bench(s, mode, b);
    return b;
  }
  const hil::BenchLayout layout_;  // the layout of config/hydraulic_bench.dbc
  hil::BenchSettings settings_;
  hil::FrameSchedule schedule_;
  hil::SimulationSink sink_;
  hil::MasterStepLog master_;
  hil::SlaveStepLog slave_;
  hil::BenchSimulation sim_;
};

// coupled_carts: position control of the free cart through the clearance, in process. The
// reference r is the free cart's desired position; the motor cart's target is w* = BI(r) (the
// backlash compensator); v = sat(PID(w* − w) + k_ff·(w* − w*(k−1))/T); the compensator observes
// (w, y). The drift segments move the rig, and the oracle gets the true half clearance, each step.
class CartsLoop {
 public:
  CartsLoop(const ClosedLoopScenario& s, CompensationMode mode)
      : s_(s),
        comp_(config(s, mode)),
        rig_(s.rig_config.coupled_carts, s.dt_s, s.seed),
        pid_(s.pid),
        ref_(s.reference, s.dt_s),
        drift_(segments(s, &rigs::RigConfig::coupled_carts)),
        truth_(s.rig_config.coupled_carts.half_clearance_m),
        y_(rig_.free_position_m()),
        w_(rig_.motor_position_m()) {}

  StepSample step(std::size_t k) noexcept {
    if (const rigs::CoupledCartsParams* p = cursor_.advance(drift_, static_cast<std::int64_t>(k))) {
      rig_.set_params(*p);
      truth_ = p->half_clearance_m;
    }
    comp_.set_oracle(truth_, truth_);  // oracle only (false otherwise)
    const double r = ref_.next();
    if (k == 0) {
      comp_.reset(r);
      wstar1_ = comp_.command(r);
    }
    const double wstar = comp_.command(r);
    const double ff = s_.feedforward * (wstar - wstar1_) / s_.dt_s;  // velocity feedforward
    wstar1_ = wstar;
    const double v = clamp(pid_.step(wstar - w_) + ff, s_.command_min, s_.command_max);
    comp_.observe(w_, y_, true);  // simulated: every sample fresh
    const PerSide<double> used = comp_.in_use();
    const StepSample out{r, y_, v, used.right, used.left, w_};
    rig_.step(v);
    y_ = rig_.free_position_m();
    w_ = rig_.motor_position_m();
    return out;
  }
  hil::CompensationState compensation() const noexcept { return hil::compensation_state(comp_); }

 private:
  static BacklashCompensationConfig config(const ClosedLoopScenario& s, CompensationMode mode) {
    BacklashCompensationConfig cc;
    cc.mode = mode;
    cc.nominal = s.backlash;
    cc.estimator = s.backlash_estimator;
    cc.adaptation = s.adaptation;
    cc.reguess = s.reguess;
    return cc;
  }
  const ClosedLoopScenario& s_;
  BacklashCompensator comp_;
  rigs::CoupledCarts rig_;
  Pid pid_;
  Signal ref_;
  std::vector<rigs::DriftSegment<rigs::CoupledCartsParams>> drift_;
  rigs::DriftCursor<rigs::CoupledCartsParams> cursor_;
  double truth_, y_, w_;
  double wstar1_ = 0.0;
};

hil::BenchScenario score_spec(const ClosedLoopScenario& s, CompensationMode mode) {
  hil::BenchScenario b;
  b.file = s.file;
  b.mode = mode;
  b.score_t0_s = s.score_t0_s;
  b.score_t1_s = s.score_t1_s;
  b.first_drift_s = s.drift.empty() ? -1.0 : static_cast<double>(step_of(s.drift.front().at_s, s.dt_s)) * s.dt_s;
  return b;
}

template <ScenarioRig Rig>
ClosedLoopScenarioResult run(const ClosedLoopScenario& s, CompensationMode mode, std::size_t n, Rig& rig,
                             const ScenarioRowFn& row) {
  hil::ScenarioScore score(score_spec(s, mode), s.dt_s);
  for (std::size_t k = 0; k < n; ++k) {
    const StepSample x = rig.step(k);
    score.add(k, x.r, x.y);
    if (row) row({static_cast<double>(k) * s.dt_s, x.r, x.y, x.command, x.right, x.left, x.drive});
  }
  const hil::CompensationState c = rig.compensation();
  const hil::ScenarioFigures f = score.result(c);
  ClosedLoopScenarioResult res;
  res.mode = mode;
  res.samples = n;
  res.rms_error = f.window.rms_error;
  res.max_abs_error = f.window.max_abs_error;
  res.final_right = c.right;
  res.final_left = c.left;
  res.updates = c.updates;
  res.reguesses_right = c.reguesses_right;
  res.reguesses_left = c.reguesses_left;
  res.guess_right = c.guess_right;
  res.guess_left = c.guess_left;
  res.events = c.events;
  res.reason = c.reason;
  res.estimator_identified = c.estimator_identified;
  res.estimator_reason = c.estimator_reason;
  if (s.rig == rigs::RigKind::pilot_valve) res.bench = f;
  return res;
}

}  // namespace

rigs::RigConfig rig_config_at(const ClosedLoopScenario& s, std::int64_t k) {
  rigs::RigConfig c = s.rig_config;
  for (const Drift& d : s.drift) {
    const std::int64_t k0 = step_of(d.at_s, s.dt_s), n = ramp_n(d, s.dt_s);
    if (k < k0) break;
    if (n == 0 || k >= k0 + n) {
      c = d.after;
      continue;
    }
    const double f = static_cast<double>(k - k0) / static_cast<double>(n);
    c = d.after;
    c.pilot_valve = rigs::lerp(d.before.pilot_valve, d.after.pilot_valve, f);
    c.coupled_carts = rigs::lerp(d.before.coupled_carts, d.after.coupled_carts, f);
    return c;
  }
  return c;
}

void apply_to_bench(const ClosedLoopScenario& s, CompensationMode mode, hil::BenchSettings& b) {
  if (s.rig != rigs::RigKind::pilot_valve)
    throw InputError(s.file, 0, "rig",
                     std::string("the HIL bench is the pilot valve (pressure control); a '") + rigs::to_string(s.rig) +
                         "' scenario runs in `lash closed-loop --scenario` only");
  if (s.command_min < -2000.0 || s.command_max > 2000.0)
    throw InputError(s.file, 0, s.command_min < -2000.0 ? "controller.min" : "controller.max",
                     "the bench drives each solenoid with 0..2000 mA: [controller] min and max must lie in "
                     "-2000..2000 [mA]");
  b.set_step(s.dt_s);
  hil::BenchScenario h = score_spec(s, mode);
  h.plant.params = s.rig_config.pilot_valve;
  h.plant.seed = s.seed;
  h.plant.drift = segments(s, &rigs::RigConfig::pilot_valve);  // a ramp is one segment
  h.law.pid = s.pid;
  h.law.pid.dt_s = s.dt_s;
  h.law.feedforward = s.feedforward;
  h.law.command_min = s.command_min;
  h.law.command_max = s.command_max;
  h.law.compensation.mode = mode;
  h.law.compensation.nominal = s.deadzone;
  h.law.compensation.estimator = s.estimator;
  h.law.compensation.adaptation = s.adaptation;
  h.law.compensation.reguess = s.reguess;
  if (mode == CompensationMode::oracle) h.law.oracle = h.plant;  // the rig's true edges, the slave's drifts
  h.reference = s.reference;
  h.duration_s = s.duration_s;
  b.scenario = std::move(h);
}

ClosedLoopScenarioResult run_closed_loop_scenario(const ClosedLoopScenario& s, CompensationMode mode,
                                                  const ScenarioRowFn& row) {
  const auto n = static_cast<std::size_t>(step_of(s.duration_s, s.dt_s));
  if (s.rig == rigs::RigKind::pilot_valve) {
    ValveBench rig(s, mode, n);
    return run(s, mode, n, rig, row);
  }
  CartsLoop rig(s, mode);
  return run(s, mode, n, rig, row);
}

}  // namespace lash::experiments
