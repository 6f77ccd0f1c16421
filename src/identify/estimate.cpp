#include "lash/identify/estimate.hpp"

#include <cmath>

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"

namespace lash {

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

ReportFit report_fit(const EstimateResult& r) noexcept { return ReportFit{r.nrmse, r.nrmse_t0_s, r.nrmse_t1_s}; }

std::string to_json(const EstimateResult& r) { return estimate_json(r.report, report_fit(r)); }

}  // namespace lash
