#include "lash/identify/estimate_report.hpp"

#include <cmath>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "lash/identify/estimators.hpp"
#include "lash/io/table.hpp"

namespace lash {
namespace {
using Json = nlohmann::ordered_json;

Json num(double x) { return std::isfinite(x) ? Json(x) : Json(); }
Json reason(Reason r) { return r == Reason::none ? Json() : Json(to_string(r)); }
Json interval(const Interval& iv) { return iv.valid() && std::isfinite(iv.lo) && std::isfinite(iv.hi) ? Json::array({iv.lo, iv.hi}) : Json(); }
Json updates(const std::vector<std::pair<std::string, std::uint64_t>>& u) {
  Json j = Json::object();
  for (const auto& [k, n] : u) j[k] = n;
  return j;
}

/// One side's (linear: the model's) keys, the ones of before first.
void put_side(Json& j, const EstimateReport& r, const SideReport& s) {
  j["a1"] = num(s.params.a1);
  j["b1"] = num(s.params.b1);
  if (r.has_c) j["c"] = num(s.params.c);
  if (r.has_side_d) j["d"] = num(s.params.d);
  j["identified"] = s.params.identified;
  j["updates"] = updates(s.updates);
  j["reason"] = reason(s.params.reason);
  j["K"] = num(s.K);
  j["tau_s"] = num(s.tau_s);
  Json ci = Json::object();
  ci["a1"] = interval(s.ci95.a1);
  ci["b1"] = interval(s.ci95.b1);
  if (r.has_c) ci["c"] = interval(s.ci95.c);
  if (r.has_side_d) ci["d"] = interval(s.ci95.d);
  ci["K"] = interval(s.ci95.K);
  ci["tau_s"] = interval(s.ci95.tau_s);
  j["ci95"] = ci;
}

/// 6 significant digits for a person ("-" for a missing value).
std::string sig(double x) { return std::isfinite(x) ? fmt::format("{:.6g}", x) : std::string("-"); }
std::string sig(const Interval& iv) {
  return iv.valid() ? fmt::format("[{}, {}]", sig(iv.lo), sig(iv.hi)) : std::string("-");
}

/// Whether some side (linear: the model) has an estimate. Without one the free run ran on the
/// recursion's unsettled values (an unstable a1 gave NRMSEs of 1e69 %): no fit to report.
bool has_estimate(const EstimateReport& r) {
  const auto est = [](const SideReport& s) { return std::isfinite(s.params.a1) && std::isfinite(s.params.b1); };
  return est(r.right) || (r.model != ModelKind::linear && est(r.left));
}
}  // namespace

std::string estimate_json(const EstimateReport& r, const ReportFit& fit) {
  Json j;
  j["model"] = to_string(r.model);
  j["samples"] = r.samples;
  if (r.model == ModelKind::linear) {
    put_side(j, r, r.right);
  } else {
    put_side(j["right"], r, r.right);
    put_side(j["left"], r, r.left);
  }
  if (r.has_shared_d) {
    j["d"] = num(r.d);
    j["d_updates"] = updates(r.d_updates);
    j["d_reason"] = reason(r.d_reason);
    j["d_ci95"] = interval(r.right.ci95.d);
  }
  const double nrmse = has_estimate(r) ? fit.nrmse : std::nan("");
  j["nrmse"] = num(nrmse);
  j["nrmse_pct"] = num(100.0 * nrmse);
  j["nrmse_window_s"] = {fit.t0_s, fit.t1_s};
  j["rows_skipped"] = fit.rows_skipped;
  j["samples_skipped"] = r.skipped;  // the text's "N skipped"
  j["gaps"] = fit.gaps;
  return j.dump();
}

std::string estimate_text(const EstimateReport& r, double dt_s, const ReportFit& fit) {
  std::string out = fmt::format("model {}: {} samples at dt = {} s, {} skipped\n", to_string(r.model), r.samples,
                                sig(dt_s), r.skipped);
  if (fit.rows_skipped)
    out += fmt::format("data: {} rows with a non-finite value skipped (the first at line {})\n", fit.rows_skipped,
                       fit.first_skipped_line);
  if (fit.gaps)
    out += fmt::format("data: {} gaps in t (steps > {} x the median step {} s)\n", fit.gaps, sig(kGapFactor),
                       sig(fit.median_dt_s));
  auto show = [&](const char* name, const SideReport& s) {
    std::string line = fmt::format("{:>6}: a1 = {}  b1 = {}", name, sig(s.params.a1), sig(s.params.b1));
    if (r.has_c) line += "  c = " + sig(s.params.c);
    if (r.has_side_d) line += "  d = " + sig(s.params.d);
    line += "  K = " + sig(s.K) + "  tau = " + sig(s.tau_s) + " s";
    line += s.params.identified ? "  identified" : fmt::format("  NOT identified ({})", to_string(s.params.reason));
    line += "  updates";
    for (const auto& [k, n] : s.updates) line += fmt::format(" {}:{}", k, n);
    out += line + "\n";
    if (s.ci95.a1.valid()) {
      std::string ci = fmt::format("        95 %: a1 {}  b1 {}", sig(s.ci95.a1), sig(s.ci95.b1));
      if (r.has_c) ci += "  c " + sig(s.ci95.c);
      if (r.has_side_d) ci += "  d " + sig(s.ci95.d);
      ci += "  K " + sig(s.ci95.K) + "  tau " + sig(s.ci95.tau_s);
      out += ci + "\n";
    } else if (s.params.reason == Reason::uncertain) {  // check 8 without intervals
      out += "        95 %: none (too few sections identify this side)\n";
    }
  };
  if (r.model == ModelKind::linear) show("model", r.right);
  else {
    show("right", r.right);
    show("left", r.left);
  }
  if (r.has_shared_d)
    out += fmt::format("     d = {} (updates +:{} -:{}){}{}\n", sig(r.d), r.d_updates[0].second, r.d_updates[1].second,
                       r.d_reason == Reason::none ? "" : fmt::format("  NOT identified ({})", to_string(r.d_reason)),
                       r.right.ci95.d.valid() ? "  95 %: " + sig(r.right.ci95.d) : "");
  out += fmt::format("NRMSE of the simulated output over [{}, {}] s: {}\n", sig(fit.t0_s), sig(fit.t1_s),
                     has_estimate(r) ? sig(100.0 * fit.nrmse) + " %" : "- (no side has an estimate to simulate)");
  return out;
}

SideAdvice side_advice(const AutoRun& ar, Side s, const DataTraits* traits) {
  SideAdvice a;
  const EstimateReport& r = ar.run.report;
  if (r.model != ModelKind::input_deadzone && r.model != ModelKind::output_deadzone &&
      r.model != ModelKind::deadzone_deadband)
    return a;
  const SideReport& sr = r[s];
  const GuessReport& g = ar.guess(s);
  const Reason why = g.wrong_side ? Reason::wrong_guess : sr.params.reason;
  const char* side = s == Side::right ? "right" : "left";
  if (why == Reason::uncertain && ar.cfg.ci_tolerance > 0.0 &&
      interval_verdict(sr.ci95, s) == Reason::none) {  // check 8 failed, not check 7
    const WidestInterval w = widest_interval(sr.ci95, r.has_c, r.has_side_d || r.has_shared_d);
    if (!w.name) return a;
    a.given = true;
    a.widest = w.name;
    a.widest_relative = w.relative;
    const double tol = ar.cfg.ci_tolerance, record_s = static_cast<double>(r.samples) * ar.cfg.dt_s;
    if (!std::isfinite(w.relative)) {
      a.text = fmt::format("{} side: no 95 % interval (fewer than 5 of the 10 sections identify it), so its precision "
                           "is unknown against --ci-tolerance {:.6g} %; record longer, driving the side beyond its "
                           "edge in every tenth of the record",
                           side, 100.0 * tol);
      return a;
    }
    // an interval's half-width falls as 1/sqrt(the record's length) for the same input and noise
    a.record_s_needed = record_s * (w.relative / tol) * (w.relative / tol);
    a.text = fmt::format("{} side: the 95 % interval of {} is +-{:.3g} % of its centre, wider than --ci-tolerance "
                         "{:.6g} %; intervals narrow as 1/sqrt(length): about {:.3g} s of the same input (this "
                         "record: {:.3g} s), or less noise",
                         side, w.name, 100.0 * w.relative, 100.0 * tol, a.record_s_needed, record_s);
    return a;
  }
  if (why != Reason::not_updated && why != Reason::not_excited && why != Reason::wrong_guess) return a;
  a.given = true;
  a.by_direction = model_traits(r.model).keys_by_direction;
  for (const auto& [k, n] : sr.updates) {
    if (k == "-") a.down = n;
    else a.up = n;
  }
  a.min_updates = ar.cfg.min_updates;
  a.dt_s = ar.cfg.dt_s;
  a.excite_duration_s = kAdviceExciteDuration;
  const bool guessed = model_traits(r.model).uses_guesses;
  if (guessed && g.source != GuessSource::unused && std::isfinite(g.guess)) a.beyond = g.guess;
  if (guessed && ar.switching.used) a.beyond = ar.cfg.switch_model[s].c;  // the switching model's edge
  if (r.model == ModelKind::output_deadzone) a.beyond = s == Side::right ? ar.cfg.zero_threshold : -ar.cfg.zero_threshold;
  if (g.wrong_side && std::isfinite(g.edge)) a.edge_seen = g.edge;
  // a rough bound per side: the largest of its guess, the edge the guess check saw and its c
  const auto bound = [&](const SideReport& x, const GuessReport& gx) {
    double b = std::numeric_limits<double>::quiet_NaN();
    const auto take = [&](double v) {
      if (std::isfinite(v) && v != 0.0) b = std::isnan(b) ? std::fabs(v) : std::max(b, std::fabs(v));
    };
    if (gx.source != GuessSource::unused) take(gx.guess);
    if (ar.switching.used) take(ar.cfg.switch_model[&x == &r.right ? Side::right : Side::left].c);
    take(gx.edge);
    take(x.params.c);
    return b;
  };
  if (guessed) {
    a.excite_left = -bound(r.left, ar.left);
    a.excite_right = bound(r.right, ar.right);
    if (traits && traits->v_lo < 0.0 && traits->v_hi > 0.0 &&
        (!(0.5 * traits->v_lo >= a.excite_left) || !(0.5 * traits->v_hi <= a.excite_right))) {
      a.excite_left = std::min(0.5 * traits->v_lo, std::isnan(a.excite_left) ? 0.0 : a.excite_left);
      a.excite_right = std::max(0.5 * traits->v_hi, std::isnan(a.excite_right) ? 0.0 : a.excite_right);
      a.from_input = true;
    }
    // a side with no update at all, or left open by model switching (whose samples inside the
    // deadzone count as updates): its edge may lie beyond the input's reach, so the bound is at
    // least the input's extreme on that side (the suggested sine then goes twice as far)
    const auto none = [&](const SideReport& x) {
      if (ar.switching.used) return !x.params.identified;
      std::uint64_t n = 0;
      for (const auto& [k, c] : x.updates) n += c;
      return n == 0;
    };
    if (traits && none(r.right) && traits->v_hi > 0.0 && !(a.excite_right >= traits->v_hi)) {
      a.excite_right = traits->v_hi;
      a.from_input = true;
    }
    if (traits && none(r.left) && traits->v_lo < 0.0 && !(a.excite_left <= traits->v_lo)) {
      a.excite_left = traits->v_lo;
      a.from_input = true;
    }
    a.drive_left = 2.0 * a.excite_left;
    a.drive_right = 2.0 * a.excite_right;
  }
  const std::string where = std::isfinite(a.beyond) ? fmt::format(" beyond {:+.6g}", a.beyond) : std::string();
  const auto count = [](std::uint64_t n) { return n == 0 ? std::string("none") : fmt::format("{}", n); };
  std::string t = fmt::format("{} side: ", side);
  if (why == Reason::wrong_guess) {
    t += fmt::format("the guess {:+.6g} lies inside the deadzone (edge seen at {:+.6g}); give --guess-{} beyond the edge, "
                     "or drive the input further beyond it",
                     a.beyond, a.edge_seen, side);
  } else if (a.by_direction) {
    t += fmt::format("{} update{} moving up{}, {} moving down ({} needed each way)", count(a.up), a.up == 1 ? "" : "s",
                     where, count(a.down), a.min_updates);
    if (why == Reason::not_excited)
      t += "; there the input or the output hardly varied (the regressors were collinear): vary how far beyond the "
           "edge the input goes";
    else if (a.up < a.min_updates && a.down < a.min_updates)
      t += "; drive the input beyond the edge and back, in both directions";
    else
      t += fmt::format("; reverse the input while it is beyond the edge, so the output also moves {} there",
                       a.up < a.min_updates ? "up" : "down");
  } else {
    t += fmt::format("{} update{}{} ({} needed)", count(a.up), a.up == 1 ? "" : "s", where, a.min_updates);
    t += why == Reason::not_excited
             ? "; there the input or the output hardly varied: vary how far beyond the edge the input goes"
             : (r.model == ModelKind::output_deadzone ? "; drive the output further to this side, for longer"
                                                      : "; drive the input further beyond the edge, for longer");
  }
  if (std::isfinite(a.drive_left) && std::isfinite(a.drive_right))
    t += fmt::format(", e.g. a sine between {:.6g} and {:.6g} (lash excite --edges={:.6g},{:.6g} --dt {:.6g} --duration {:.6g}){}",
                     a.drive_left, a.drive_right, a.excite_left, a.excite_right, a.dt_s, a.excite_duration_s,
                     a.from_input ? ""
                                  : "; the bounds are the switching guesses, and the edge of a side not identified may "
                                    "lie beyond its guess: if it still fails, widen them towards the input's extremes");
  a.text = std::move(t);
  return a;
}

std::string estimate_auto_json(const AutoRun& ar, Preset preset, const ReportFit& fit, const DataTraits* traits) {
  Json j = Json::parse(estimate_json(ar.run.report, fit));
  const auto put_guess = [&](const char* side, const GuessReport& g) {
    if (!j.contains(side) || g.source == GuessSource::unused) return;
    if (g.wrong_side) j[side]["reason"] = "wrong_guess";
    j[side]["guess"] = {{"value", num(g.guess)}, {"source", to_string(g.source)}, {"edge_seen", num(g.edge)}};
  };
  put_guess("right", ar.right);
  put_guess("left", ar.left);
  const auto put_advice = [&](const char* side, Side s) {
    if (!j.contains(side)) return;
    const SideAdvice a = side_advice(ar, s, traits);
    if (!a.given) {
      j[side]["advice"] = Json();
      return;
    }
    Json o;
    o["text"] = a.text;
    if (!a.widest.empty()) {  // check 8: precision, not updates
      o["widest_interval"] = {{"parameter", a.widest}, {"relative_half_width", num(a.widest_relative)},
                              {"record_s_needed", num(a.record_s_needed)}};
      j[side]["advice"] = o;
      return;
    }
    if (a.by_direction) {
      o["updates_up"] = a.up;
      o["updates_down"] = a.down;
    } else {
      o["updates"] = a.up;
    }
    o["min_updates"] = a.min_updates;
    o["beyond"] = num(a.beyond);
    o["edge_seen"] = num(a.edge_seen);
    o["drive"] = {num(a.drive_left), num(a.drive_right)};
    o["excite_edges"] = {num(a.excite_left), num(a.excite_right)};
    o["bounds_from"] = a.from_input ? "input" : "guesses";
    o["dt_s"] = a.dt_s;
    o["excite_duration_s"] = a.excite_duration_s;
    j[side]["advice"] = o;
  };
  put_advice("right", Side::right);
  put_advice("left", Side::left);
  j["outliers"] = ar.outliers;
  if (ar.switching.tried) {
    const auto& m = ar.cfg.switch_model;
    Json sw{{"used", ar.switching.used},
            {"converged", ar.switching.converged},
            {"passes", ar.switching.passes},
            {"starts", ar.switching.starts},
            {"trigger", to_string(ar.switching.trigger)}};
    if (ar.switching.used)
      for (const auto& [name, sd] : {std::pair{"right", &m.right}, std::pair{"left", &m.left}})
        sw["model"][name] = {{"a1", num(sd->a1)}, {"b1", num(sd->b1)}, {"c", num(sd->c)}, {"d", num(sd->d)}};
    j["model_switching"] = sw;
  }
  if (ar.output_error.tried) {
    const OutputErrorReport& oe = ar.output_error;
    Json o{{"used", oe.used}};
    if (oe.used)
      o.update({{"converged", oe.fit.converged},
                {"passes", oe.fit.passes},
                {"starts", oe.starts},
                {"best_start", oe.best_start},
                {"steps", oe.fit.steps},
                {"residuals", oe.fit.n},
                {"rms_start", num(oe.fit.rms_start)},
                {"rms", num(oe.fit.rms)},
                {"residual_rho1", num(oe.fit.rho1)},
                {"variance_factor", num(oe.fit.variance_factor)}});
    else
      o["why_not"] = oe.why_not;
    if (oe.check) {  // output_error_check: what the fit from the estimate moved
      Json c{{"rms_start", num(oe.fit.rms_start)}, {"rms", num(oe.fit.rms)}, {"passes", oe.fit.passes}};
      for (const Side s : {Side::right, Side::left})
        c[to_string(s)] = oe.moved[s].param < 0
                              ? Json(nullptr)
                              : Json{{"moved", side_param_name(oe.moved[s].param)}, {"by", num(oe.moved[s].by)}};
      o["check"] = c;
    }
    if (const auto& db = oe.deadband; db.tried) {  // input-deadzone: the same fit with d free
      Json c{{"ok", db.ok}, {"flagged", db.flagged}, {"passes", db.passes}};
      if (db.ok) {
        c["rms"] = num(db.rms);
        for (const Side s : {Side::right, Side::left})
          c[to_string(s)] = {{"d", num(db.d[s])}, {"d_half95", num(db.d_half95[s])}};
      }
      o["deadband_check"] = c;
    }
    if (oe.used) {  // a side rejected (checks 3-5, or its guess inside the deadzone) takes the other along
      Json c{{"flagged", oe.joint.flagged}};
      if (oe.joint.flagged)
        c.update({{"rejected", to_string(oe.joint.rejected)},
                  {"reason", to_string(oe.joint.reason)},
                  {"guess_inside", oe.joint.guess_inside}});
      o["joint_check"] = c;
    }
    j["output_error"] = o;
  }
  j["preset"] = to_string(preset);
  return j.dump();
}

std::string estimate_auto_text(const AutoRun& ar, double dt_s, const ReportFit& fit, const DataTraits* traits) {
  std::string out = estimate_text(ar.run.report, dt_s, fit);
  for (const auto& [name, g] : {std::pair{"right", &ar.right}, std::pair{"left", &ar.left}}) {
    if (g->wrong_side)
      out += fmt::format("wrong_guess: the {} guess {:.6g} lies inside the deadzone (edge seen at {:.6g})\n", name,
                         g->guess, g->edge);
    else if (g->source != GuessSource::unused)
      out += fmt::format("{} guess: {:.6g} ({})\n", name, g->guess, to_string(g->source));
  }
  for (const Side s : {Side::right, Side::left}) {
    const SideAdvice a = side_advice(ar, s, traits);
    if (a.given) out += "advice: " + a.text + "\n";
  }
  if (ar.outliers > 0) out += fmt::format("outliers: {} samples of y replaced by the outlier gate\n", ar.outliers);
  if (ar.switching.tried)
    out += fmt::format("model switching: {} after {} runs ({}){}{}\n", ar.switching.used ? "used" : "not used",
                       ar.switching.passes, ar.switching.converged ? "converged" : "did not converge",
                       ar.switching.used ? "" : "; the result is the dy/dt switching's",
                       ar.switching.trigger == SwitchTrigger::no_interval
                           ? "; tried because the dy/dt switching's estimate had no 95 % interval"
                       : ar.switching.trigger == SwitchTrigger::check ? "; run to check the dy/dt switching's estimate"
                                                                      : "");
  if (ar.output_error.tried) {
    const OutputErrorReport& oe = ar.output_error;
    out += oe.used ? fmt::format("output error: {} after {} passes ({} steps), free-run rms {:.6g} -> {:.6g}\n",
                                 oe.fit.converged ? "converged" : "did not converge", oe.fit.passes, oe.fit.steps,
                                 oe.fit.rms_start, oe.fit.rms)
                   : fmt::format("output error: not used ({})\n", oe.why_not);
    // The advice: with the refinement off (the thesis preset) it is to turn it on; with it on, it
    // did not run because the other side is not_excited, so the input is what to change.
    const char* advice = ar.cfg.output_error
                             ? "the refinement needs both sides excited: drive beyond both edges, in both directions"
                             : "use lash's preset, or --output-error, for the refined estimate";
    for (const Side s : {Side::right, Side::left})
      if (oe.check && oe.moved[s].param >= 0)
        out += fmt::format("output error check: the fit from this estimate moves the {} side's {} by {:.3g} %: "
                           "reported poor_fit ({})\n",
                           to_string(s), side_param_name(oe.moved[s].param), 100.0 * oe.moved[s].by, advice);
    if (const auto& db = oe.deadband; db.flagged)
      out += fmt::format("deadband check: a deadband of d_r = {:.6g}, d_l = {:.6g} lowers the free-run rms {:.6g} -> "
                         "{:.6g}: the record shows a backlash this model lacks, both sides reported poor_fit; use "
                         "--model deadzone-deadband\n",
                         db.d[Side::right], db.d[Side::left], oe.fit.rms, db.rms);
    if (const auto& jc = oe.joint; jc.flagged) {
      const char *r = to_string(jc.rejected), *o = to_string(opposite(jc.rejected));
      out += jc.guess_inside
                 ? fmt::format("joint check: the {} side is not identified ({}) and its guess lies inside the deadzone "
                               "(the fit started from its samples there); the {} side, fitted together with it, "
                               "reported poor_fit (give --guess-{} beyond the edge, or drive further beyond it)\n",
                               r, to_string(jc.reason), o, r)
                 : fmt::format("joint check: the fit's {} side is {}; the {} side, fitted together with it, reported "
                               "poor_fit ({})\n",
                               r, to_string(jc.reason), o, advice);
    }
  }
  return out;
}

}  // namespace lash
