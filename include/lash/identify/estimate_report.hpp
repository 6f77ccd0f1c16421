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
#include <cstdint>
#include <limits>
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

/// What a side that was not identified because of the input lacked, and what to do (issue 30):
/// given for a side of a two-sided model (input-deadzone, output-deadzone, deadzone-deadband)
/// whose reason is not_updated, not_excited or wrong_guess. Every number of `text` is a member
/// here (and in the JSON: docs/identification.md, "Advice").
struct SideAdvice {
  bool given = false;
  std::string text;
  std::uint64_t up = 0;        ///< updates moving up (deadzone-deadband "+"), else all updates
  std::uint64_t down = 0;      ///< updates moving down (deadzone-deadband "-"; 0 otherwise)
  bool by_direction = false;   ///< up/down are per direction (deadzone-deadband)
  double beyond = std::numeric_limits<double>::quiet_NaN();  ///< the side's switching threshold (guess c*; output-deadzone ±z)
  double edge_seen = std::numeric_limits<double>::quiet_NaN();  ///< wrong_guess: the edge beyond the guess
  std::uint64_t min_updates = 0;  ///< updates needed per key
  /// The input's suggested extremes (2 × a rough bound per side, as `lash excite` drives),
  /// NaN when no bound is known; `excite_left/right` the bounds themselves: per side the
  /// largest of |guess|, the edge seen and |c| — or, when the record's traits are given, half
  /// its input's 0.1 % / 99.9 % quantile if that is larger (a sine as wide as the record's own
  /// input). `from_input`: the bounds came from the traits.
  double drive_left = std::numeric_limits<double>::quiet_NaN();
  double drive_right = std::numeric_limits<double>::quiet_NaN();
  double excite_left = std::numeric_limits<double>::quiet_NaN();
  double excite_right = std::numeric_limits<double>::quiet_NaN();
  bool from_input = false;
  double dt_s = 0.0;              ///< the record's sample period (for the `lash excite` line)
  double excite_duration_s = 0.0; ///< the duration suggested for `lash excite` [s]
  /// `uncertain` by check 8 (ci_tolerance): the widest judged interval (widest_interval), its
  /// half-width over its centre (+inf: not computed) and the record length [s] that would
  /// narrow it to the tolerance at the same input and noise (intervals narrow as 1/√length).
  std::string widest;
  double widest_relative = std::numeric_limits<double>::quiet_NaN();
  double record_s_needed = std::numeric_limits<double>::quiet_NaN();
};
/// The `lash excite --duration` the advice suggests [s]: the default sine identified the
/// deadzone-deadband model within 5 % in about half of it (docs/excite.md).
inline constexpr double kAdviceExciteDuration = 120.0;
/// The advice for side `s` of an estimate_auto run (given = false when none is due).
/// `traits`: analyse_record of the record, when the caller has it (else the bounds come from the
/// guesses alone, which for a side never identified may lie inside its deadzone).
SideAdvice side_advice(const AutoRun& run, Side s, const DataTraits* traits = nullptr);

/// What `lash estimate --json` and Python's `Result.to_dict()` print for an estimate_auto run:
/// estimate_json of its report, plus per side `guess` ({"value", "source": "given"|"searched",
/// "edge_seen"}; `reason` "wrong_guess" when the guess lay inside the deadzone), `advice`
/// (SideAdvice as an object, null when none is due), `outliers` (samples of y the outlier gate
/// replaced) and `preset`.
std::string estimate_auto_json(const AutoRun& run, Preset preset, const ReportFit& fit,
                               const DataTraits* traits = nullptr);
/// estimate_text plus a line per searched/given guess (or wrong_guess), a line of advice per side
/// that has one, and the outlier count.
std::string estimate_auto_text(const AutoRun& run, double dt_s, const ReportFit& fit,
                               const DataTraits* traits = nullptr);

}  // namespace lash
