#pragma once
/// @file sweep.hpp
/// Runs a campaign (docs/method.md §A7, E3–E5): every run drives its virtual rig with its
/// signal, feeds (v, y) sample by sample to the estimator and scores the
/// estimator's free-run simulated output against the rig's measured output by
/// NRMSE = RMS(y − y_sim)/max|y| over the campaign's window (docs/method.md §A6, thesis
/// 7.5–30 s). Runs are independent and run in parallel on a std::thread pool.
/// Not real-time safe (this is the offline harness around real-time pieces).
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "lash/blocks/side.hpp"
#include "lash/identify/estimators.hpp"
#include "lash/experiments/campaign.hpp"

namespace lash::sweep {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// What one run identified, per side, with the estimator's verdict.
struct SideResult {
  double a1 = kNaN, b1 = kNaN, c = kNaN;
  double gain = kNaN;    ///< K = b1/(1 + a1)
  double tau_s = kNaN;   ///< τ = −T/ln(−a1)
  bool identified = false;
  std::uint64_t updates = 0;
  /// The estimator's verdict when the side is not identified ("" when identified):
  /// not_updated, not_excited, unstable, unphysical, poor_fit or wrong_guess (verdict.hpp).
  std::string rejected;
};

/// Whether a rig's τ is a constant an identified τ can be scored against. The pilot valve's is
/// not: its pressure lag's time constant falls with pressure (docs/rigs.md, "What the first-order
/// model cannot see"), so its runs are scored on K and c alone, by param_error and the summary.
constexpr bool compares_tau(rigs::RigKind k) noexcept { return k != rigs::RigKind::pilot_valve; }

struct RunResult {
  RunSpec spec;
  double nrmse = kNaN;       ///< fraction (0.05 = 5 %)
  double max_abs_y = 0.0;    ///< max |y| over the window [output unit]
  PerSide<SideResult> side;
  double d = kNaN;           ///< coupled carts: deadband half-width [m]
  bool d_identified = false;
  rigs::EffectiveModel truth;///< the rig's true effective model for this run (docs/rigs.md)
  /// Largest relative error of the identified K, c (carts: also τ; coupled carts: also d) against
  /// `truth`; NaN when nothing was identified.
  double param_error = kNaN;
  bool good(double threshold) const noexcept { return nrmse < threshold; }
};

/// One sample of a traced run: what the estimator saw and gave, for looking into a run.
struct TraceRow {
  double t_s = 0.0;       ///< time of the sample [s]
  double v = 0.0;         ///< input [rig input unit]
  double y = 0.0;         ///< scored output (coupled carts: free-cart velocity) [output unit]
  double y_sim = 0.0;     ///< the model's free-run output scored against y
  PerSide<SideParams> side;  ///< the estimator's parameters after the sample (NaN while not identified)
};

/// Receives every sample of a traced run as it is produced.
using TraceFn = std::function<void(const TraceRow&)>;

/// Runs one run from scratch (deterministic: same campaign and spec → same bits). With
/// `trace`, every sample is passed to it as it is produced and nothing is kept (the NRMSE over
/// the window is computed from exactly these y and y_sim). Memory: O(1) in the run's length,
/// except a campaign without an [estimator] table, whose settings are tuned to the run's record
/// first (v and y of the run, 16 bytes a sample, freed before the run).
RunResult run_one(const Campaign& c, const RunSpec& run, const TraceFn& trace = {});

/// Called from the coordinating thread with (runs done, total) about five times a second
/// and once at the end.
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

/// Runs every run of the campaign on `jobs` threads (0 = all hardware threads). Results come
/// back in campaign order whatever the scheduling. The first exception of a worker is rethrown.
std::vector<RunResult> run_campaign(const Campaign& c, unsigned jobs, const ProgressFn& progress = {});

struct WaveformSummary {
  std::string waveform;
  std::size_t runs = 0, good = 0;
  double share_good = 0.0;   ///< good / runs
  double median_nrmse = kNaN;
};

struct Summary {
  std::string campaign;
  std::size_t runs = 0, good = 0;
  double threshold = 0.10;
  double share_good = 0.0;
  std::vector<WaveformSummary> per_waveform;  ///< in order of first appearance
  double median_nrmse = kNaN;
  std::size_t median_index = 0;   ///< run whose NRMSE is the (lower) median
  std::size_t worst_index = 0;    ///< run with the largest NRMSE (NaN counts as worst)
  double worst_nrmse = kNaN;
  std::size_t params_checked = 0; ///< runs with at least one identified side
  std::size_t params_within = 0;  ///< … whose param_error ≤ tolerance
  double param_tolerance = 0.05;
  std::size_t sides_identified = 0, sides_total = 0;
  /// Identified sides whose K, τ (where `compares_tau`) and c (coupled carts: and d, when
  /// identified) all lie within param_tolerance of the rig's true effective values; and those
  /// with an error above 20 %.
  std::size_t sides_within = 0, sides_above_20 = 0;
  std::size_t unphysical_reported = 0;  ///< identified sides with c_l > c_r (must be 0)
  /// Runs whose whole model was identified at the end (both sides; coupled carts: and d).
  std::size_t runs_identified = 0;
  /// Runs whose NRMSE could not be computed (no output in the window, or a non-finite error).
  std::size_t nrmse_failed = 0;
};

Summary summarize(const Campaign& c, const std::vector<RunResult>& results);

/// Human-readable summary (several lines, ends with a newline).
std::string summary_text(const Campaign& c, const Summary& s, const std::vector<RunResult>& results);
/// The same summary as one JSON object.
std::string summary_json(const Campaign& c, const Summary& s, const std::vector<RunResult>& results);

/// Writes one CSV row per run (atomically): waveform, amplitude, frequency_rad_s, repeat, seed,
/// nrmse, per side a1/b1/c/K/tau/identified/updates, d, d_identified, param_error and the
/// rig's true K/tau/c per side. Not-identified values are written as "nan".
void write_results_csv(const std::string& path, const Campaign& c, const std::vector<RunResult>& results);
/// The text write_results_csv() writes (header line and one line per run).
std::string results_csv_text(const Campaign& c, const std::vector<RunResult>& results);

}  // namespace lash::sweep
