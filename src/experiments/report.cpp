// Summary, JSON and CSV of a campaign's results.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "lash/io/atomic_file.hpp"
#include "lash/io/csv.hpp"
#include "lash/experiments/sweep.hpp"
#include "lash/metrics/error.hpp"

namespace lash::sweep {
namespace {

double key(double nrmse) { return std::isfinite(nrmse) ? nrmse : std::numeric_limits<double>::infinity(); }

/// Index of the lower median of `idx` ordered by NRMSE.
std::size_t median_of(std::vector<std::size_t> idx, const std::vector<RunResult>& r) {
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return key(r[a].nrmse) < key(r[b].nrmse); });
  return idx[(idx.size() - 1) / 2];
}

std::string label(const RunSpec& s) {
  if (s.waveform == Waveform::randomized) return fmt::format("randomized #{}", s.repeat);
  return fmt::format("{} A={} w={} rad/s #{}", to_string(s.waveform), format_double(s.amplitude),
                     format_double(s.frequency_rad_s), s.repeat);
}

std::string pct(double share) { return fmt::format("{:.1f} %", 100.0 * share); }

/// An NRMSE for the summary: never "inf %" or "nan %" without saying why.
std::string nrmse_text(double x) {
  return std::isfinite(x) ? pct(x) : std::string("not computed (no output in the window or a non-finite error)");
}

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

}  // namespace

Summary summarize(const Campaign& c, const std::vector<RunResult>& results) {
  Summary s;
  s.campaign = c.name;
  s.threshold = c.good_nrmse;
  s.param_tolerance = c.param_tolerance;
  s.runs = results.size();
  std::vector<std::size_t> all;
  std::vector<std::string> order;
  std::map<std::string, std::vector<std::size_t>> by_wf;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto& r = results[i];
    all.push_back(i);
    const std::string w = to_string(r.spec.waveform);
    if (!by_wf.count(w)) order.push_back(w);
    by_wf[w].push_back(i);
    if (r.good(c.good_nrmse)) ++s.good;
    if (key(r.nrmse) > key(results[s.worst_index].nrmse)) s.worst_index = i;
    for (Side sd : {Side::right, Side::left}) {
      ++s.sides_total;
      if (r.side[sd].identified) {
        ++s.sides_identified;
        const SideResult& x = r.side[sd];
        const auto& t = r.truth.side[sd];
        double e = 0.0;  // the largest error; NaN (e.g. no τ from a1 <= 0) wins
        const double tau_e = compares_tau(c.rig.kind) ? relative_error(x.tau_s, t.tau_s) : 0.0;
        for (const double x_e : {relative_error(x.gain, t.gain), tau_e, relative_error(x.c, t.c),
                                 r.d_identified ? relative_error(r.d, r.truth.d) : 0.0})
          e = (std::isnan(x_e) || x_e > e) ? x_e : e;
        if (std::isnan(e)) e = std::numeric_limits<double>::infinity();
        if (e <= c.param_tolerance) ++s.sides_within;
        if (e > 0.20) ++s.sides_above_20;
      }
    }
    if (r.side.right.identified && r.side.left.identified && r.side.left.c > r.side.right.c) ++s.unphysical_reported;
    const bool needs_d = c.rig.kind == rigs::RigKind::coupled_carts;
    if (r.side.right.identified && r.side.left.identified && (!needs_d || r.d_identified)) ++s.runs_identified;
    if (!std::isfinite(r.nrmse)) ++s.nrmse_failed;
    if (std::isfinite(r.param_error)) {
      ++s.params_checked;
      if (r.param_error <= c.param_tolerance) ++s.params_within;
    }
  }
  if (!results.empty()) {
    s.share_good = static_cast<double>(s.good) / static_cast<double>(s.runs);
    s.median_index = median_of(all, results);
    s.median_nrmse = results[s.median_index].nrmse;
    s.worst_nrmse = results[s.worst_index].nrmse;
  }
  for (const auto& w : order) {
    WaveformSummary ws;
    ws.waveform = w;
    const auto& idx = by_wf[w];
    ws.runs = idx.size();
    for (auto i : idx)
      if (results[i].good(c.good_nrmse)) ++ws.good;
    ws.share_good = static_cast<double>(ws.good) / static_cast<double>(ws.runs);
    ws.median_nrmse = results[median_of(idx, results)].nrmse;
    s.per_waveform.push_back(ws);
  }
  return s;
}

std::string summary_text(const Campaign& c, const Summary& s, const std::vector<RunResult>& results) {
  std::string out;
  out += fmt::format("{} — virtual rig '{}', {} runs of {} s at T = {} s\n", c.name, rigs::to_string(c.rig.kind), s.runs,
                     format_double(c.duration_s), format_double(c.dt_s));
  out += fmt::format("NRMSE over {}–{} s < {}: {}/{} runs = {}\n", format_double(c.window_start_s),
                     format_double(c.window_end_s), pct(s.threshold), s.good, s.runs, pct(s.share_good));
  for (const auto& w : s.per_waveform)
    out += fmt::format("  {:<11} {:>4}/{:<4} = {:>7}   median NRMSE {}\n", w.waveform, w.good, w.runs, pct(w.share_good),
                       nrmse_text(w.median_nrmse));
  if (!results.empty()) {
    out += fmt::format("median run: {} NRMSE {}\n", label(results[s.median_index].spec), nrmse_text(s.median_nrmse));
    out += fmt::format("worst run:  {} NRMSE {}\n", label(results[s.worst_index].spec), nrmse_text(s.worst_nrmse));
  }
  if (s.nrmse_failed > 0)
    out += fmt::format("runs whose NRMSE could not be computed: {} (counted as not good, ranked worst)\n", s.nrmse_failed);
  out += fmt::format("runs with the whole model identified{}: {}/{}\n",
                     c.rig.kind == rigs::RigKind::coupled_carts ? " (both sides and d)" : " (both sides)",
                     s.runs_identified, s.runs);
  out += fmt::format("sides identified: {}/{}; identified with c_l > c_r: {}\n", s.sides_identified, s.sides_total,
                     s.unphysical_reported);
  out += fmt::format("parameters within {} of the rig's true effective values: {}/{} runs with identified sides\n",
                     pct(s.param_tolerance), s.params_within, s.params_checked);
  out += fmt::format("identified sides within {} of the true K, {}c{}: {}/{} = {}; above 20 %: {}\n",
                     pct(s.param_tolerance), compares_tau(c.rig.kind) ? "tau, " : "",
                     c.rig.kind == rigs::RigKind::coupled_carts ? ", d" : "", s.sides_within,
                     s.sides_identified,
                     pct(s.sides_identified ? static_cast<double>(s.sides_within) / static_cast<double>(s.sides_identified) : 0.0),
                     s.sides_above_20);
  return out;
}

std::string summary_json(const Campaign& c, const Summary& s, const std::vector<RunResult>& results) {
  nlohmann::json j;
  j["campaign"] = c.name;
  j["file"] = c.file;
  j["rig"] = rigs::to_string(c.rig.kind);
  j["runs"] = s.runs;
  j["threshold"] = s.threshold;
  j["good"] = s.good;
  j["share_good"] = s.share_good;
  j["median_nrmse"] = num(s.median_nrmse);
  j["worst_nrmse"] = num(s.worst_nrmse);
  j["median_nrmse_pct"] = num(100.0 * s.median_nrmse);  // the same in percent, for a person
  j["worst_nrmse_pct"] = num(100.0 * s.worst_nrmse);
  if (!results.empty()) {
    j["median_run"] = label(results[s.median_index].spec);
    j["worst_run"] = label(results[s.worst_index].spec);
  }
  auto& pw = j["per_waveform"];
  pw = nlohmann::json::object();
  for (const auto& w : s.per_waveform)
    pw[w.waveform] = {{"runs", w.runs}, {"good", w.good}, {"share_good", w.share_good}, {"median_nrmse", num(w.median_nrmse)},
                        {"median_nrmse_pct", num(100.0 * w.median_nrmse)}};
  j["sides_identified"] = s.sides_identified;
  j["sides_total"] = s.sides_total;
  j["identified_with_cl_gt_cr"] = s.unphysical_reported;
  j["runs_identified"] = s.runs_identified;
  j["nrmse_failed"] = s.nrmse_failed;
  j["param_tolerance"] = s.param_tolerance;
  j["params_checked"] = s.params_checked;
  j["params_within_tolerance"] = s.params_within;
  j["sides_within_tolerance"] = s.sides_within;  // identified sides with K, tau, c (and d) within
  j["sides_above_20pct"] = s.sides_above_20;
  return j.dump(2) + "\n";
}

void write_results_csv(const std::string& path, const Campaign& c, const std::vector<RunResult>& results) {
  AtomicFile f(path);
  f.stream() << results_csv_text(c, results);
  f.commit();
}

std::string results_csv_text(const Campaign& c, const std::vector<RunResult>& results) {
  (void)c;
  std::string text;
  std::string line =
      "run,waveform,amplitude,frequency_rad_s,repeat,seed,nrmse,max_abs_y,"
      "a1_r,b1_r,c_r,K_r,tau_r_s,identified_r,updates_r,rejected_r,"
      "a1_l,b1_l,c_l,K_l,tau_l_s,identified_l,updates_l,rejected_l,"
      "d,identified_d,param_error,true_K_r,true_tau_r_s,true_c_r,true_K_l,true_tau_l_s,true_c_l,true_d\n";
  text += line;
  auto put = [&](double x) {
    line += ',';
    append_double(line, x);
  };
  for (const auto& r : results) {
    line.clear();
    line += std::to_string(r.spec.index);
    line += ',';
    line += to_string(r.spec.waveform);
    put(r.spec.amplitude);
    put(r.spec.frequency_rad_s);
    line += ',' + std::to_string(r.spec.repeat) + ',' + std::to_string(r.spec.seed);
    put(r.nrmse);
    put(r.max_abs_y);
    for (Side s : {Side::right, Side::left}) {
      const auto& sd = r.side[s];
      put(sd.identified ? sd.a1 : kNaN);
      put(sd.identified ? sd.b1 : kNaN);
      put(sd.identified ? sd.c : kNaN);
      put(sd.identified ? sd.gain : kNaN);
      put(sd.identified ? sd.tau_s : kNaN);
      line += sd.identified ? ",1," : ",0,";
      line += std::to_string(sd.updates);
      line += ',' + (sd.rejected.empty() ? std::string("-") : sd.rejected);
    }
    put(r.d_identified ? r.d : kNaN);
    line += r.d_identified ? ",1" : ",0";
    put(r.param_error);
    for (Side s : {Side::right, Side::left}) {
      put(r.truth.side[s].gain);
      put(r.truth.side[s].tau_s);
      put(r.truth.side[s].c);
    }
    put(r.truth.d);
    line += '\n';
    text += line;
  }
  return text;
}

}  // namespace lash::sweep
