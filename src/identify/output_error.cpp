#include "lash/identify/output_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "lash/blocks/delay.hpp"
#include "lash/identify/auto.hpp"
#include "lash/io/error.hpp"
#include "lash/identify/estimator_skeleton.hpp"
#include "lash/metrics/first_order.hpp"

namespace lash {

namespace {

constexpr std::size_t P = 8;
using Mat = std::array<std::array<double, P>, P>;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
/// A fit's residual with a lag-1 autocorrelation above this did not reach the record's noise
/// level (refine_by_output_error's further starts).
constexpr double kWhite = 0.5;

/// Solves A x = b for a symmetric positive definite A by Cholesky; false when A is not.
bool cholesky_solve(Mat a, OutputErrorParams b, OutputErrorParams& x) noexcept {
  for (std::size_t j = 0; j < P; ++j) {
    double s = a[j][j];
    for (std::size_t k = 0; k < j; ++k) s -= a[j][k] * a[j][k];
    if (!(s > 0.0) || !std::isfinite(s)) return false;
    a[j][j] = std::sqrt(s);
    for (std::size_t i = j + 1; i < P; ++i) {
      double t = a[i][j];
      for (std::size_t k = 0; k < j; ++k) t -= a[i][k] * a[j][k];
      a[i][j] = t / a[j][j];
    }
  }
  for (std::size_t i = 0; i < P; ++i) {  // L z = b
    for (std::size_t k = 0; k < i; ++k) b[i] -= a[i][k] * b[k];
    b[i] /= a[i][i];
  }
  for (std::size_t i = P; i-- > 0;) {  // Lᵀ x = z
    for (std::size_t k = i + 1; k < P; ++k) b[i] -= a[k][i] * b[k];
    b[i] /= a[i][i];
  }
  x = b;
  return true;
}

/// a1 in (−1, 1), b1 > 0, c_r ≥ 0 ≥ c_l, d ≥ 0, all finite: a model the free run may hold.
bool admissible(const OutputErrorParams& t) noexcept {
  for (double x : t)
    if (!std::isfinite(x)) return false;
  return std::fabs(t[0]) < 1.0 && std::fabs(t[4]) < 1.0 && t[1] > 0.0 && t[5] > 0.0 && t[2] >= 0.0 &&
         t[6] <= 0.0 && t[3] >= 0.0 && t[7] >= 0.0;
}

/// Walks an ascending list of rows alongside a pass over the record (rows asked in ascending
/// order): at(row) is the list's index of `row`, or npos when it is not listed.
class RowCursor {
 public:
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
  explicit RowCursor(std::span<const std::size_t> rows) noexcept : rows_(rows) {}
  std::size_t at(std::size_t row) noexcept {
    while (i_ < rows_.size() && rows_[i_] < row) ++i_;
    return i_ < rows_.size() && rows_[i_] == row ? i_ : npos;
  }

 private:
  std::span<const std::size_t> rows_;
  std::size_t i_ = 0;
};

/// What drives the free runs of a pass: v(k − 1 − dead_time), a missing input as 0 (it drives
/// nothing), and the gap rows, where the plant is where y says and its input history is unknown
/// (as at the record's start): the delay empties and the runs restart from y, a missing y as 0.
class Drive {
 public:
  Drive(std::size_t dead_time, std::span<const std::size_t> gap_rows) noexcept : delay_(dead_time), gaps_(gap_rows) {}
  /// Whether `row` (asked in ascending order) restarts the runs; empties the delay if so.
  bool restarts(std::size_t row) noexcept {
    const bool gap = gaps_.at(row) != RowCursor::npos && row > 0;
    if (gap) delay_.reset();
    return gap;
  }
  static double restart_value(double y) noexcept { return std::isfinite(y) ? y : 0.0; }
  double v1() const noexcept { return v1_; }
  /// After the row's step: its input enters the delay.
  void push(double v) noexcept { v1_ = delay_.step(std::isfinite(v) ? v : 0.0); }

 private:
  Delay delay_;
  RowCursor gaps_;
  double v1_ = 0.0;
};

/// One pass: rᵀr, JᵀJ and Jᵀr at θ (J by forward differences of step h).
struct Pass {
  double sse = 0.0;
  Mat jtj{};
  OutputErrorParams jtr{};
  std::size_t n = 0;
  double y_peak = 0.0;
  double sse_given = 0.0;  // against y as given
  double lag1 = 0.0;       // Σ r(k)·r(k−1) over consecutive summed rows
};

/// The model at θ and at its P forward-difference points θ + h_i e_i.
template <std::size_t... I>
std::array<FreeRunDzDb, P + 1> perturbed(const OutputErrorParams& th, const OutputErrorParams& h, bool by_sign,
                                         bool output_dz, std::index_sequence<I...>) {
  const auto at = [&](std::size_t i) {
    OutputErrorParams t = th;
    if (i > 0) t[i - 1] += h[i - 1];
    return FreeRunDzDb(t, by_sign, output_dz);
  };
  return {at(I)...};
}

Pass run_pass(const RecordColumns& rec, const OutputErrorParams& th, const OutputErrorParams& h,
              const OutputErrorOptions& o, std::size_t end) {
  auto m = perturbed(th, h, o.side_by_sign, o.output_deadzone, std::make_index_sequence<P + 1>{});
  Pass p;
  double r_prev = 0.0;
  bool have_prev = false;
  RowCursor edits(o.edit_rows);
  Drive drive(o.dead_time, o.restart_rows);
  std::size_t settled = o.begin;
  for_chunks(rec.store, rec.vy, 0, end, [&](std::size_t base, const auto& cols) {
    const auto& v = cols[0];
    const auto& y = cols[1];
    for (std::size_t k = 0; k < v.size(); ++k) {
      const std::size_t row = base + k;
      const std::size_t edit = edits.at(row);
      const double yk = edit != RowCursor::npos ? o.edit_values[edit] : y[k];
      const bool gap = drive.restarts(row);
      std::array<double, P + 1> ys{};
      if (gap) settled = std::max(settled, row + 1 + o.restart_settle);
      for (std::size_t i = 0; i <= P; ++i)
        if (o.fit_d || (i != 4 && i != 8))  // d held: its points are not run
          ys[i] = gap ? m[i].restart(Drive::restart_value(yk)) : m[i].step(drive.v1());
      drive.push(v[k]);
      if (row < settled || !std::isfinite(y[k]) || !std::isfinite(v[k])) {
        have_prev = false;
        continue;
      }
      const double r = yk - ys[0];
      p.sse += r * r;
      if (have_prev) p.lag1 += r * r_prev;
      r_prev = r;
      have_prev = true;
      p.sse_given += (y[k] - ys[0]) * (y[k] - ys[0]);
      p.y_peak = std::max(p.y_peak, std::fabs(y[k]));
      ++p.n;
      OutputErrorParams g;  // ∂y_sim/∂θ
      for (std::size_t i = 0; i < P; ++i) g[i] = (ys[i + 1] - ys[0]) / h[i];
      if (!o.fit_d) g[3] = g[7] = 0.0;  // d held: no column
      for (std::size_t i = 0; i < P; ++i) {
        p.jtr[i] += g[i] * r;
        for (std::size_t j = 0; j <= i; ++j) p.jtj[i][j] += g[i] * g[j];
      }
    }
  });
  for (std::size_t i = 0; i < P; ++i)
    for (std::size_t j = i + 1; j < P; ++j) p.jtj[i][j] = p.jtj[j][i];
  if (!o.fit_d) p.jtj[3][3] = p.jtj[7][7] = 1.0;  // a held parameter: its step solves to 0
  return p;
}

}  // namespace

FreeRunDzDb::FreeRunDzDb(const OutputErrorParams& th, bool by_sign, bool output_dz) noexcept
    : edge_{th[2], th[6]},
      sides_{{th[0], th[1], th[3]}, {th[4], th[5], th[7]}},
      a1_{th[0], th[4]},
      b1_{th[1], th[5]},
      by_sign_(by_sign),
      output_dz_(output_dz) {}

double FreeRunDzDb::step(double v1) noexcept {
  y_ = output_dz_ ? detail::output_dz_free_run(v1, edge_, a1_, b1_, last_, w_)
                  : detail::dzdb_free_run(v1, edge_, sides_, by_sign_, last_, w_, y_);
  return y_;
}

double FreeRunDzDb::restart(double y) noexcept {
  if (output_dz_) w_ = y > 0.0 ? y + edge_.right : y < 0.0 ? y + edge_.left : 0.0;
  else w_ = y;
  y_ = y;
  return y_;
}

OutputErrorFit fit_output_error(const RecordColumns& rec, const OutputErrorParams& start,
                                const OutputErrorOptions& options) {
  OutputErrorOptions o = options;
  if (o.output_deadzone) o.fit_d = false;  // the model has no deadband
  OutputErrorFit f;
  f.theta = start;
  f.half95.fill(kNaN);
  for (auto& c : f.ab_cov) c.fill(kNaN);
  const std::size_t end = o.end == 0 ? rec.size() : std::min(o.end, rec.size());
  if (!admissible(start) || end <= o.begin || end - o.begin <= 2 * P) return f;
  // forward-difference steps: relative to each parameter's scale (a1: its distance to ±1 matters)
  const double cscale = std::max({std::fabs(start[2]), std::fabs(start[6]), 1e-12});
  OutputErrorParams h{};
  for (std::size_t s = 0; s < 2; ++s) {
    const std::size_t b = 4 * s;
    h[b] = 1e-7 * std::max(1.0 - std::fabs(start[b]), 1e-6);
    h[b + 1] = 1e-7 * std::fabs(start[b + 1]);
    h[b + 2] = 1e-7 * cscale;
    h[b + 3] = 1e-7 * std::max(std::fabs(start[b + 3]), 1e-3 * cscale);
  }
  OutputErrorParams theta = start;
  Pass cur = run_pass(rec, theta, h, o, end);
  f.passes = 1;
  if (!std::isfinite(cur.sse) || cur.n <= P) return f;
  f.rms_start = std::sqrt(cur.sse / static_cast<double>(cur.n));
  double mu = 1e-3;
  while (f.passes < o.max_passes) {
    // (JᵀJ + μ diag JᵀJ) δ = Jᵀr (r = y − y_sim, so θ + δ lowers rᵀr to first order)
    OutputErrorParams delta{}, next{};
    bool found = false;
    for (int tries = 0; tries < 30 && !found; ++tries) {
      Mat a = cur.jtj;
      for (std::size_t i = 0; i < P; ++i) a[i][i] *= 1.0 + mu;
      if (!cholesky_solve(a, cur.jtr, delta)) {
        mu *= 10.0;
        continue;
      }
      for (std::size_t i = 0; i < P; ++i) next[i] = theta[i] + delta[i];
      if (admissible(next)) found = true;
      else mu *= 10.0;
    }
    if (!found) break;
    Pass cand = run_pass(rec, next, h, o, end);
    ++f.passes;
    if (std::isfinite(cand.sse) && cand.sse < cur.sse) {
      const double gain = (cur.sse - cand.sse) / cur.sse;
      theta = next;
      cur = cand;
      ++f.steps;
      mu = std::max(mu / 10.0, 1e-12);
      if (gain < 1e-10) {
        f.converged = true;
        break;
      }
    } else {
      mu *= 10.0;
      if (mu > 1e12) {  // no step lowers the cost: θ is a minimum to the precision of the differences
        f.converged = true;
        break;
      }
    }
  }
  f.ok = true;
  f.theta = theta;
  f.n = cur.n;
  f.rms = std::sqrt(cur.sse / static_cast<double>(cur.n));
  f.y_peak = cur.y_peak;
  f.rms_given = std::sqrt(cur.sse_given / static_cast<double>(cur.n));
  // covariance σ̂²(JᵀJ)⁻¹ at the result, σ̂² widened by the residual's long-run variance factor
  // (1 + ρ1)/(1 − ρ1) when its lag-1 autocorrelation ρ1 is positive: the residual of a model
  // that does not fit (unmodelled dynamics, coloured noise, a local minimum) is correlated, and
  // J's columns, sensitivities of a low-pass free run, are slow, so Jᵀr sums about n(1 − ρ1)/(1 + ρ1)
  // independent terms (an AR(1) residual's effective sample size)
  f.rho1 = cur.sse > 0.0 ? std::clamp(cur.lag1 / cur.sse, -1.0, 0.999) : 0.0;
  f.variance_factor = std::max(1.0, (1.0 + f.rho1) / (1.0 - f.rho1));
  const std::size_t free = o.fit_d ? P : P - 2;
  const double s2 = f.variance_factor * cur.sse / static_cast<double>(cur.n - free);
  Mat inv{};
  bool regular = true;
  for (std::size_t j = 0; j < P && regular; ++j) {
    OutputErrorParams e{}, col{};
    e[j] = 1.0;
    regular = cholesky_solve(cur.jtj, e, col);
    for (std::size_t i = 0; i < P; ++i) inv[i][j] = col[i];
  }
  if (regular) {
    for (std::size_t i = 0; i < P; ++i) f.half95[i] = 1.96 * std::sqrt(std::max(0.0, s2 * inv[i][i]));
    if (!o.fit_d) f.half95[3] = f.half95[7] = kNaN;
    for (std::size_t s = 0; s < 2; ++s) {
      const std::size_t b = 4 * s;
      f.ab_cov[s] = {s2 * inv[b][b], s2 * inv[b][b + 1], s2 * inv[b + 1][b + 1]};
    }
  }
  return f;
}

namespace {
/// Where a side's (a1, b1, c, d) sit in θ.
constexpr std::size_t offset(Side s) noexcept { return s == Side::right ? 0 : 4; }
void put(OutputErrorParams& th, Side s, const SideParams& p) noexcept {
  const std::size_t b = offset(s);
  th[b] = p.a1, th[b + 1] = p.b1, th[b + 2] = p.c, th[b + 3] = p.d;
}
/// `has_d` false (input-, output-deadzone): p.d is left as it is, d is not a parameter of the model.
void get(const OutputErrorParams& th, Side s, SideParams& p, bool has_d) noexcept {
  const std::size_t b = offset(s);
  p.a1 = th[b], p.b1 = th[b + 1], p.c = th[b + 2];
  if (has_d) p.d = th[b + 3];
}

/// The 95 % intervals of one side from the fit: ±half95 around a1, b1, c, d; K and τ by the delta
/// method from the (a1, b1) covariance (K = b1/(1 + a1), τ = −T/ln(−a1)).
SideIntervals fit_intervals(const OutputErrorFit& f, Side side, double dt_s) {
  const std::size_t b = offset(side);
  const auto iv = [](double c, double h) { return std::isfinite(h) ? Interval{c - h, c + h} : Interval{}; };
  SideIntervals ci;
  ci.a1 = iv(f.theta[b], f.half95[b]);
  ci.b1 = iv(f.theta[b + 1], f.half95[b + 1]);
  ci.c = iv(f.theta[b + 2], f.half95[b + 2]);
  ci.d = iv(f.theta[b + 3], f.half95[b + 3]);
  const double a1 = f.theta[b], b1 = f.theta[b + 1];
  const auto& [vaa, vab, vbb] = f.ab_cov[b / 4];
  const double ka = -b1 / ((1.0 + a1) * (1.0 + a1)), kb = 1.0 / (1.0 + a1);
  const double var_k = ka * ka * vaa + 2.0 * ka * kb * vab + kb * kb * vbb;
  if (std::isfinite(var_k)) ci.K = iv(static_gain(a1, b1), 1.96 * std::sqrt(std::max(0.0, var_k)));
  const double tau = time_constant_s(a1, dt_s);
  if (std::isfinite(tau)) {
    const double l = std::log(-a1);
    const double ta = dt_s / (a1 * l * l);  // dτ/da1
    const double var_t = ta * ta * vaa;
    if (std::isfinite(var_t)) ci.tau_s = iv(tau, 1.96 * std::sqrt(var_t));
  }
  return ci;
}

/// Side `s` of `rep` is not identified: reason poor_fit (the free-run fit's checks).
void mark_poor_fit(EstimateReport& rep, Side s) noexcept {
  rep[s].params.identified = false;
  rep[s].params.reason = Reason::poor_fit;
  rep.identified = false;
}

/// output_error_check (or a side not_excited): the estimate stays; an identified side the fit
/// of lowest cost (out.fit, from the estimate and the further starts) moves beyond the bounds in
/// any of its parameters is reported poor_fit.
void check_estimate(AutoRun& ar, bool has_d, bool unexcited) {
  OutputErrorReport& out = ar.output_error;
  out.check = true;
  const OutputErrorFit& f = out.fit;
  out.why_not = unexcited ? "a side is not excited (its input held one level or one value): the fit only checks the "
                            "other side's estimate"
                          : "check only (output-error-check): the switching estimate is kept";
  if (!f.ok) {
    out.why_not = "check: the fit failed (too few rows in the window, or a non-finite pass)";
    return;
  }
  if (!(f.rms_start * f.rms_start > (1.0 + kCheckCost) * f.rms * f.rms)) return;  // no material gain
  // a free run more than twice the fit's sum of squares is the estimate's bias whatever the
  // fit's intervals (wide where the fit itself misfits)
  const bool gross = f.rms_start * f.rms_start > (1.0 + kCheckGross) * f.rms * f.rms;
  EstimateReport& rep = ar.run.report;
  for (const Side s : {Side::right, Side::left}) {
    SideParams& p = rep[s].params;
    if (!p.identified) continue;
    const std::size_t b = offset(s);
    const std::array<double, 4> est{p.a1, p.b1, p.c, p.d};
    OutputErrorReport::CheckMove& m = out.moved[s];
    for (std::size_t i = 0; i < (has_d ? 4u : 3u); ++i) {
      const double diff = std::fabs(f.theta[b + i] - est[i]);
      const double hw = std::isfinite(f.half95[b + i]) ? f.half95[b + i] : 0.0;
      const double by = est[i] != 0.0 ? diff / std::fabs(est[i]) : kInf;
      if (diff > kCheckMove * std::fabs(est[i]) && (gross || diff > kCheckHalfWidths * hw) && by > m.by) {
        m.param = static_cast<int>(i);
        m.by = by;
      }
    }
    if (m.param >= 0) mark_poor_fit(rep, s);
  }
}
/// The deadband check (OutputErrorReport::DeadbandCheck) of a used input-deadzone refinement:
/// the fit again from its result with d free, started at kDeadbandStart of the peak |y| on
/// each side (d = 0 is the boundary of the constraint d >= 0).
void check_deadband(AutoRun& ar, const RecordColumns& rec, OutputErrorOptions o) {
  OutputErrorReport& out = ar.output_error;
  OutputErrorReport::DeadbandCheck& db = out.deadband;
  db.tried = true;
  OutputErrorParams start = out.fit.theta;
  start[3] = start[7] = kDeadbandStart * out.fit.y_peak;
  o.fit_d = true;
  const OutputErrorFit g = fit_output_error(rec, start, o);
  db.passes = g.passes;
  if (!g.ok) return;
  db.ok = true;
  db.rms = g.rms;
  bool clear = false;  // a side's d with its 95 % interval clear of 0
  for (const Side s : {Side::right, Side::left}) {
    const std::size_t i = offset(s) + 3;
    db.d[s] = g.theta[i];
    db.d_half95[s] = g.half95[i];
    clear = clear || (std::isfinite(g.half95[i]) && g.theta[i] > g.half95[i]);
  }
  if (!(clear && g.rms * g.rms < (1.0 - kDeadbandGain) * out.fit.rms * out.fit.rms)) return;
  db.flagged = true;
  EstimateReport& rep = ar.run.report;
  for (const Side s : {Side::right, Side::left})
    if (rep[s].params.identified) mark_poor_fit(rep, s);
}

/// The joint check (OutputErrorReport::JointCheck) on the refined sides' verdicts and guesses.
void check_joint(AutoRun& ar) noexcept {
  OutputErrorReport& out = ar.output_error;
  EstimateReport& rep = ar.run.report;
  for (const Side s : {Side::right, Side::left}) {
    // a guess inside the deadzone (GuessReport::wrong_side): the switching estimate the fit
    // starts from selected that side's samples from inside the deadzone
    const bool guess_inside = ar.guess(s).wrong_side && !rep[s].params.identified;
    const Reason why = rep[s].params.reason;
    const Side other = opposite(s);
    if (!(guess_inside || why == Reason::unstable || why == Reason::unphysical || why == Reason::wrong_guess) ||
        !rep[other].params.identified)
      continue;
    out.joint = {true, s, why, guess_inside};
    mark_poor_fit(rep, other);
  }
}
}  // namespace

const char* side_param_name(int i) noexcept {
  static constexpr const char* names[] = {"a1", "b1", "c", "d"};
  return i >= 0 && i < 4 ? names[i] : "";
}

void refuse_output_error_online(const EstimatorConfig& cfg, const char* where) {
  if (cfg.output_error)
    throw InputError("", 0, "output-error",
                     std::string("the output-error refinement iterates over a whole record, an estimator fed sample "
                                 "by sample cannot; use ") +
                         where);
}

void refine_by_output_error(AutoRun& ar, const RecordColumns& rec, std::size_t begin, std::size_t end,
                            bool intervals, double gate, std::span<const std::size_t> gap_rows) {
  OutputErrorReport& out = ar.output_error;
  out = {};
  const EstimatorConfig& cfg = ar.cfg;
  if (!(cfg.output_error || cfg.output_error_check) || (cfg.model != ModelKind::deadzone_deadband && cfg.model != ModelKind::input_deadzone &&
                            cfg.model != ModelKind::output_deadzone))
    return;
  const bool has_d = cfg.model == ModelKind::deadzone_deadband;  // the others: d = 0 held
  out.tried = true;
  EstimateReport& rep = ar.run.report;
  // the start: the sides' estimates; a side without one (a check on its values or its updates
  // failed) starts from the other side's dynamics and deadband with its edge mirrored (the free
  // run needs every parameter). A side not excited (its input held one level or one value) is
  // not refined: its parameters are not told apart by the record.
  const auto finite = [has_d](const SideParams& p) {
    return std::isfinite(p.a1) && std::isfinite(p.b1) && std::isfinite(p.c) && (!has_d || std::isfinite(p.d));
  };
  // Such a side leaves the refinement to a check of the other side (check_estimate): the fit
  // from the estimates, the unexcited side from its own values where it has them.
  bool unexcited = false;
  OutputErrorParams start{};
  for (const Side s : {Side::right, Side::left}) {
    const SideParams& p = rep[s].params;
    const SideParams& q = rep[opposite(s)].params;
    unexcited = unexcited || p.reason == Reason::not_excited;
    if (finite(p)) put(start, s, p);
    else if (finite(q)) {
      SideParams mirrored = q;
      mirrored.c = -q.c;
      put(start, s, mirrored);
    } else {
      out.why_not = "neither side has an estimate to start from";
      return;
    }
  }
  if (unexcited && !rep[Side::right].params.identified && !rep[Side::left].params.identified) {
    out.why_not = "a side is not excited (its input held one level or one value)";
    return;  // nothing to refine, nothing to check
  }
  OutputErrorOptions o;
  o.begin = begin;
  o.end = end;
  std::vector<std::size_t> edit_rows;
  std::vector<double> edit_values;
  if (ar.outliers > 0) gate_outliers(rec, gate, edit_rows, edit_values);  // the run's replacements again
  o.edit_rows = edit_rows;
  o.edit_values = edit_values;
  o.restart_rows = gap_rows;
  o.restart_settle = begin;  // after a gap, the allowance the record's start gets
  o.side_by_sign = true;  // the plant's structure (eq. 34, blocks/deadband.hpp): the side of the sign of v(k−1)
  o.fit_d = has_d;
  o.output_deadzone = cfg.model == ModelKind::output_deadzone;
  o.dead_time = cfg.noise.dead_time;
  if (!has_d) start[3] = start[7] = 0.0;
  // The starts (the free run's cost is not convex in θ: an edge the input passes only a little
  // and a deadband that hides most of a side's motion leave local minima). First the estimate.
  // From that fit's result: each side's a1, b1, d given to the other (its own edge kept: the two
  // sides of a real actuator share most of their dynamics), each side's d doubled and halved
  // (a deadband's width moves the cost in steps where the output turns); and the model
  // switching's model. The fit of lowest cost is kept. The further starts run only when the
  // first fit did not reach the record's level: its residual's lag-1 autocorrelation above
  // kWhite (a white measurement noise gives |ρ1| ~ 1/√n), or no convergence in max_passes.
  out.fit = fit_output_error(rec, start, o);
  out.starts = 1;
  std::vector<OutputErrorParams> starts;
  const OutputErrorParams first = out.fit.theta;
  const auto lend = [&](std::size_t from, std::size_t to) {
    OutputErrorParams t = first;
    t[to] = first[from], t[to + 1] = first[from + 1], t[to + 3] = first[from + 3];
    if (t != first) starts.push_back(t);
  };
  lend(0, 4);
  lend(4, 0);
  if (has_d)
    for (const std::size_t i : {3u, 7u})
      for (const double scale : {2.0, 0.5}) {
        OutputErrorParams t = first;
        t[i] *= scale;
        if (t != first) starts.push_back(t);
      }
  const auto& sw = cfg.switch_model;
  if (ar.switching.used && sw.right.usable() && sw.left.usable()) {
    OutputErrorParams t{sw.right.a1, sw.right.b1, sw.right.c, sw.right.d, sw.left.a1, sw.left.b1, sw.left.c, sw.left.d};
    if (!has_d) t[3] = t[7] = 0.0;
    if (t != start) starts.push_back(t);
  }
  if (out.fit.ok && (out.fit.rho1 > kWhite || !out.fit.converged))
    for (std::size_t i = 0; i < starts.size(); ++i) {
      if (!admissible(starts[i])) continue;
      OutputErrorFit g = fit_output_error(rec, starts[i], o);
      ++out.starts;
      if (g.ok && g.rms < out.fit.rms) {
        g.rms_start = out.fit.rms_start;  // the estimate's, as the report says
        g.passes += out.fit.passes;
        out.fit = g;
        out.best_start = out.starts - 1;
      } else {
        out.fit.passes += g.passes;
      }
    }
  if (!cfg.output_error || unexcited) {  // the fit of lowest cost only checks the estimate
    check_estimate(ar, has_d, unexcited);
    return;
  }
  const OutputErrorFit& f = out.fit;
  if (!f.ok) {
    out.why_not = admissible(start) ? "the fit failed (too few rows in the window, or a non-finite pass)"
                                    : "the estimate is not one the free run can hold (|a1| >= 1, b1 <= 0 or an edge "
                                      "on the wrong side of zero)";
    return;
  }
  out.used = true;
  const NrmseAccumulator score{f.rms_given * f.rms_given * static_cast<double>(f.n), f.y_peak, f.n};
  rep.fit_nrmse = score.value();
  ar.run.score = score;
  rep.identified = true;
  for (const Side s : {Side::right, Side::left}) {
    SideReport& r = rep[s];
    const std::size_t b = offset(s);
    get(f.theta, s, r.params, has_d);
    r.K = static_gain(r.params.a1, r.params.b1);
    r.tau_s = time_constant_s(r.params.a1, cfg.dt_s);
    {  // checks 3–6 again on the new values; check 2 on the fit's information (JᵀJ)
      verdict_rules::Evidence e;
      e.side = s;
      e.updated = true;
      e.excited = std::isfinite(f.half95[b]) && std::isfinite(f.half95[b + 1]) && std::isfinite(f.half95[b + 2]) &&
                  (!has_d || std::isfinite(f.half95[b + 3]));
      e.a1 = r.params.a1, e.b1 = r.params.b1, e.c = r.params.c, e.d = r.params.d;
      e.has_c = true;
      e.has_d = has_d;
      r.params.reason = verdict_rules::finish(verdict_rules::judge(e), true, rep.fit_nrmse, cfg.fit_threshold);
      r.params.identified = r.params.reason == Reason::none;
    }
    r.ci95 = {};
    if (!r.params.identified) rep.identified = false;
  }
  if (intervals)
    attach_intervals(rep, {fit_intervals(f, Side::right, cfg.dt_s), fit_intervals(f, Side::left, cfg.dt_s)},
                     cfg.ci_tolerance);
  if (cfg.model == ModelKind::input_deadzone) check_deadband(ar, rec, o);
  check_joint(ar);  // after check 7: a side may be rejected by its intervals
  if (!ar.run.ysim.empty()) {  // the stored free run: the refined model's
    FreeRunDzDb m(f.theta, o.side_by_sign, o.output_deadzone);  // the rule the fit used
    Drive drive(o.dead_time, gap_rows);
    for_chunks(rec.store, rec.vy, 0, std::min(rec.size(), ar.run.ysim.size()),
               [&](std::size_t base, const auto& cols) {
                 for (std::size_t k = 0; k < cols[0].size(); ++k) {
                   const std::size_t row = base + k;
                   ar.run.ysim[row] =
                       drive.restarts(row) ? m.restart(Drive::restart_value(cols[1][k])) : m.step(drive.v1());
                   drive.push(cols[0][k]);
                 }
               });
  }
}

}  // namespace lash
