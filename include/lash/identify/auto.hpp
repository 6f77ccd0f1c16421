#pragma once
/// @file auto.hpp
/// Identification that needs no tuning (docs/identification.md, "Defaults chosen from the data"):
///  - `preset_config(model, preset)`: lash's best settings per model, or the thesis's (§1.5.1);
///  - `analyse_record` + `tune_to_data`: the settings that depend on the record (noise level,
///    sample time, excitation) are chosen from it;
///  - `estimate_auto`: runs the estimator and, for a model that switches on the input
///    (input-deadzone, deadzone-deadband) without given guesses c_l*, c_r*, finds them by the
///    fixed-point iteration guess → estimate → guess; given guesses are honoured and checked
///    against the identified edge (wrong side = `wrong_guess`).
/// Not real-time safe (allocates, runs whole records). The sample path stays in the estimators.
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>
#include <span>
#include <string>
#include <string_view>

#include "lash/identify/any_estimator.hpp"
#include "lash/identify/config.hpp"
#include "lash/identify/intervals.hpp"
#include "lash/identify/output_error.hpp"

namespace lash {

enum class Preset : std::uint8_t {
  lash,   ///< lash's best settings for the model, tuned to the data where they depend on it
  thesis  ///< the thesis's settings (§1.5.1): RLS, λ = 0.99, P0 = 1000·I, η0 = [1 1 1], no filters
};
/// "lash" or "thesis"; throws std::invalid_argument otherwise.
Preset parse_preset(std::string_view name);
const char* to_string(Preset p) noexcept;

/// The static settings of `model` for `preset` (before any data is seen), sample period dt_s:
/// EstimatorConfig(model, dt_s) (lash's) or EstimatorConfig::thesis(model, dt_s).
EstimatorConfig preset_config(ModelKind model, Preset preset = Preset::lash, double dt_s = 0.005);

/// What a record says about the settings that depend on it.
struct DataTraits {
  double dt_s = 0.0;          ///< sample period [s]
  std::size_t samples = 0;
  double v_lo = 0.0, v_hi = 0.0;  ///< 0.1 % and 99.9 % quantiles of v [v unit]
  double y_span = 0.0;        ///< 99.9 % − 0.1 % quantile of y [y unit]
  /// Standard deviation of white measurement noise on y [y unit]: MAD of the second
  /// differences / (0.6745·√6) (var Δ²e = 6σ² for white e; the signal's own Δ² is small).
  double noise_sigma = 0.0;
  /// 90 % quantile of |ẏ| over 40-sample windows, |y(k) − y(k−40)|/(40·T) [y unit/s]: how fast the
  /// output moves when it moves (the scale of the switching dead band).
  double ydot_p90 = 0.0;
  /// 90 % quantile of |ÿ| (second difference / T²) over samples where y moved in the same
  /// direction three samples in a row [y unit/s²] (coupled carts: the acceleration gate's scale).
  double yddot_p90 = 0.0;
  /// Smallest step of y (encoder resolution) [y unit]; 0 when y is not visibly quantised: 99 % of
  /// the steps (quantum_step) are integer multiples of the smallest one.
  double quantum = 0.0;
};
/// |b − a| as a step of y for DataTraits::quantum, over consecutive pairs (a, b) of a record:
/// 0 when it is below 1e-9 of `scale`, the largest |y| so far (updated here): floating-point
/// rounding, not a change. An encoder velocity, counts·q/T differenced, repeats its value up to a
/// few ulps of the position (steps of 5e-17 to 3e-15 m/s on the cart hid its 1.96 mm/s quantum).
inline double quantum_step(double a, double b, double& scale) noexcept {
  scale = std::fmax(scale, std::fmax(std::fabs(a), std::fabs(b)));
  const double s = std::fabs(b - a);
  return s > 1e-9 * scale ? s : 0.0;
}
/// Not real-time safe. Non-finite samples are ignored. `y_edits`: samples of y read from
/// elsewhere (the outlier gate's replacements, any_estimator.hpp YEdits).
DataTraits analyse_record(std::span<const double> v, std::span<const double> y, double dt_s, YEdits y_edits = {});
/// The same over a record's columns, read in chunks (a spilled record streams).
DataTraits analyse_record(const RecordColumns& record, double dt_s, YEdits y_edits = {});

/// Sets the data-dependent settings of a `Preset::lash` config (docs/identification.md).
void tune_to_data(EstimatorConfig& cfg, const DataTraits& d);

/// Where a switching guess came from.
enum class GuessSource : std::uint8_t { unused, given, searched };
const char* to_string(GuessSource s) noexcept;

/// One side's guess and what the run made of it.
struct GuessReport {
  double guess = 0.0;          ///< c* used by the final run [v unit] (±inf: unused)
  GuessSource source = GuessSource::unused;
  /// The identified edge lies beyond the guess (c_r > c_r* or c_l < c_l*): the guess sits inside
  /// the deadzone, the side's regressions mixed samples of two regimes (`reason: wrong_guess`).
  bool wrong_side = false;
  double edge = 0.0;           ///< the edge the check used [v unit] (NaN: none)
  /// Sets wrong_side from edge and guess for side s.
  void judge(Side s) noexcept { wrong_side = std::isfinite(edge) && (s == Side::right ? edge >= guess : edge <= guess); }
};

/// Why estimate_auto ran model switching (docs/method.md §A4.4b).
enum class SwitchTrigger {
  none,         ///< it did not run
  asked,        ///< --model-switching
  side_open,    ///< the ẏ switching left a side unidentified
  no_interval,  ///< the ẏ switching identified both, but batch means' sections could not give a
                ///< side an interval: an estimate that rests on few samples
  check,        ///< the ẏ switching identified both with intervals; model switching checks it
                ///< (the ẏ selection is biased where its window straddles a reversal, §A4.4b)
};
/// The JSON / text name: "none", "asked", "side_open", "no_interval", "check".
const char* to_string(SwitchTrigger t) noexcept;

/// What model switching (docs/method.md §A4.4b) did in estimate_auto.
struct SwitchingReport {
  bool tried = false;      ///< the iteration ran (deadzone-deadband, pooled)
  bool used = false;       ///< the final run switched on the model (else on ẏ and the guesses)
  bool converged = false;  ///< the switching model stopped moving (within the tolerance)
  int passes = 0;          ///< runs over the record the iterations took (all starts)
  int starts = 0;          ///< starting models tried (lags of 10, 100, 30, 300 samples)
  SwitchTrigger trigger = SwitchTrigger::none;  ///< why it ran
};
struct AutoRun {
  EstimatorConfig cfg;         ///< the settings of the final run
  /// The settings that give this run again through estimate_auto (what --print-config writes): the
  /// final run's, with the searched guesses; when model switching was kept, the settings given
  /// (its switching model comes from the iteration, which the same settings repeat exactly).
  EstimatorConfig settings;
  SwitchingReport switching;
  EstimationRun run;
  GuessReport right, left;
  GuessReport& guess(Side s) noexcept { return s == Side::right ? right : left; }
  const GuessReport& guess(Side s) const noexcept { return s == Side::right ? right : left; }
  std::uint64_t outliers = 0;  ///< samples of y the outlier gate replaced (auto_gate.hpp)
  /// The batch-means intervals of the final run's estimate when estimate_auto computed them
  /// already (the check of a ẏ result, SwitchingReport::trigger): add_intervals need not run again.
  std::optional<PerSide<SideIntervals>> ci95;
  OutputErrorReport output_error;  ///< the output-error refinement (refine_by_output_error)
};

struct AutoOptions {
  bool keep_trace = false;    ///< every parameter per step (RunOptions::keep_trace)
  bool keep_outputs = true;   ///< ŷ and y_sim per step (RunOptions::keep_outputs)
  /// The final run's trace, streamed (RunOptions::on_step).
  std::function<void(const TraceRow&)> on_step;
  double gate = 12.0;         ///< the outlier gate's threshold [innovation scales] (0 = off)
  std::span<const std::size_t> gap_rows;  ///< where t jumps (Record::gap_rows())
  /// Rows [begin, end) whose NRMSE of the final run's y_sim against y (as given, not gated) is
  /// summed into run.score.
  std::size_t score_begin = 0, score_end = 0;
  /// analyse_record(v, y, cfg.dt_s) of this y, when the caller has it (resolve_settings took it to
  /// tune the settings): the guess search reuses it when the gate replaced no sample (the gated y
  /// is then this y, bit for bit) instead of taking the same quantiles again.
  const DataTraits* traits = nullptr;
};

/// Runs `cfg`'s estimator over v, y. Deadzone-deadband (pooled): when the switching on ẏ leaves a
/// side unidentified (and no guess was given), or cfg.model_switching asks for it, the model switching of docs/method.md
/// §A4.4b is iterated (the switching model from the previous run's estimate, from a start taken
/// from the identified sides or the record's ranges, until it moves less than 0.2 % of each
/// parameter; at most 40 runs, with shrinking steps after 10; up to four starts); its final run
/// is kept when it converged and identifies more sides (or was asked for). For input-deadzone and deadzone-deadband, a side whose
/// guess is infinite is searched: pass 0 uses c* = 0.7·(v quantile of that side); each pass sets
/// c* = ĉ + max(margin, 0.15·(v_extreme − ĉ)) from the side's identified edge ĉ, or moves c*
/// halfway out when ĉ lies beyond c* (inside-the-deadzone guess), until c* moves less than 1 %
/// of the input span (at most 5 passes). Not real-time safe.
/// y first passes the outlier gate (auto_gate.hpp) with threshold `options.gate`; the replaced
/// samples are kept apart (YEdits: O(replaced) memory, no copy of y). Every run restarts its
/// estimator's regressors at `options.gap_rows` (AnyEstimator::restart).
AutoRun estimate_auto(const EstimatorConfig& cfg, std::span<const double> v, std::span<const double> y,
                      const AutoOptions& options);
/// The same over a record's columns, read in chunks (a spilled record streams).
AutoRun estimate_auto(const EstimatorConfig& cfg, const RecordColumns& record, const AutoOptions& options);
/// The same with the options of before: keep_trace, gate, gap_rows (outputs kept, no score).
AutoRun estimate_auto(const EstimatorConfig& cfg, std::span<const double> v, std::span<const double> y,
                      bool keep_trace = false, double gate = 12.0, std::span<const std::size_t> gap_rows = {});

/// The outlier gate of estimate_auto over a whole record: the causal gate (auto_gate.hpp,
/// threshold `gate`, 0 = off), except that a flagged sample whose successor lies nearer it than
/// the gate's value is kept (the output really stepped there, a square-wave input). Appends the
/// replaced rows (ascending) and their values to `rows` and `values` (YEdits' parts).
void gate_outliers(std::span<const double> y, double gate, std::vector<std::size_t>& rows,
                   std::vector<double>& values);
/// The same over the y column of a record, read in chunks.
void gate_outliers(const RecordColumns& record, double gate, std::vector<std::size_t>& rows,
                   std::vector<double>& values);

/// The switching guesses estimate_auto would use on this record ({c_r*, c_l*}); for the sweep,
/// which runs its estimator online on a rig whose open-loop record it can take first.
/// `y_edits`: samples of y read from elsewhere (YEdits); `traits`: analyse_record of (v, y with
/// the edits), when the caller has it.
std::array<double, 2> search_guesses(const EstimatorConfig& cfg, std::span<const double> v,
                                     std::span<const double> y, std::span<const std::size_t> gap_rows = {},
                                     YEdits y_edits = {}, const DataTraits* traits = nullptr);
/// The same over a record's columns, read in chunks.
std::array<double, 2> search_guesses(const EstimatorConfig& cfg, const RecordColumns& record,
                                     std::span<const std::size_t> gap_rows = {}, YEdits y_edits = {},
                                     const DataTraits* traits = nullptr);

}  // namespace lash
