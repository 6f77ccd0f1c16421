#include "lash/identify/estimate.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"

namespace lash {

namespace {
nlohmann::ordered_json num(double x) { return std::isfinite(x) ? nlohmann::ordered_json(x) : nlohmann::ordered_json(); }

nlohmann::ordered_json updates_json(const std::vector<std::pair<std::string, std::uint64_t>>& updates) {
  nlohmann::ordered_json u = nlohmann::ordered_json::object();
  for (const auto& [k, n] : updates) u[k] = n;
  return u;
}

/// One side's (linear: the model's) keys: a1, b1, c, d, identified, updates, the verdict's
/// reason (null when identified), K and tau_s.
void put_side(nlohmann::ordered_json& j, const EstimateReport& r, const SideReport& s) {
  j["a1"] = num(s.params.a1);
  j["b1"] = num(s.params.b1);
  if (r.has_c) j["c"] = num(s.params.c);
  if (r.has_side_d) j["d"] = num(s.params.d);
  j["identified"] = s.params.identified;
  j["updates"] = updates_json(s.updates);
  j["reason"] = s.params.identified ? nlohmann::ordered_json() : nlohmann::ordered_json(to_string(s.params.reason));
  j["K"] = num(s.K);
  j["tau_s"] = num(s.tau_s);
}
}  // namespace

double sample_period(std::span<const double> t, const std::string& file, const std::vector<int>& line_of_row,
                     const std::string& t_name) {
  if (t.empty()) throw InputError(file, 0, t_name, "no data rows");
  if (t.size() < 3) throw InputError(file, 0, t_name, "need at least 3 samples");
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (!(t[i] > t[i - 1])) {
      const int line = i < line_of_row.size() ? line_of_row[i] : 0;
      throw InputError(file, line, t_name,
                       "time must increase strictly (row " + std::to_string(i + 1) + ": " + format_double(t[i]) +
                           " after " + format_double(t[i - 1]) + ")");
    }
  }
  return (t.back() - t.front()) / static_cast<double>(t.size() - 1);
}

EstimatorConfig config_for_record(EstimatorConfig cfg, const EstimationJob& job, double dt_s) {
  cfg.dt_s = dt_s;
  cfg.fit_start_s = job.nrmse_t0_s;
  return cfg;
}

EstimateResult score_estimate(const EstimateReport& report, double dt_s, const EstimationJob& job,
                              std::span<const double> t, std::span<const double> y, std::span<const double> ysim) {
  EstimateResult r;
  r.report = report;
  r.dt_s = dt_s;
  r.nrmse_t0_s = job.nrmse_t0_s;
  r.nrmse_t1_s = job.nrmse_t1_s < 0 ? (t.empty() ? 0.0 : t.back()) : job.nrmse_t1_s;
  r.nrmse = nrmse(t, y, ysim, r.nrmse_t0_s, r.nrmse_t1_s);
  return r;
}

std::string to_json(const EstimateResult& res) {
  const EstimateReport& r = res.report;
  nlohmann::ordered_json j;
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
    j["d_updates"] = updates_json(r.d_updates);
    j["d_reason"] = r.d_reason == Reason::none ? nlohmann::ordered_json() : nlohmann::ordered_json(to_string(r.d_reason));
  }
  j["nrmse"] = num(res.nrmse);
  j["nrmse_pct"] = num(100.0 * res.nrmse);
  j["nrmse_window_s"] = {res.nrmse_t0_s, res.nrmse_t1_s};
  return j.dump();
}

}  // namespace lash
