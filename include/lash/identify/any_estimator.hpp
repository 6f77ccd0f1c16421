#pragma once
/// @file any_estimator.hpp
/// One type for every estimator of docs/method.md §A4 (a std::variant, no virtual calls), plus a
/// summary report and a batch runner used by `lash estimate`, `lash demo` and sweeps.
#include <algorithm>
#include <array>
#include <functional>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "lash/identify/estimators.hpp"
#include "lash/identify/intervals.hpp"
#include "lash/identify/record_columns.hpp"
#include "lash/metrics/fit.hpp"  // nrmse, outside_3sigma_per_1000 (were declared here)

namespace lash {

/// Summary of one side (or of the whole model for `linear`, kept in `right`).
struct SideReport {
  SideParams params;  ///< NaN = not identified (JSON null); params.identified/reason: the full verdict
  double K = std::numeric_limits<double>::quiet_NaN();      ///< static gain b1/(1 + a1) [y unit / v unit]
  double tau_s = std::numeric_limits<double>::quiet_NaN();  ///< time constant −T/ln(−a1) [s]
  SideIntervals ci95;  ///< 95 % intervals (add_intervals, intervals.hpp); only when asked for
  std::vector<std::pair<std::string, std::uint64_t>> updates;  ///< per key: "+"/"-" or "all"
};

/// What the estimator knows now. Not real-time safe (allocates).
struct EstimateReport {
  ModelKind model = ModelKind::linear;
  std::uint64_t samples = 0;   ///< samples stepped (including skipped ones)
  std::uint64_t skipped = 0;   ///< non-finite samples / updates skipped
  bool identified = false;
  bool has_c = false;          ///< model has a deadzone c per side
  bool has_side_d = false;     ///< model has a deadband d per side
  bool has_shared_d = false;   ///< coupled-carts: one d for both directions
  SideReport right, left;      ///< linear: only `right` is meaningful
  double d = std::numeric_limits<double>::quiet_NaN();  ///< coupled-carts
  Reason d_reason = Reason::not_updated;                ///< coupled-carts: verdict of d
  double fit_nrmse = std::numeric_limits<double>::quiet_NaN();  ///< the verdict's free-run NRMSE (fraction)
  std::vector<std::pair<std::string, std::uint64_t>> d_updates;

  SideReport& operator[](Side s) noexcept { return s == Side::right ? right : left; }
  const SideReport& operator[](Side s) const noexcept { return s == Side::right ? right : left; }
};

/// Names of the per-step parameter columns of a model ("a1_r", "b1_r", "c_r", "d_r", …; the
/// linear model's "a1", "b1"), from its traits.
std::vector<std::string> param_names(const ModelTraits& traits);

class AnyEstimator {
 public:
  /// Validates the config (std::invalid_argument) and builds the estimator of cfg.model.
  explicit AnyEstimator(const EstimatorConfig& cfg);

  /// One sample; returns ŷ. noexcept, allocation-free.
  double step(double v, double y) noexcept {
    ++samples_;
    return std::visit([&](auto& e) noexcept { return e.step(v, y); }, e_);
  }
  double prediction() const noexcept {
    return std::visit([](const auto& e) noexcept { return e.prediction(); }, e_);
  }
  double simulated() const noexcept {
    return std::visit([](const auto& e) noexcept { return e.simulated(); }, e_);
  }
  bool identified() const noexcept {
    return std::visit([](const auto& e) noexcept { return e.identified(); }, e_);
  }
  /// Per-side parameters with the update-time verdict (linear: both sides return the single model).
  SideParams params(Side s) const noexcept {
    return std::visit([s](const auto& e) noexcept { return e.params(s); }, e_);
  }
  /// The full verdict of a side (verdict.hpp); Reason::none = identified.
  Reason verdict(Side s) const noexcept {
    return std::visit([s](const auto& e) noexcept { return e.verdict(s); }, e_);
  }
  std::uint64_t skipped() const noexcept {
    return std::visit([](const auto& e) noexcept { return e.skipped(); }, e_);
  }
  /// Updates of side s's recursion so far (linear: the model's). noexcept.
  std::uint64_t updates(Side s) const noexcept {
    return std::visit([s](const auto& e) noexcept { return e.updates(s); }, e_);
  }
  std::uint64_t samples() const noexcept { return samples_; }
  /// After a gap in the record: clears the signal history, keeps the estimates (estimators.hpp).
  /// noexcept, allocation-free.
  void restart() noexcept {
    std::visit([](auto& e) noexcept { e.restart(); }, e_);
  }
  /// Sets side s's switching guess and starts that side's recursion anew (estimator_skeleton.hpp).
  void set_guess(Side s, double guess) noexcept {
    std::visit([s, guess](auto& e) noexcept { e.set_guess(s, guess); }, e_);
    cfg_.guess(s) = guess;
  }
  /// The deadzone edge side s's regression points at, identified or not (NaN when none).
  double raw_edge(Side s) const noexcept {
    return std::visit([s](const auto& e) noexcept { return e.raw_edge(s); }, e_);
  }
  /// Back to the state right after construction. Not real-time safe.
  void reset() {
    std::visit([](auto& e) { e.reset(); }, e_);
    samples_ = 0;
  }

  /// Names of the per-step parameter columns ("a1_r", "b1_r", "c_r", "d_r", …).
  std::vector<std::string> param_names() const;
  /// Current values in the order of param_names() (NaN = not identified). noexcept, no allocation.
  void param_values(std::span<double> out) const noexcept;

  EstimateReport report() const;
  const EstimatorConfig& config() const noexcept { return cfg_; }
  template <class E>
  const E* get() const noexcept { return std::get_if<E>(&e_); }
  /// Calls f(estimator) with the concrete estimator, which f steps `n` times (step_through):
  /// one dispatch for a whole run of samples.
  template <class F>
  void visit_steps(std::uint64_t n, F&& f) {
    samples_ += n;
    std::visit(std::forward<F>(f), e_);
  }

 private:
  template <class List>
  struct VariantOf;
  template <class... M>
  struct VariantOf<ModelList<M...>> {
    using type = std::variant<SwitchingEstimator<M>...>;
  };
  using Variant = VariantOf<EstimatorModels>::type;  // one alternative per registered model
  static Variant make(const EstimatorConfig& cfg);

  EstimatorConfig cfg_;
  Variant e_;
  std::uint64_t samples_ = 0;
};

/// Samples of y replaced before an estimator sees them (the outlier gate's, auto_gate.hpp):
/// row rows[i] reads values[i] instead of y[rows[i]]; rows ascending. The record itself stays
/// as it is (memory: two numbers per replaced sample, not a copy of y).
struct YEdits {
  std::span<const std::size_t> rows;
  std::span<const double> values;
};

/// Steps the concrete estimator `e` through rows [begin, end) of a chunk whose v[0], y[0] are row
/// `base`, restarting it before every row of `gap_rows` after row `first` (where its run started:
/// the history is empty there), reading y from `edits` at an edited row, and calling
/// each(k, y_k as given, e) after the step of row k.
template <class E, class Each>
void step_rows(E& e, std::span<const double> v, std::span<const double> y, std::size_t base, std::size_t begin,
               std::size_t end, std::size_t first, std::span<const std::size_t> gap_rows, YEdits edits,
               Each& each) {
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  auto gap = std::lower_bound(gap_rows.begin(), gap_rows.end(), begin);
  auto edit = std::lower_bound(edits.rows.begin(), edits.rows.end(), begin);
  std::size_t next_gap = gap != gap_rows.end() ? *gap : kNone;
  std::size_t next_edit = edit != edits.rows.end() ? *edit : kNone;
  std::size_t next = std::min(next_gap, next_edit);  // one comparison per sample for both
  for (std::size_t k = begin, i = begin - base; k < end; ++k, ++i) {  // i: k's index in the chunk
    const double yg = y[i];
    double yk = yg;
    if (k == next) [[unlikely]] {
      if (k == next_gap) {
        if (k > first) e.restart();  // at `first` the history is already empty (new or reset estimator)
        ++gap;
        next_gap = gap != gap_rows.end() ? *gap : kNone;
      }
      if (k == next_edit) {
        yk = edits.values[static_cast<std::size_t>(edit - edits.rows.begin())];
        ++edit;
        next_edit = edit != edits.rows.end() ? *edit : kNone;
      }
      next = std::min(next_gap, next_edit);
    }
    e.step(v[i], yk);
    each(k, yg, std::as_const(e));
  }
}

/// Steps `est` through samples [begin, end) of the record `r`, calling restart() before every row
/// listed in `gap_rows` (ascending row indices where a gap ends, as Record::gap_rows() /
/// Table::gap_rows; a gap row outside the range is ignored), and `each(k, y_k, e)` after the step
/// of sample k, where y_k is y[k] as given (not edited) and `e` the concrete estimator
/// (LinearEstimator, ...): the variant is dispatched once per call, not per sample. `edits`:
/// samples of y read from elsewhere (YEdits). The record is read in chunks (for_chunks): the same
/// samples in the same order, the same bits as over arrays. The one run loop of every
/// whole-record estimation (run_estimator, search_guesses, the intervals' sections).
template <class Each>
void step_through(AnyEstimator& est, const RecordColumns& r, std::size_t begin, std::size_t end,
                  std::span<const std::size_t> gap_rows, Each&& each, YEdits edits = {}) {
  est.visit_steps(end - begin, [&](auto& e) {
    for_chunks(r.store, r.vy, begin, end, [&](std::size_t base, const auto& c) {
      step_rows(e, c[0], c[1], base, base, base + c[0].size(), begin, gap_rows, edits, each);
    });
  });
}

/// Result of running an estimator over a whole record.
struct EstimationRun {
  EstimateReport report;
  std::vector<double> yhat, ysim;                 ///< per sample (only with RunOptions::keep_outputs)
  std::vector<std::string> param_names;
  std::vector<std::vector<double>> params;        ///< params[p][k] (only if keep_trace)
  /// NRMSE of y_sim against y (as given, before any YEdits) over RunOptions' score rows, summed
  /// during the run in row order (the same bits as metrics nrmse() over the stored outputs).
  NrmseAccumulator score;
};

/// One step of a run as a trace sink sees it (RunOptions::on_step).
struct TraceRow {
  std::size_t k = 0;               ///< row
  double y = 0.0;                  ///< y[k] as given (before any YEdits)
  double yhat = 0.0, ysim = 0.0;   ///< one-step prediction and free-run simulation
  std::span<const double> params;  ///< every parameter in param_names() order (NaN: not identified)
};

struct RunOptions {
  bool keep_trace = false;    ///< store every parameter per step (EstimationRun::params)
  /// Called after every step (the trace streamed to a file as the run goes: nothing per sample is
  /// kept in memory). Not called when empty.
  std::function<void(const TraceRow&)> on_step;
  bool keep_outputs = true;   ///< store ŷ and y_sim per step (EstimationRun::yhat, ysim)
  /// `at_end`, when given, is called with the estimator after the last sample (to read more of
  /// its final state without a second pass over the record).
  std::function<void(const AnyEstimator&)> at_end;
  std::span<const std::size_t> gap_rows;  ///< where t jumps: the estimator restarts there (step_through)
  YEdits y_edits;             ///< samples of y the estimator reads from elsewhere (the outlier gate's)
  std::size_t score_begin = 0, score_end = 0;  ///< rows [begin, end) of EstimationRun::score
};

/// Steps `cfg`'s estimator through the record, as RunOptions say. Not real-time safe.
EstimationRun run_estimator(const EstimatorConfig& cfg, const RecordColumns& record, const RunOptions& options);
/// The same over v, y (same length).
EstimationRun run_estimator(const EstimatorConfig& cfg, std::span<const double> v, std::span<const double> y,
                            const RunOptions& options);
/// Steps `cfg`'s estimator through v, y (same length). keep_trace stores the parameters per step.
/// `at_end`, when given, is called with the estimator after the last sample (to read more of its
/// final state without a second pass over the record). `gap_rows`: where the record's timestamps
/// jump (step_through): the estimator restarts its regressors there.
EstimationRun run_estimator(const EstimatorConfig& cfg, std::span<const double> v, std::span<const double> y,
                            bool keep_trace = false,
                            const std::function<void(const AnyEstimator&)>& at_end = {},
                            std::span<const std::size_t> gap_rows = {});
/// Adds the 95 % intervals of every identified side's parameters to run.report (intervals.hpp):
/// under model switching with λ = 1 the delete-a-group jackknife (5.4 more passes over the
/// record), else batch means (one more run over sections of the same record).
void add_intervals(EstimationRun& run, const EstimatorConfig& cfg, const RecordColumns& record,
                   std::span<const std::size_t> gap_rows = {});
void add_intervals(EstimationRun& run, const EstimatorConfig& cfg, std::span<const double> v,
                   std::span<const double> y, std::span<const std::size_t> gap_rows = {});
/// Sets the 95 % intervals ci on the identified sides of rep and applies verdict checks 7
/// (interval_verdict) and 8 (precision_verdict with `ci_tolerance`; ci may be all invalid: no
/// intervals could be computed): a side whose interval reaches a physically impossible value, or
/// is missing or wider than the tolerance, becomes `uncertain` (not identified; its intervals
/// kept, to show why), and so does the model.
void attach_intervals(EstimateReport& rep, const PerSide<SideIntervals>& ci, double ci_tolerance = 0.0);

}  // namespace lash
