#pragma once
/// @file estimate_report.hpp
/// What `lash estimate` prints, built in the library so that the CLI, tests and the Python
/// module show the same thing. Not real-time code.
///
/// JSON (one line, full precision): every key of before (model, samples, per side a1, b1, c, d,
/// identified, updates; coupled carts d, d_updates; nrmse, nrmse_window_s) plus per side
/// `reason` (null when identified), `K`, `tau_s` and `ci95` ({"a1": [lo, hi], …} for every
/// parameter the model reports, null where no interval exists), coupled carts `d_reason` and
/// `d_ci95`, and `nrmse_pct`. A value that does not exist is null — never NaN or infinity.
/// Text: 6 significant digits, NRMSE in percent.
#include <string>

#include "lash/identify/any_estimator.hpp"
#include "lash/identify/auto.hpp"

namespace lash {

/// The report's fit: NRMSE (a fraction) of the free run over [t0_s, t1_s].
struct ReportFit {
  double nrmse = std::numeric_limits<double>::quiet_NaN();
  double t0_s = 0.0, t1_s = 0.0;
  // What the reader found in the record (io/table.hpp): reported as rows_skipped and gaps.
  std::size_t rows_skipped = 0;  ///< rows dropped for a non-finite value
  int first_skipped_line = 0;    ///< file line of the first of them
  std::size_t gaps = 0;          ///< steps of t longer than kGapFactor median steps
  double median_dt_s = 0.0;      ///< median step of t [s]
};

std::string estimate_json(const EstimateReport& r, const ReportFit& fit);
std::string estimate_text(const EstimateReport& r, double dt_s, const ReportFit& fit);

/// What `lash estimate --json` and Python's `Result.to_dict()` print for an estimate_auto run:
/// estimate_json of its report, plus per side `guess` ({"value", "source": "given"|"searched",
/// "edge_seen"}; `reason` "wrong_guess" when the guess lay inside the deadzone), `outliers` (samples
/// of y the outlier gate replaced) and `preset`.
std::string estimate_auto_json(const AutoRun& run, Preset preset, const ReportFit& fit);
/// estimate_text plus a line per searched/given guess (or wrong_guess) and the outlier count.
std::string estimate_auto_text(const AutoRun& run, double dt_s, const ReportFit& fit);

}  // namespace lash
