#pragma once
/// @file estimate.hpp
/// One estimation over a whole record, as `lash estimate` and Python's `lash.estimate` do it:
/// the sample period from t, the settings for the record and the NRMSE score; the JSON object is
/// estimate_json() of estimate_report.hpp. One implementation, so the CLI's `--json` and
/// Python's `Result.to_dict()` cannot drift apart.
/// Not real-time safe (allocates). Errors are lash::InputError naming file, line and column.
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lash/identify/any_estimator.hpp"
#include "lash/identify/config_file.hpp"
#include "lash/identify/config_sources.hpp"
#include "lash/identify/estimate_report.hpp"
#include "lash/io/table.hpp"

namespace lash {

/// What `lash estimate` reports about one record.
struct EstimateResult {
  EstimateReport report;
  double dt_s = 0.0;        ///< sample period used by the estimator (mean step of t) [s]
  double nrmse = 0.0;       ///< NRMSE of the free-run simulation over the window (docs/method.md §A6); NaN if empty
  double nrmse_t0_s = 0.0;  ///< window start [s]
  double nrmse_t1_s = 0.0;  ///< window end [s] (the last t when the job leaves it open)
};

/// Checks a time column (at least 3 samples, strictly increasing) and returns its mean step [s].
/// Errors name `file`, the line of the row (from `line_of_row`, when given) and the column `t_name`.
double sample_period(std::span<const double> t, const std::string& file = "", const RowLines& line_of_row = {},
                     const std::string& t_name = "t");

/// The estimator settings for one record: `cfg` with the record's sample period `dt_s` [s] and
/// the verdict's fit window starting where the job's reported NRMSE window does.
EstimatorConfig config_for_record(EstimatorConfig cfg, const EstimationJob& job, double dt_s);

/// Scores a finished run: the NRMSE window of `job` over t, y and the simulated output.
/// t_increasing: t is known to increase strictly (sample_period checked it): the window's rows are
/// then found by bisection and only y and ysim are read (same samples, same sum, same bits).
EstimateResult score_estimate(const EstimateReport& report, double dt_s, const EstimationJob& job,
                              std::span<const double> t, std::span<const double> y, std::span<const double> ysim,
                              bool t_increasing = false);

/// The fit part of the report (estimate_json / estimate_text).
ReportFit report_fit(const EstimateResult& result) noexcept;

/// The JSON object printed by `lash estimate --json`: estimate_json(report, report_fit(result)).
std::string to_json(const EstimateResult& result);

struct ArrayEstimateOptions {
  bool trace = false;          ///< keep every parameter per sample (run.run.params), and ŷ, y_sim
  /// keep ŷ and y_sim per sample (run.run.yhat, ysim; 16 B per sample). The NRMSE is summed
  /// during the final run either way (EstimationRun::score).
  bool outputs = true;
  double outlier_gate = 12.0;  ///< estimate_auto's outlier gate [innovation scales] (0 = off)
  bool intervals = true;       ///< the 95 % intervals (add_intervals: one more estimator pass over sections)
  /// The sampling of t when the caller has it already (a file's reader analysed it): else analysed here.
  const Sampling* sampling = nullptr;
  /// Called after every step of the final run (the trace streamed: RunOptions::on_step).
  std::function<void(const TraceRow&)> on_step;
  std::size_t rows_skipped = 0;  ///< rows the reader dropped for a non-finite value (reported, not used)
  int first_skipped_line = 0;    ///< file line of the first of them
};

/// One whole-record estimation from arrays: `lash estimate` (on a file's columns) and Python's
/// lash.estimate make exactly this call.
struct ArrayEstimate {
  AutoRun run;            ///< settings of the final run, per-sample yhat/ysim, guesses, outliers
  EstimateResult result;  ///< report, dt, NRMSE and its window
  Sampling sampling;      ///< gaps and median step of t
  Preset preset = Preset::lash;
  EstimationJob job;      ///< the job part of the resolved settings (columns, NRMSE window)
  ReportFit fit;          ///< the fit part of the report (NRMSE, window, skipped rows, gaps, median step)
  /// Wall time of the estimator with its defaults [s] (`lash estimate --timing`): the settings
  /// chosen from the data (resolve_settings with the record: analyse_record), the outlier gate,
  /// the guess search and the final run (estimate_auto); not the intervals, nor the reading.
  double estimator_s = 0.0;
  double estimator_cpu_s = 0.0;  ///< CPU time of the calling thread in the same [s] (`--timing`)
  std::string json;       ///< what `lash estimate --json` prints (estimate_auto_json)
  /// What the record said (analyse_record), when the settings were tuned to it (preset lash): the
  /// report's advice sizes its example input from the record's input range (side_advice).
  std::optional<DataTraits> traits;
};

/// Python's lash.estimate, the library calls in one place: settings checked (before the data),
/// t checked (sample_period), its sampling analysed (analyse_sampling: dt = mean step without gaps,
/// the estimator restarts at each gap), the settings resolved for the record (resolve_settings),
/// estimate_auto, the intervals, the NRMSE of the free run (score_estimate) and the JSON report.
/// t [s], v, y: equal lengths (else InputError naming v or y). Not real-time safe.
ArrayEstimate estimate_arrays(const SettingsSources& src, std::span<const double> t, std::span<const double> v,
                              std::span<const double> y, const ArrayEstimateOptions& options = {});

/// The same over a record's columns t, v, y (RecordColumns with its t column), read in chunks: a
/// record spilled to a temporary file (load_record on a long file) is estimated in memory that
/// does not grow with it. t must be known to increase strictly (load_record checked it) and
/// `options.sampling` given (load_record analysed it); std::invalid_argument otherwise.
ArrayEstimate estimate_record(const SettingsSources& src, const RecordColumns& record,
                              const ArrayEstimateOptions& options);

}  // namespace lash
