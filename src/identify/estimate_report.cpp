#include "lash/identify/estimate_report.hpp"

#include <cmath>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

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
  j["nrmse"] = num(fit.nrmse);
  j["nrmse_pct"] = num(100.0 * fit.nrmse);
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
  out += fmt::format("NRMSE of the simulated output over [{}, {}] s: {} %\n", sig(fit.t0_s), sig(fit.t1_s),
                     sig(100.0 * fit.nrmse));
  return out;
}

std::string estimate_auto_json(const AutoRun& ar, Preset preset, const ReportFit& fit) {
  Json j = Json::parse(estimate_json(ar.run.report, fit));
  const auto put_guess = [&](const char* side, const GuessReport& g) {
    if (!j.contains(side) || g.source == GuessSource::unused) return;
    if (g.wrong_side) j[side]["reason"] = "wrong_guess";
    j[side]["guess"] = {{"value", num(g.guess)}, {"source", to_string(g.source)}, {"edge_seen", num(g.edge)}};
  };
  put_guess("right", ar.right);
  put_guess("left", ar.left);
  j["outliers"] = ar.outliers;
  j["preset"] = to_string(preset);
  return j.dump();
}

std::string estimate_auto_text(const AutoRun& ar, double dt_s, const ReportFit& fit) {
  std::string out = estimate_text(ar.run.report, dt_s, fit);
  for (const auto& [name, g] : {std::pair{"right", &ar.right}, std::pair{"left", &ar.left}}) {
    if (g->wrong_side)
      out += fmt::format("wrong_guess: the {} guess {:.6g} lies inside the deadzone (edge seen at {:.6g})\n", name,
                         g->guess, g->edge);
    else if (g->source != GuessSource::unused)
      out += fmt::format("{} guess: {:.6g} ({})\n", name, g->guess, to_string(g->source));
  }
  if (ar.outliers > 0) out += fmt::format("outliers: {} samples of y replaced by the outlier gate\n", ar.outliers);
  return out;
}

}  // namespace lash
