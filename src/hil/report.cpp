#include "lash/hil/report.hpp"
#include "lash/io/numeric.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "json_parts.hpp"

namespace lash::hil {

std::optional<StepWindow> find_step(const std::vector<double>& r, double dt_s, double min_hold_s,
                                    double max_window_s) {
  std::size_t level_start = 0;
  for (std::size_t k = 1; k < r.size(); ++k) {
    if (r[k] == r[k - 1]) continue;
    const double held = static_cast<double>(k - level_start) * dt_s;
    if (held + 1e-12 >= min_hold_s) {
      StepWindow w;
      w.begin = k;
      w.t_step_s = static_cast<double>(k) * dt_s;
      w.y0 = r[k - 1];
      w.y1 = r[k];
      std::size_t e = k + 1;
      const auto max_n = round_clamped<std::size_t>(max_window_s / dt_s, 0, std::numeric_limits<std::size_t>::max());
      while (e < r.size() && r[e] == r[k] && e - k < max_n) ++e;
      w.end = e;
      return w;
    }
    level_start = k;
  }
  return std::nullopt;
}

SimulationDiff compare_with_simulation(const std::vector<std::int64_t>& control_step,
                                       const std::vector<double>& measured_kPa, const std::vector<double>& current_mA,
                                       const std::vector<MasterStepLog>& simulated) {
  SimulationDiff d;
  // Index the simulation by control step.
  std::vector<const MasterStepLog*> by_m;
  for (const auto& s : simulated) {
    if (s.control_step < 0) continue;
    const auto m = static_cast<std::size_t>(s.control_step);
    if (by_m.size() <= m) by_m.resize(m + 1, nullptr);
    by_m[m] = &s;
  }
  for (std::size_t i = 0; i < control_step.size(); ++i) {
    if (control_step[i] < 0) continue;
    const auto m = static_cast<std::size_t>(control_step[i]);
    if (m >= by_m.size() || by_m[m] == nullptr) continue;
    d.add(control_step[i], measured_kPa[i], by_m[m]->measured_kPa, current_mA[i], by_m[m]->current_mA);
  }
  return d;
}

SimulationDiff compare_with_simulation(const std::vector<MasterStepLog>& emulated,
                                       const std::vector<MasterStepLog>& simulated) {
  std::vector<std::int64_t> m;
  std::vector<double> y, i;
  for (const auto& l : emulated) {
    m.push_back(l.control_step);
    y.push_back(l.measured_kPa);
    i.push_back(l.current_mA);
  }
  return compare_with_simulation(m, y, i, simulated);
}

std::optional<StepResponse> step_response(const std::vector<double>& reference_kPa, double dt_s,
                                          const std::vector<double>& pressure_kPa,
                                          const std::vector<double>* measured_kPa) {
  const std::optional<StepWindow> w = find_step(reference_kPa, dt_s);
  if (!w || w->end > pressure_kPa.size() || (measured_kPa != nullptr && w->end > measured_kPa->size()))
    return std::nullopt;
  const auto b = static_cast<std::ptrdiff_t>(w->begin), e = static_cast<std::ptrdiff_t>(w->end);
  std::vector<double> t;
  for (std::size_t i = w->begin; i < w->end; ++i) t.push_back(static_cast<double>(i) * dt_s);
  StepResponse r;
  r.window = *w;
  r.plant = step_metrics(t, std::vector<double>(pressure_kPa.begin() + b, pressure_kPa.begin() + e), w->t_step_s,
                         w->y0, w->y1);
  if (measured_kPa != nullptr)
    r.measured = step_metrics(t, std::vector<double>(measured_kPa->begin() + b, measured_kPa->begin() + e),
                              w->t_step_s, w->y0, w->y1);
  return r;
}

StepResponseStream::StepResponseStream(double dt_s, bool with_measured, double min_hold_s, double max_window_s)
    : dt_s_(dt_s),
      min_hold_s_(min_hold_s),
      with_measured_(with_measured),
      max_n_(round_clamped<std::size_t>(max_window_s / dt_s, 0, std::numeric_limits<std::size_t>::max())) {}

// find_step() one sample at a time: the window is the samples k.. of the first jump whose level
// was held min_hold_s, up to the next jump or max_window_s.
void StepResponseStream::add(double r, double p, double y) {
  const std::size_t k = k_++;
  if (open_) {
    if (r == w_.y1 && k - w_.begin < max_n_) {
      p_.push_back(p);
      if (with_measured_) y_.push_back(y);
      w_.end = k + 1;
    } else {
      open_ = false;
    }
  } else if (!found_ && k > 0 && r != prev_) {
    const double held = static_cast<double>(k - level_start_) * dt_s_;
    if (held + 1e-12 >= min_hold_s_) {
      found_ = open_ = true;
      w_.begin = k;
      w_.end = k + 1;
      w_.t_step_s = static_cast<double>(k) * dt_s_;
      w_.y0 = prev_;
      w_.y1 = r;
      p_.push_back(p);
      if (with_measured_) y_.push_back(y);
    } else {
      level_start_ = k;
    }
  }
  prev_ = r;
}

std::optional<StepResponse> StepResponseStream::result() const {
  if (!found_) return std::nullopt;
  std::vector<double> t;
  for (std::size_t i = w_.begin; i < w_.end; ++i) t.push_back(static_cast<double>(i) * dt_s_);
  StepResponse r;
  r.window = w_;
  r.plant = step_metrics(t, p_, w_.t_step_s, w_.y0, w_.y1);
  if (with_measured_) r.measured = step_metrics(t, y_, w_.t_step_s, w_.y0, w_.y1);
  return r;
}

std::size_t off_schedule_steps(const std::vector<MasterStepLog>& master, const std::vector<SlaveStepLog>& slave,
                               std::int64_t control_steps) {
  std::set<std::int64_t> off;
  for (const auto& l : master)
    if (l.control_step >= 0 &&
        (!l.sensor_fresh || l.sensor_counter != static_cast<std::uint16_t>(l.control_step)))
      off.insert(l.control_step);
  for (const auto& l : slave) {
    const auto s = static_cast<std::int64_t>(l.step);
    if (s > 0 && s < control_steps &&
        (!l.command_fresh || l.command_counter != static_cast<std::uint64_t>(s - 1)))
      off.insert(s);
  }
  return off.size();
}

void TrackingAccumulator::add(std::size_t m, double r, double y) noexcept {
  const double t = static_cast<double>(m) * dt_s_;
  if (t < w_.t0_s - 1e-12 || t > w_.t1_s + 1e-12) return;
  const double e = r - y;
  sum2_ += e * e;
  w_.max_abs_error = std::max(w_.max_abs_error, std::fabs(e));
  ++w_.samples;
}

Tracking TrackingAccumulator::result() const noexcept {
  Tracking w = w_;
  w.rms_error = w.samples ? std::sqrt(sum2_ / static_cast<double>(w.samples)) : std::nan("");
  return w;
}

Tracking tracking(const std::vector<double>& reference, const std::vector<double>& output, double dt_s, double t0_s,
                  double t1_s) {
  TrackingAccumulator a(dt_s, t0_s, t1_s);
  const std::size_t n = std::min(reference.size(), output.size());
  for (std::size_t m = 0; m < n; ++m) a.add(m, reference[m], output[m]);
  return a.result();
}

namespace {
// [0, drift): the last sample before the drift's control step.
double before_end_s(double first_drift_s, double dt_s) {
  return static_cast<double>(std::llround(first_drift_s / dt_s) - 1) * dt_s;
}
}  // namespace

ScenarioScore::ScenarioScore(const BenchScenario& s, double dt_s) noexcept
    : file_(s.file),
      mode_(s.mode),
      dt_s_(dt_s),
      first_drift_s_(s.first_drift_s),
      window_(dt_s, s.score_t0_s, s.score_t1_s),
      before_(dt_s, 0.0, s.first_drift_s >= 0 ? before_end_s(s.first_drift_s, dt_s) : 0.0),
      after_(dt_s, s.first_drift_s, std::numeric_limits<double>::infinity()) {}

void ScenarioScore::add(std::size_t m, double r, double y) noexcept {
  window_.add(m, r, y);
  if (first_drift_s_ >= 0) {
    before_.add(m, r, y);
    after_.add(m, r, y);
  }
  samples_ = m + 1;
}

ScenarioFigures ScenarioScore::result(const CompensationState& compensation) const {
  ScenarioFigures f;
  f.file = file_;
  f.mode = mode_;
  f.window = window_.result();
  const double end = static_cast<double>(samples_) * dt_s_;
  if (first_drift_s_ >= 0) {  // a run that ended before the drift has no "after"
    f.before_drift = before_.result();
    if (first_drift_s_ < end) {
      Tracking a = after_.result();
      a.t1_s = end;  // every sample added lies before the end
      f.after_drift = a;
    }
  }
  f.compensation = compensation;
  return f;
}

ScenarioFigures scenario_figures(const BenchScenario& s, double dt_s, const std::vector<MasterStepLog>& master,
                                 const std::vector<SlaveStepLog>& slave, const CompensationState& compensation) {
  // Control step m pairs the master's r(m) with slave step m's pressure.
  ScenarioScore score(s, dt_s);
  std::size_t m = 0;
  auto ml = master.begin();
  for (const auto& sl : slave) {
    while (ml != master.end() && ml->control_step < 0) ++ml;
    if (ml == master.end()) break;
    score.add(m++, ml->reference_kPa, sl.pressure_kPa);
    ++ml;
  }
  return score.result(compensation);
}

NodeFigures node_figures(const NodeStats& stats, const LoopTrace& loop) {
  NodeFigures f;
  const bool kept = !loop.records.empty();  // else: the node's log writer's statistics
  f.tet_us = kept ? rt::tet_us(loop.records) : stats.tet_us;
  f.io_us = kept ? rt::io_us(loop.records) : stats.io_us;
  f.cycle_us = kept ? rt::cycle_us(loop.records) : stats.cycle_us;
  f.wake_latency_us = kept ? rt::wake_latency_us(loop.records) : stats.wake_latency_us;
  f.logs = stats.logs;
  f.peak_rss_kB = stats.peak_rss_kB;
  f.steps = stats.result.steps;
  f.overruns = stats.result.overruns;
  f.frames = stats.frames;
  f.warnings = loop.warnings;
  f.dma_latency_held = stats.dma_latency_held;
  return f;
}

void report_nodes(RunReport& rep, const MasterRun* master, const std::vector<SlaveRun>& slaves,
                  const std::function<NodeFigures(const NodeStats&, const LoopTrace&, bool is_master)>& figures) {
  rep.have_master = master != nullptr;
  rep.have_slave = !slaves.empty();
  rep.frames = {};
  auto add = [&](const FrameStats& f) {
    rep.frames.sent += f.sent;
    rep.frames.received += f.received;
    rep.frames.late += f.late;
    rep.frames.lost += f.lost;
  };
  for (const auto& s : slaves) add(s.stats.frames);
  if (rep.have_slave) {
    rep.slave = figures(slaves[0].stats, slaves[0].loop, false);
    rep.slave.recovered = rep.slave_recovered;
    rep.slave_events = slaves[0].events;
    rep.slave_state = slaves[0].stats.state;
  }
  if (!master) return;
  add(master->stats.frames);
  rep.master = figures(master->stats, master->loop, true);
  rep.master.recovered = rep.master_recovered;
  rep.handshake_s = master->stats.handshake_s;
  rep.control_steps = master->stats.control_steps;
  rep.events = master->events;
  rep.master_state = master->stats.state;
}

void make_run_report(RunReport& rep, const MasterRun* master, const std::vector<SlaveRun>& slaves,
                     const std::vector<MasterStepLog>& simulated, const BenchScenario* scenario) {
  report_nodes(rep, master, slaves,
               [](const NodeStats& s, const LoopTrace& l, bool) { return node_figures(s, l); });
  if (!master) return;
  rep.vs_simulation = compare_with_simulation(master->log, simulated);
  rep.off_schedule = off_schedule_steps(master->log, rep.have_slave ? slaves[0].log : std::vector<SlaveStepLog>{},
                                        rep.control_steps);
  // Step response on the emulated plant pressure (slave step s = control step m).
  if (rep.have_slave) {
    std::vector<double> ref, p, y;
    for (const auto& l : master->log)
      if (l.control_step >= 0) ref.push_back(l.reference_kPa);
    for (const auto& l : slaves[0].log) {
      p.push_back(l.pressure_kPa);
      y.push_back(l.measured_kPa);
    }
    rep.step = step_response(ref, rep.step_s, p, &y);
    if (scenario)
      rep.scenario = scenario_figures(*scenario, rep.step_s, master->log, slaves[0].log, master->stats.compensation);
  }
}

namespace {
using nlohmann::json;

json node_json(const NodeFigures& f) {
  return json{{"tet_us", detail::summary_json(f.tet_us)},
              {"io_us", detail::summary_json(f.io_us)},
              {"cycle_us", detail::summary_json(f.cycle_us)},
              {"wake_latency_us", detail::summary_json(f.wake_latency_us)},
              {"overruns", f.overruns},
              {"steps", f.steps},
              {"frames", detail::frames_json(f.frames)},
              {"warnings", f.warnings},
              {"dma_latency_held", f.dma_latency_held},
              {"peak_rss_kB", f.peak_rss_kB},
              {"logs", {{"rows", f.logs.rows}, {"ring_full", f.logs.ring_full}, {"writes", f.logs.writes}}},
              {"recovered_from_log", f.recovered ? json{{"file", f.recovered->file},
                                                        {"rows", f.recovered->rows},
                                                        {"cut_lines", f.recovered->cut_lines},
                                                        {"last_t_s", f.recovered->last_t_s}}
                                                  : json(nullptr)}};
}

json exit_json(const NodeExit& e) {
  json j{{"exited", e.exited}, {"status", e.status}, {"t_s", e.t_s}};
  if (e.signal) j["signal"] = e.signal;
  return j;
}

json num(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json tracking_json(const Tracking& t) {
  return json{{"rms_error", num(t.rms_error)}, {"max_abs_error", num(t.max_abs_error)}, {"unit", "kPa"},
              {"window_s", {t.t0_s, t.t1_s}}, {"samples", t.samples}};
}

json metrics_json(const StepMetrics& m) {
  return json{{"rise_s", m.rise_s}, {"settling_s", m.settling_s}, {"overshoot_pct", m.overshoot_pct}};
}
}  // namespace

std::string scenario_json(const ScenarioFigures& f) {
  const CompensationState& c = f.compensation;
  json j;
  j["scenario"] = f.file;
  j["rig"] = "pilot_valve";
  j["compensation_mode"] = to_string(f.mode);
  j["score_window_s"] = {f.window.t0_s, f.window.t1_s};
  j["tracking"] = tracking_json(f.window);
  if (f.before_drift) j["tracking_before_drift"] = tracking_json(*f.before_drift);
  if (f.after_drift) j["tracking_after_drift"] = tracking_json(*f.after_drift);
  // final_mode: the mode at the end, as calibrated over XCP (compensation_mode: the start's).
  j["compensation"] = {
      {"final", {{"right", c.right}, {"left", c.left}}}, {"final_mode", to_string(c.mode)}, {"unit", "mA"}};
  j["adaptation"] = {{"updates", c.updates},
                     {"reason", to_string(c.reason)},
                     {"estimator_identified", c.estimator_identified},
                     {"estimator_reason", std::string(c.estimator_reason)}};
  return j.dump();
}

std::string run_report_json(const RunReport& r) {
  json out;
  out["duration_s"] = r.duration_s;
  out["step_ms"] = r.step_s * 1e3;
  out["reference"] = r.reference;
  out["isolation"] = r.isolation;
  out["bus"] = r.bus;
  out["interrupted"] = r.interrupted;
  if (r.interrupted) out["interrupt_signal"] = r.interrupt_signal;
  out["master_exit"] = exit_json(r.master_exit);
  json se = json::array();
  for (const auto& e : r.slave_exits) se.push_back(exit_json(e));
  out["slave_exits"] = se;
  json rs = json::array();
  for (const auto& g : r.restarts) {
    json j{{"died", exit_json(g.died)}, {"restarted_s", g.restarted_s}};
    if (g.restarted_s >= 0) j["gap_s"] = g.gap_s();
    rs.push_back(j);
  }
  out["slave_restarts"] = rs;
  if (r.have_master) {
    out["master"] = node_json(r.master);
    out["master"]["handshake_s"] = r.handshake_s;
    out["master"]["events"] = detail::events_json(r.events);
    out["master"]["state"] = to_string(r.master_state);
    out["master"]["control_steps"] = r.control_steps;
  }
  if (r.have_slave) {
    out["slave"] = node_json(r.slave);
    out["slave"]["events"] = detail::events_json(r.slave_events);
    out["slave"]["state"] = to_string(r.slave_state);
  }
  out["frames"] = {{"sent", r.frames.sent}, {"received", r.frames.received}, {"late", r.frames.late},
                   {"lost", r.frames.lost}};
  json step = json::object();
  if (r.step) {
    const auto& w = r.step->window;
    step = metrics_json(r.step->plant);
    step["t_step_s"] = w.t_step_s;
    step["from_kPa"] = w.y0;
    step["to_kPa"] = w.y1;
    step["signal"] = "plant pressure (noise-free, slave log)";
    if (r.step->measured) step["measured"] = metrics_json(*r.step->measured);
  }
  out["step_response"] = step;
  if (r.have_master) {
    out["max_abs_diff_vs_simulation_kPa"] = r.vs_simulation.max_abs_diff_kPa;
    out["max_abs_diff_vs_simulation_mA"] = r.vs_simulation.max_abs_diff_mA;
    out["compared_steps"] = r.vs_simulation.compared;
    if (r.vs_simulation.first_diff_step) out["first_diff_control_step"] = *r.vs_simulation.first_diff_step;
    out["off_schedule_steps"] = r.off_schedule;
    if (r.vs_observed_schedule) {
      out["max_abs_diff_vs_observed_schedule_kPa"] = r.vs_observed_schedule->max_abs_diff_kPa;
      out["max_abs_diff_vs_observed_schedule_mA"] = r.vs_observed_schedule->max_abs_diff_mA;
      out["observed_schedule_compared_steps"] = r.vs_observed_schedule->compared;
    } else {
      out["max_abs_diff_vs_observed_schedule_kPa"] = nullptr;
      out["observed_schedule_note"] = r.observed_schedule_note;
    }
  }
  if (r.scenario) {  // the keys of `lash closed-loop --json` (scenario_json)
    const json sj = json::parse(scenario_json(*r.scenario));
    for (auto& [k, v] : sj.items()) out[k] = v;
  }
  out["out_dir"] = r.out_dir;
  if (r.session_peak_rss_kB >= 0) out["session_peak_rss_kB"] = r.session_peak_rss_kB;
  return out.dump(2) + "\n";
}

}  // namespace lash::hil
