#pragma once
/// @file output_error.hpp
/// Output-error refinement of a deadzone-deadband, input-deadzone or output-deadzone estimate over
/// a whole record (docs/method.md §A4.4c): the parameters θ = (a1, b1, c, d) of each side (input-
/// and output-deadzone: d = 0 held; output-deadzone with its own free run, G → DZ) are moved to minimise the sum of squares of y − y_sim(θ), the free run of the model driven by v alone (the verdict's
/// simulation, eq. 36 of the thesis; the refinement takes the side of the sign of v(k−1), eq. 34,
/// the rule of lash's plant blocks/deadband.hpp), by Levenberg–Marquardt
/// from the switching estimate. Why: the switching RLS regresses y(k) on the measured y(k−1);
/// with measurement noise that regressor is noisy (errors in variables), its instruments are
/// weak where the pole is near 1 (b1 = K(1 + a1): a1 off by 3·10⁻⁴ moves b1 by 3 % at
/// τ = 0.17 s, 5 ms), and in closed loop v(k−1) carries the noise of y(k−1). The free run
/// depends on v only, so with white measurement noise its minimiser is the maximum-likelihood
/// estimate, consistent in open and in closed loop when the plant is strictly proper (v(k−1)
/// depends on the noise up to k−1 only; Ljung, System Identification, 2nd ed. 1999, §13.4,
/// the direct approach), and its covariance is σ²(JᵀJ)⁻¹ (ibid. §9.3).
///
/// Memory does not grow with the record: every iteration is one pass over its rows (for_chunks:
/// a spilled record streams), running the model at θ and at each of the eight forward-difference
/// points side by side and summing JᵀJ, Jᵀr and rᵀr on the way (O(8²)). Not real-time safe
/// (whole-record passes); the per-sample estimators never use it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "lash/blocks/side.hpp"
#include "lash/identify/estimator_skeleton.hpp"
#include "lash/identify/record_columns.hpp"

namespace lash {

/// θ in this order: a1_r, b1_r, c_r, d_r, a1_l, b1_l, c_l, d_l.
using OutputErrorParams = std::array<double, 8>;

struct OutputErrorOptions {
  std::size_t begin = 0;       ///< first row whose residual is summed (the fit window's start)
  std::size_t end = 0;         ///< one past the last (0: the record's end)
  int max_passes = 100;        ///< passes over the record at most
  bool side_by_sign = false;   ///< the free run's side by the sign of v (EstimatorConfig::sim_side_by_sign)
  /// The model's dead time [samples]: y_sim(k) from v(k − 1 − dead_time) (NoiseSettings::dead_time).
  std::size_t dead_time = 0;
  /// The output-deadzone model's free run (G → DZ, detail::output_dz_free_run) instead of
  /// deadzone → G → deadband: c is the edge on the linear part's output [y unit], d is unused
  /// (fit_d must be false), side_by_sign is not read (the side is the output's against the edges).
  bool output_deadzone = false;
  /// false: d_r, d_l stay at their start values (input-deadzone: 0, the model has no deadband);
  /// only a1, b1, c of each side are fitted and their half-widths of d are NaN.
  bool fit_d = true;
  /// Rows (ascending) where the record restarts after a gap (the reader's gap rows): there the
  /// free run's state is set from the measured y of that row (the plant is not at rest after a
  /// gap) and the input's delay line empties, as at the record's start; the residuals of that row
  /// and the `restart_settle` rows after it are not summed (the record's start gets `begin`).
  std::span<const std::size_t> restart_rows;
  std::size_t restart_settle = 0;
  /// Rows (ascending) whose y the fit reads from `edit_values` instead (the outlier gate's
  /// replacements, gate_outliers): an outlier would pull a least-squares fit.
  std::span<const std::size_t> edit_rows;
  std::span<const double> edit_values;
};

struct OutputErrorFit {
  bool ok = false;             ///< a finite start, enough rows, and every pass finite
  bool converged = false;      ///< the cost stopped falling (relative 1e-10) before max_passes
  int passes = 0;              ///< passes over the record
  int steps = 0;               ///< accepted Levenberg–Marquardt steps
  std::size_t n = 0;           ///< residuals summed
  double rms_start = 0.0;      ///< RMS of y − y_sim at the start [y unit]
  double rms = 0.0;            ///< at the result [y unit]
  double rms_given = 0.0;      ///< at the result, against y as given (no edits) [y unit]
  double y_peak = 0.0;         ///< max |y| (as given) over the residuals' rows (the NRMSE's scale) [y unit]
  OutputErrorParams theta{};   ///< the result (the start when !ok)
  /// Lag-1 autocorrelation of the residual y − y_sim at the result, Σ r(k)r(k−1) / Σ r(k)²
  /// (at most 0.999): about 0 for white measurement noise.
  double rho1 = 0.0;
  /// σ̂²'s factor max(1, (1 + ρ1)/(1 − ρ1)): a correlated residual (a model that does not fit)
  /// holds fewer independent errors than rows (docs/method.md §A4.4c).
  double variance_factor = 1.0;
  /// 95 % half-widths of θ: 1.96·√diag(σ̂²(JᵀJ)⁻¹), σ̂² = variance_factor·rᵀr/(n − 8); NaN where
  /// JᵀJ is singular.
  OutputErrorParams half95{};
  /// The covariance σ̂²(JᵀJ)⁻¹ of (a1, b1) per side ({var a1, cov, var b1}; right, left): the
  /// intervals of K = b1/(1 + a1) and τ by the delta method.
  std::array<std::array<double, 3>, 2> ab_cov{};
};

/// The model's free run at θ from rest (w = y_sim = 0, the right side first), one sample at a
/// time: y_sim(k) from v up to k − 1, the estimators' free run (detail::dzdb_free_run; with
/// `output_dz`, detail::output_dz_free_run).
class FreeRunDzDb {
 public:
  FreeRunDzDb(const OutputErrorParams& th, bool by_sign, bool output_dz = false) noexcept;
  /// y_sim(k) given v(k − 1).
  double step(double v1) noexcept;
  /// After a gap: the state that outputs y now (deadband: w = y_sim = y; output-deadzone: the
  /// linear part's x beyond the edge on y's side, x = 0 for y = 0); returns y.
  double restart(double y) noexcept;

 private:
  PerSide<double> edge_{};
  PerSide<detail::DzDbSide> sides_{};
  PerSide<double> a1_{}, b1_{};  // output_dz: the sides' linear parts
  bool by_sign_ = false, output_dz_ = false;
  Side last_ = Side::right;
  double w_ = 0.0, y_ = 0.0;
};

/// Levenberg–Marquardt over the record's columns from `start` (a1 within (−1, 1), b1 > 0,
/// c_r ≥ 0 ≥ c_l, d ≥ 0 are kept: a step that leaves them is shortened by more damping).
OutputErrorFit fit_output_error(const RecordColumns& record, const OutputErrorParams& start,
                                const OutputErrorOptions& options = {});

/// What the refinement of a run did (AutoRun::output_error; the JSON's "output_error").
struct OutputErrorReport {
  bool tried = false;          ///< the setting was on and the model is one the fit has
  bool used = false;           ///< the refined parameters replaced the switching estimate's
  const char* why_not = "";    ///< when tried and not used: why (a fixed text)
  int starts = 0;              ///< fits run (refine_by_output_error's starts)
  int best_start = 0;          ///< the start whose fit was kept (0: the estimate)
  OutputErrorFit fit;          ///< the kept fit (passes: of all the starts)
  /// output_error_check (output_error off, or on with a side not_excited): the fit from the
  /// estimate only checked it; per side, what it moved (CheckMove).
  bool check = false;
  /// The parameter the fit moved furthest beyond the check's bounds (0–3: a1, b1, c, d; −1: none,
  /// or the side was not identified) and by how much, |fit/estimate − 1| [-].
  struct CheckMove {
    int param = -1;
    double by = 0.0;
  };
  PerSide<CheckMove> moved;
  /// The deadband check of an input-deadzone refinement (docs/method.md §A4.4c): the model nests
  /// in deadzone-deadband (d = 0), so the same fit is run once more from its result with d free.
  /// A deadband that lowers the free run's sum of squares by more than kDeadbandGain, with the
  /// 95 % interval of a side's d clear of 0, is a backlash the record shows and this model lacks:
  /// its a1, b1 and c absorb it (biased), and both sides are reported poor_fit.
  struct DeadbandCheck {
    bool tried = false;       ///< the refinement was used on an input-deadzone model
    bool ok = false;          ///< the fit with d free ran (finite)
    bool flagged = false;     ///< the sides were reported poor_fit for it
    int passes = 0;           ///< its passes over the record
    double rms = 0.0;         ///< free-run rms with d free [y unit] (against fit.rms)
    PerSide<double> d{};      ///< the deadband half-widths it found [y unit]
    PerSide<double> d_half95{};  ///< their 95 % half-widths [y unit] (NaN: not told apart)
  };
  DeadbandCheck deadband;
  /// The joint check of a used refinement: both sides are fitted together (one free run), so a
  /// side's values rest on the other side's. When the verdict rejects one side's fitted values
  /// (unstable, unphysical or wrong_guess: checks 3–5), the other side's, fitted with a model the
  /// verdict rejects, are reported poor_fit too. Likewise when a side is not identified and its
  /// switching guess lies inside the deadzone (GuessReport::wrong_side): the estimate the fit
  /// started from took that side's samples from inside the deadzone.
  struct JointCheck {
    bool flagged = false;          ///< the other side was reported poor_fit for it
    Side rejected = Side::right;   ///< the side that failed
    Reason reason = Reason::none;  ///< its reason
    bool guess_inside = false;     ///< flagged for its guess inside the deadzone
  };
  JointCheck joint;
};

/// The deadband check's bounds (OutputErrorReport::DeadbandCheck): the share of the input-deadzone
/// fit's sum of squares a deadband must remove to flag it [-] (the valve rig's unmodelled
/// dynamics leave at most 3 % to a deadband, issue 30's backlash plant 98 %; docs/identification.md) ...
inline constexpr double kDeadbandGain = 0.1;
/// ... and d's start, the share of the fit window's peak |y| [-].
inline constexpr double kDeadbandStart = 0.01;

/// The names of θ's parameters of one side, by index 0–3: "a1", "b1", "c", "d".
const char* side_param_name(int i) noexcept;

struct AutoRun;
struct EstimatorConfig;

/// Estimators fed sample by sample (lash monitor's, Python's Estimator) refuse output_error:
/// InputError naming `output-error` when it is on (`where`: what the user should use instead).
void refuse_output_error_online(const EstimatorConfig& cfg, const char* where);

/// With cfg.output_error on a deadzone-deadband, input-deadzone or output-deadzone run (the latter
/// two: d = 0 held; output-deadzone: OutputErrorOptions::output_deadzone):
/// fits rows [begin, end) of `record` from the run's estimate (a side without one starts from the
/// other side's, its edge mirrored; the free run delayed by cfg.noise.dead_time) and, when the
/// first fit's residual is not white or it did not converge, from further starts (the sides'
/// dynamics exchanged, each d doubled and halved, the model switching's model; the fit of lowest
/// cost is kept, docs/method.md §A4.4c). When the fit is ok, puts its parameters (and K, τ) in
/// the report, the free run's NRMSE over those rows in the report's fit and the run's score, the
/// refined free run in the stored y_sim, and judges both sides again: checks 3–6 on the new
/// values, check 2 on the fit's information (a side whose JᵀJ block is singular is
/// not_excited). With `intervals`, the fit's 95 % intervals replace the batch means' and checks
/// 7–8 run on them. Not used (why_not says why): a side not_excited by the switching run's
/// checks (its input held one level or one value; then the check below), no side with finite parameters, a start the
/// free run cannot hold, or a failed fit.
/// With cfg.output_error_check instead (cfg.output_error off), or with a side not_excited: the
/// same fits (the further starts too) only check the estimate; it, its free run and its
/// intervals are kept, and an identified side whose a1, b1, c
/// or d the fit moves by more than kCheckMove of its value and by more than kCheckHalfWidths of
/// the fit's 95 % half-widths is reported poor_fit (the report's moved), when the
/// estimate's free-run sum of squares exceeds the fit's by more than kCheckCost (by more than
/// kCheckGross: the half-widths' bound waived).
/// `gate`: the outlier gate's threshold of the run (AutoOptions::gate; 0 = off): the fit reads y
/// with the gate's replacements, the NRMSE is taken against y as given.
/// The output-error check's bounds (output_error_check): a move larger than both flags a side.
inline constexpr double kCheckMove = 0.01;       ///< of the parameter's value [-]
inline constexpr double kCheckHalfWidths = 3.0;  ///< of the fit's 95 % half-width [-]
/// ... and only when the estimate's free-run sum of squares exceeds the fit's by more than this
/// share of it (a move the output barely tells from the noise does not count) [-]
inline constexpr double kCheckCost = 0.01;
/// ... and the half-widths' bound is waived when it exceeds the fit's by more than this share
/// (the fit misfits too, its intervals are wide, but the estimate is the further off) [-]
inline constexpr double kCheckGross = 1.0;

/// `gap_rows`: where the record restarts after a gap (OutputErrorOptions::restart_rows; the rows
/// before `begin` are the settling allowance after each).
void refine_by_output_error(AutoRun& run, const RecordColumns& record, std::size_t begin, std::size_t end,
                            bool intervals, double gate, std::span<const std::size_t> gap_rows = {});

}  // namespace lash
