#include "lash/identify/estimate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <tuple>
#include <utility>

#include "lash/io/csv.hpp"
#include "lash/io/error.hpp"

namespace lash {

namespace {
/// CPU time of the calling thread [s] (on a shared machine the wall time also counts the time
/// other processes held the core).
double thread_cpu_s() noexcept {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

double sample_period(std::span<const double> t, const std::string& file, const RowLines& line_of_row,
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

namespace {
/// The result without its NRMSE: the window [t0, t1] of `job` (t1 < 0: to the last t).
EstimateResult unscored(const EstimateReport& report, double dt_s, const EstimationJob& job, double t_last) {
  EstimateResult r;
  r.report = report;
  r.dt_s = dt_s;
  r.nrmse_t0_s = job.nrmse_t0_s;
  r.nrmse_t1_s = job.nrmse_t1_s < 0 ? t_last : job.nrmse_t1_s;
  return r;
}
EstimateResult unscored(const EstimateReport& report, double dt_s, const EstimationJob& job,
                        std::span<const double> t) {
  return unscored(report, dt_s, job, t.empty() ? 0.0 : t.back());
}
/// Rows [k0, k1) of an increasing t with t0 <= t <= t1, by bisection.
std::pair<std::size_t, std::size_t> window_rows(std::span<const double> t, double t0, double t1) {
  const auto k0 = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), t0) - t.begin());
  const auto k1 = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), t1) - t.begin());
  return {k0, std::max(k0, k1)};
}
/// The same rows of column `c` of a store (one read per bisection step).
std::pair<std::size_t, std::size_t> window_rows(const ColumnStore& s, std::size_t c, double t0, double t1) {
  if (s.in_memory()) return window_rows(s.column(c), t0, t1);
  const auto first_not = [&](auto&& below) {  // the first row whose t is not `below`
    std::size_t lo = 0, hi = s.rows();
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (below(s.at(c, mid))) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  };
  const std::size_t k0 = first_not([&](double t) { return t < t0; });
  const std::size_t k1 = first_not([&](double t) { return !(t1 < t); });
  return {k0, std::max(k0, k1)};
}
}  // namespace

EstimateResult score_estimate(const EstimateReport& report, double dt_s, const EstimationJob& job,
                              std::span<const double> t, std::span<const double> y, std::span<const double> ysim,
                              bool t_increasing) {
  EstimateResult r = unscored(report, dt_s, job, t);
  if (t_increasing) {
    const std::size_t n = std::min({t.size(), y.size(), ysim.size()});
    const auto [k0, k1] = window_rows(t.first(n), r.nrmse_t0_s, r.nrmse_t1_s);
    r.nrmse = nrmse(y.subspan(k0, k1 - k0), ysim.subspan(k0, k1 - k0));
  } else {
    r.nrmse = nrmse(t, y, ysim, r.nrmse_t0_s, r.nrmse_t1_s);
  }
  return r;
}

ReportFit report_fit(const EstimateResult& r) noexcept { return ReportFit{r.nrmse, r.nrmse_t0_s, r.nrmse_t1_s}; }

std::string to_json(const EstimateResult& r) { return estimate_json(r.report, report_fit(r)); }

ArrayEstimate estimate_arrays(const SettingsSources& src, std::span<const double> t, std::span<const double> v,
                              std::span<const double> y, const ArrayEstimateOptions& o) {
  resolve_settings(src);  // settings are checked before the data is looked at
  for (const auto& [name, col] : {std::pair{"v", v}, std::pair{"y", y}})
    if (col.size() != t.size())
      throw InputError("", 0, name,
                       "has " + std::to_string(col.size()) + " samples, t has " + std::to_string(t.size()));
  sample_period(t);  // t: at least 3 samples, strictly increasing
  const Sampling smp = o.sampling ? *o.sampling : analyse_sampling(t);
  ArrayEstimateOptions o2 = o;
  o2.sampling = &smp;
  return estimate_record(src, RecordColumns::of(t, v, y), o2);
}

ArrayEstimate estimate_record(const SettingsSources& src, const RecordColumns& rec, const ArrayEstimateOptions& o) {
  resolve_settings(src);  // settings are checked before the data is looked at
  if (rec.t == RecordColumns::kNone) throw std::invalid_argument("estimate_record: the record has no t column");
  if (!o.sampling) throw std::invalid_argument("estimate_record: the record's sampling is not given");
  if (rec.size() < 3) throw InputError("", 0, "t", "need at least 3 samples");
  ArrayEstimate out;
  out.sampling = *o.sampling;
  const Sampling& smp = out.sampling;
  const auto t_start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_s();
  const EstimateSettings set = resolve_settings(src, smp.dt, &rec);
  out.preset = set.preset;
  out.job = set.job;
  AutoOptions ao;
  ao.keep_trace = o.trace;
  ao.keep_outputs = o.outputs || o.trace;
  ao.on_step = o.on_step;
  ao.gate = o.outlier_gate;
  ao.gap_rows = smp.gap_rows;
  ao.traits = set.traits ? &*set.traits : nullptr;  // the guess search needs the same quantiles
  // the NRMSE window's rows: its sum is taken during the final run (no stored y_sim needed)
  EstimateResult scored = unscored({}, smp.dt, set.job, rec.store.back(rec.t));
  std::tie(ao.score_begin, ao.score_end) = window_rows(rec.store, rec.t, scored.nrmse_t0_s, scored.nrmse_t1_s);
  out.run = estimate_auto(set.cfg, rec, ao);
  out.estimator_cpu_s = thread_cpu_s() - cpu_start;
  out.estimator_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  if (o.intervals && out.run.ci95)  // computed while checking the ẏ result: the same estimate, settings, record
    attach_intervals(out.run.run.report, *out.run.ci95, out.run.cfg.ci_tolerance);
  else if (o.intervals)
    add_intervals(out.run.run, out.run.cfg, rec, smp.gap_rows);
  refine_by_output_error(out.run, rec, ao.score_begin, ao.score_end, o.intervals, ao.gate, smp.gap_rows);
  scored.report = out.run.run.report;
  scored.nrmse = out.run.run.score.value();
  out.result = std::move(scored);
  out.fit = report_fit(out.result);  // with what the reader found: skipped rows, gaps, median step of t
  out.fit.rows_skipped = o.rows_skipped;
  out.fit.first_skipped_line = o.first_skipped_line;
  out.fit.gaps = smp.gap_rows.size();
  out.fit.median_dt_s = smp.median_dt;
  out.traits = set.traits;
  out.json = estimate_auto_json(out.run, set.preset, out.fit, out.traits ? &*out.traits : nullptr);
  return out;
}

}  // namespace lash
