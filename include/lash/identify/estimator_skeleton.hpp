#pragma once
/// @file estimator_skeleton.hpp
/// The one skeleton of every switching estimator of docs/method.md §A4: SwitchingEstimator<Model>
/// owns what all models share — the non-finite-sample check, the preprocessing (§A5), the
/// warm-up after restart(), the signal history, the value ranges of the regressors, the fit
/// window of the verdict, the accessors and the step evidence → SideParams (verdict.hpp) — and
/// a small policy `Model` supplies what differs: which side/key a sample updates and its
/// regressor, the parameters derived from the raw estimate, and the free-run model. Each
/// policy also carries constexpr ModelTraits (name, which parameters it has, defaults), from
/// which AnyEstimator, the reports and the settings derive everything model-specific.
///
/// A policy (estimators.hpp has five) is a class with
///   static constexpr ModelTraits traits;
///   explicit Model(const EstimatorConfig&);
///   double update(EstimatorCore&, const Conditioned&, bool warming) noexcept;  // ŷ(k)
///   void free_run(EstimatorCore&) noexcept;      // y_sim(k) into core.ysim (reads core.vraw1 = v(k−1−dead_time))
///   verdict_rules::Evidence evidence(const EstimatorCore&, Side) const noexcept;
///   bool conditioned(const EstimatorCore&, Side) const noexcept;
///   std::uint64_t side_updates(Side) const noexcept, rls_skipped() const noexcept;
///   void restart() noexcept;                      // its own signal history (may be empty)
///   void restart_side(EstimatorCore&, Side) noexcept;  // set_guess(): that side's recursion anew
/// and optionally bool settled(Side) const (false: a side with a clean verdict still counts as
/// not_updated), double deadband() const (traits.has_shared_d), std::uint64_t
/// key_updates(Side, bool plus) const (traits.keys_by_direction). Its public members are the
/// model-specific accessors of the estimator (SwitchingEstimator<Model> derives from it).
#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>

#include "lash/blocks/side.hpp"
#include "lash/identify/config.hpp"
#include "lash/identify/preprocess.hpp"
#include "lash/identify/rls.hpp"
#include "lash/identify/verdict.hpp"
#include "lash/metrics/fit.hpp"

namespace lash {

struct DataTraits;  // auto.hpp: what a record shows (the policies' tune())

/// What the rest of lash needs to know of a model, at compile time.
struct ModelTraits {
  ModelKind kind;
  std::string_view name;          ///< CLI/TOML/JSON name ("input-deadzone")
  bool two_sided = true;          ///< per-side parameters (false: one model, reported on `right`)
  bool has_c = false;             ///< a deadzone edge c per side
  bool has_side_d = false;        ///< a deadband half-width d per side
  bool has_shared_d = false;      ///< one deadband d for both directions
  bool keys_by_direction = false; ///< a side's updates are counted per direction ("+", "-")
  bool uses_guesses = false;      ///< switches on v(k−1) against the guesses c_l*, c_r* (set_guess)
  bool free_run_first = false;    ///< the free run steps before the update (it reads last sample's set)
};

namespace detail {
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double deadzone(double x, double cl, double cr) noexcept {
  return x > cr ? x - cr : (x < cl ? x - cl : 0.0);
}
using ValueRange = verdict_rules::ValueRange;
using Extent = verdict_rules::Extent;
/// Samples after a restart() before a regression may use a sample again: the preprocessor's
/// memory, the previous samples y(k−1), y(k−2) and, for IV, the instrument's delay.
inline std::uint32_t warmup_samples(const EstimatorConfig& c, const Preprocessor& p) noexcept {
  const std::size_t iv = c.method == EstimationMethod::iv ? c.iv_delay + 1 : 0;
  return static_cast<std::uint32_t>(p.memory_samples() + 2 + iv);
}
/// Fixed ring of the last 64 values (instrument history).
struct History {
  std::array<double, 64> buf{};
  unsigned pos = 0;
  void push(double x) noexcept { buf[pos++ & 63u] = x; }
  /// j = 1 → last pushed value.
  double ago(std::size_t j) const noexcept { return buf[(pos - static_cast<unsigned>(j)) & 63u]; }
};
/// The one free-run side choice of the two-sided models: right above the right edge, left below
/// the left edge, otherwise (inside the deadzone) the side last used (thesis §1.4.2, docs/method.md §A4.2);
/// by_sign: the side of the sign of x (eq. 34).
constexpr Side free_run_side(double x, const PerSide<double>& edge, Side last, bool by_sign = false) noexcept {
  if (by_sign) return side_of(x);
  return x > edge.right ? Side::right : (x < edge.left ? Side::left : last);
}
/// The free-run model of one side of deadzone → first order → deadband (eq. 36).
struct DzDbSide {
  double a1 = 0.0, b1 = 0.0, d = 0.0;
};
/// One step of that free run: the side by free_run_side (updates `last`), w ← −a1·w + b1·DZ(v1)
/// on the linear part's output w, and the output y held within ±d of w (eq. 5–6). Returns the
/// new y. The estimator's free run (models/deadzone_deadband.cpp) and the output-error fit
/// (output_error.cpp) step this one function.
[[gnu::always_inline]] constexpr double dzdb_free_run(double v1, const PerSide<double>& edge,
                                                     const PerSide<DzDbSide>& sides, bool by_sign, Side& last,
                                                     double& w, double y) noexcept {
  last = free_run_side(v1, edge, last, by_sign);
  const DzDbSide& m = sides[last];
  w = -m.a1 * w + m.b1 * deadzone(v1, edge.left, edge.right);
  if (w < y - m.d) return w + m.d;
  if (w > y + m.d) return w - m.d;
  return y;
}
/// One step of the output-deadzone model's free run (G → DZ, §A4.3): the side of the linear
/// part's output x against the edges (free_run_side, updates `last`), x ← −a1·x + b1·v1, and the
/// output DZ(x). The estimator's free run (models/output_deadzone.cpp) and the output-error fit
/// step this one function.
[[gnu::always_inline]] constexpr double output_dz_free_run(double v1, const PerSide<double>& edge,
                                                          const PerSide<double>& a1, const PerSide<double>& b1,
                                                          Side& last, double& x) noexcept {
  last = free_run_side(x, edge, last);
  x = -a1[last] * x + b1[last] * v1;
  return deadzone(x, edge.left, edge.right);
}
/// Input-side switching (eq. 18): right when v(k−1) > c_r*, left when v(k−1) < c_l*, none inside.
constexpr std::optional<Side> guess_side(double v1, const EstimatorConfig& c) noexcept {
  if (v1 > c.guess_right) return Side::right;
  if (v1 < c.guess_left) return Side::left;
  return std::nullopt;
}
/// Free-run fit of a model (verdict check 6): NRMSE of y_sim against y over t ≥ fit_start_s, or
/// over every sample when the record ends before that.
struct FitWindow {
  std::uint64_t k0 = 0, k = 0;
  NrmseAccumulator window, before;  // t ≥ fit_start_s, and the samples before it
  void add(double y, double ysim) noexcept {
    if (k++ >= k0) [[likely]]
      window.add(y, ysim);
    else
      before.add(y, ysim);
  }
  /// The window's NRMSE; the whole record's when it ended before the window began.
  double nrmse() const noexcept { return window.n > 0 ? window.value() : before.value(); }
};
/// Samples before t = s [s] at period dt (a start beyond 2^64 samples is never reached).
std::uint64_t start_index(double s, double dt) noexcept;
/// Whether a side's estimate (a1, b1, e) with deadzone edge c may drive the free-run simulation:
/// finite and stable (|a1| < 1: a1 ≤ −1 integrates or diverges, and such a transient made E3/E4
/// free runs overflow). The free run holds the last such set of each side. This is not the
/// verdict: a simulable set may still be unphysical (a square wave determines only b1·v + e and
/// its set reproduces the output it was fitted on) — verdict.hpp decides what is presented.
inline bool simulable(const std::array<double, 3>& e, double c) noexcept {
  return std::isfinite(e[0]) && std::isfinite(e[1]) && std::isfinite(e[2]) && std::fabs(e[0]) < 1.0 &&
         std::isfinite(c);
}
/// cfg after cfg.validate() (std::invalid_argument naming the field).
const EstimatorConfig& checked(const EstimatorConfig& cfg);
// x·0 is ±0 for a finite x and NaN for ±inf or NaN: one compare for both, no branch each
constexpr bool finite_all(double a, double b) noexcept { return a * 0.0 + b * 0.0 == 0.0; }
}  // namespace detail

/// The state every model shares, owned by SwitchingEstimator and handed to the policy's hooks.
struct EstimatorCore {
  explicit EstimatorCore(const EstimatorConfig& cfg);  // validates cfg (std::invalid_argument)
  EstimatorConfig cfg;
  Preprocessor pre;
  std::uint32_t warmup = 0, warm = 0;  // warm-up length; samples of it still to go
  /// The record's first samples (fit.k counts them since construction) whose regressors still
  /// hold the filters' zero initial state: they update, but are not evidence of excitation (a
  /// moving average's start-up ramp would make a constant input take several values).
  std::uint64_t start = 0;
  detail::History hist;                // y(k−1), y(k−2), … after the preprocessing (the IV instrument)
  PerSide<detail::ValueRange> vrange{};  // v(k−1) over each side's updates, with its held levels
  PerSide<detail::Extent> yrange{};      // y(k−1) over each side's updates
  detail::FitWindow fit;
  double y1 = 0.0, v1 = 0.0;  // the previous conditioned sample
  double vraw1 = 0.0;         // the previous raw v, delayed by the dead time (the free run's input)
  double yhat = 0.0, ysim = 0.0;
  std::uint64_t skipped = 0;

  /// One regression step with φ, by the configured method: LS, or IV with the instrument φ whose
  /// first entry −y(k−1) is replaced by −y(k−1−iv_delay). Returns ŷ.
  template <std::size_t N>
  double regress(Rls<N>& r, const std::array<double, N>& phi, double y) noexcept {
    if (cfg.method == EstimationMethod::iv) {
      std::array<double, N> z = phi;
      z[0] = -hist.ago(1 + cfg.iv_delay);
      return r.update_iv(phi, z, y);
    }
    return r.update(phi, y);
  }
  /// The regressors of an update of side s enter its value ranges (verdict check 2).
  void seen(Side s, double v, double y) noexcept {
    if (fit.k < start) return;  // fit.k: this sample's index (fit.add comes after the update)
    vrange[s].add(v);
    yrange[s].add(y);
  }
  /// Check 2's value tests for a side of a two-sided model: v varied (not held at one level
  /// on most updates) and y took several values.
  bool excited(Side s) const noexcept { return vrange[s].varied() && yrange[s].several(); }
  /// The same for the linear model, whose regression has no offset: v and y took several values
  /// (a step's one level beyond zero identifies a1 and b1).
  bool varies(Side s) const noexcept { return vrange[s].several() && yrange[s].several(); }
  /// Verdict check 2's condition test. Least squares: P is the (scaled) inverse information
  /// matrix. Instrumental variables: P = (Σ z φᵀ)⁻¹ is not symmetric and not a covariance, so
  /// the test does not apply (the value-range checks still do).
  template <std::size_t N>
  bool conditioned(const Rls<N>& r) const noexcept {
    return cfg.method == EstimationMethod::iv || verdict_rules::well_conditioned<N>(r.P());
  }
};

/// The step evidence → SideParams: the verdict of checks 1–5 and, when it is clean, the values
/// (a1, b1 and, where the model has them, c and d); NaN otherwise.
constexpr SideParams side_params(const verdict_rules::Evidence& ev, Reason r) noexcept {
  SideParams p;
  p.reason = r;
  p.identified = r == Reason::none;
  if (p.identified) {
    p.a1 = ev.a1;
    p.b1 = ev.b1;
    if (ev.has_c) p.c = ev.c;
    if (ev.has_d) p.d = ev.d;
  }
  return p;
}

template <class Model>
class SwitchingEstimator : public Model {
 public:
  static constexpr ModelTraits traits = Model::traits;

  /// Validates cfg (std::invalid_argument naming the field) and allocates the filters.
  explicit SwitchingEstimator(const EstimatorConfig& cfg) : Model(detail::checked(cfg)), c_(cfg) {}

  /// Advances one sample (v(k), y(k)); returns ŷ(k) = φᵀη̂(k−1) (eq. 14) of the regression the
  /// sample selects. A non-finite sample changes nothing but the skip count (ŷ = NaN).
  /// noexcept, O(1), allocation-free.
  double step(double v, double y) noexcept;
  double prediction() const noexcept { return c_.yhat; }
  /// The free-run output y_sim(k) of the identified model driven by v alone.
  double simulated() const noexcept { return c_.ysim; }
  /// Side s's parameters with the update-time verdict (checks 1–5 of verdict.hpp); NaN while
  /// not identified. A one-sided model (linear) answers the same for both sides.
  SideParams params(Side s = Side::right) const noexcept {
    const verdict_rules::Evidence ev = Model::evidence(c_, s);
    Reason r = verdict_rules::judge(ev);
    if constexpr (requires(const Model& m) { m.settled(c_, s); })
      if (r == Reason::none && !Model::settled(c_, s)) r = Reason::not_updated;  // a transient
    SideParams p = side_params(ev, r);
    if constexpr (traits.has_shared_d) p.d = Model::deadband();
    return p;
  }
  /// The full verdict (checks 1–6): what reports show.
  Reason verdict(Side s = Side::right) const noexcept {
    return verdict_rules::finish(params(s).reason, Model::conditioned(c_, s), c_.fit.nrmse(), c_.cfg.fit_threshold);
  }
  /// The model's verdict: every side (and a shared deadband) identified.
  bool identified() const noexcept {
    if constexpr (!traits.two_sided) return verdict(Side::right) == Reason::none;
    bool ok = verdict(Side::right) == Reason::none && verdict(Side::left) == Reason::none;
    if constexpr (traits.has_shared_d) ok = ok && Model::deadband_reason() == Reason::none;
    return ok;
  }
  /// Updates of side s (of the model, when one-sided).
  std::uint64_t updates(Side s = Side::right) const noexcept { return Model::side_updates(s); }
  /// Updates of key (side, +) or (side, −).
  /// (A member template: an explicit instantiation of the class leaves it out where the model has
  /// no such keys.)
  template <class M = Model>
    requires(M::traits.keys_by_direction)
  std::uint64_t updates(Side s, bool plus) const noexcept {
    return M::key_updates(s, plus);
  }
  /// The deadzone edge c that side s's regression points at, identified or not: the identified c,
  /// else the model's c from the raw estimate once the side has min_updates updates; NaN when
  /// there is none (auto.cpp's guess search reads it).
  double raw_edge(Side s) const noexcept {
    const SideParams p = params(s);
    if (p.identified && std::isfinite(p.c)) return p.c;
    if constexpr (requires(const Model& m) { m.edge(s); }) {
      if (updates(s) < c_.cfg.min_updates) return detail::kNaN;
      return Model::edge(s);
    }
    return detail::kNaN;
  }
  /// Non-finite samples and skipped regression updates.
  std::uint64_t skipped() const noexcept { return c_.skipped + Model::rls_skipped(); }
  /// NRMSE of the free run y_sim against y (verdict check 6, a fraction).
  double fit_nrmse() const noexcept { return c_.fit.nrmse(); }
  const EstimatorConfig& config() const noexcept { return c_.cfg; }

  /// Back to the state right after construction. Not real-time safe (reallocates the filters).
  void reset() { *this = SwitchingEstimator(c_.cfg); }
  /// After a gap: clears the signal history, keeps the estimates (see estimators.hpp).
  void restart() noexcept {
    c_.pre.reset();
    c_.hist = {};
    c_.y1 = c_.v1 = 0.0;
    c_.warm = c_.warmup;
    Model::restart();
  }
  /// Samples after restart() that update nothing.
  std::uint32_t warmup() const noexcept { return c_.warmup; }
  /// True while samples of that warm-up are still to go (after the last step()).
  bool warming_up() const noexcept { return c_.warm > 0; }

  /// Sets side s's switching guess (guess_right / guess_left: c_r*, c_l*) and starts that side's
  /// recursion anew — its RLS (η0, P0, no updates), its value ranges and settling (the verdict's
  /// evidence), its free-run parameter set — without touching the other side or the signal
  /// history. Models that do not switch on the guesses (traits.uses_guesses false) only store
  /// the value. noexcept, allocation-free.
  void set_guess(Side s, double guess) noexcept {
    c_.cfg.guess(s) = guess;
    if constexpr (traits.uses_guesses) {
      c_.vrange[s] = {};
      c_.yrange[s] = {};
      Model::restart_side(c_, s);
    }
  }

 private:
  EstimatorCore c_;
};

// The sample path, instantiated once per model in the model's source file (the hooks inline into it).
template <class Model>
double SwitchingEstimator<Model>::step(double v, double y) noexcept {
  if (!detail::finite_all(v, y)) [[unlikely]] {
    ++c_.skipped;
    return c_.yhat = detail::kNaN;
  }
  const Conditioned s = c_.pre.step(v, y);
  const bool warming = c_.warm > 0;  // after a gap: the regressors are not all from this side of it yet
  if (warming) --c_.warm;
  if constexpr (traits.free_run_first) Model::free_run(c_);
  c_.yhat = Model::update(c_, s, warming);
  if constexpr (!traits.free_run_first) Model::free_run(c_);
  c_.hist.push(s.y);
  c_.y1 = s.y;
  c_.v1 = s.v;
  c_.vraw1 = s.vplant;
  c_.fit.add(y, c_.ysim);
  return c_.yhat;
}

namespace detail {
/// What the three models with one Rls<3> per side (η = [a1, b1, e]) share: the regressions, the
/// parameter set the free run holds per side, and the side's evidence.
class SideRegressions {
 public:
  const Rls<3>& rls(Side s) const noexcept { return rls_[s]; }

 protected:
  SideRegressions(const EstimatorConfig& cfg, PerSide<double> c0) : rls_{Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3())}, sc_(c0) {}
  /// Updates side s with φ = [−y(k−1), v(k−1), 1] (or its instrument); returns ŷ.
  double regress_side(EstimatorCore& c, Side s, double y) noexcept {
    c.seen(s, c.v1, c.y1);
    return c.regress(rls_[s], std::array<double, 3>{-c.y1, c.v1, 1.0}, y);
  }
  /// The free run holds side s's set (a1, b1, edge) from now on.
  void hold(Side s, double edge) noexcept {
    sa1_[s] = rls_[s].eta(0);
    sb1_[s] = rls_[s].eta(1);
    sc_[s] = edge;
  }
  /// Checks 1–5 see side s with deadzone edge `edge`.
  verdict_rules::Evidence side_evidence(const EstimatorCore& c, Side s, double edge, bool guess_ok) const noexcept {
    verdict_rules::Evidence ev;
    ev.side = s;
    ev.updated = rls_[s].updates() >= c.cfg.min_updates;
    ev.excited = c.excited(s);
    ev.a1 = rls_[s].eta(0);
    ev.b1 = rls_[s].eta(1);
    ev.has_c = true;
    ev.c = edge;
    ev.guess_ok = guess_ok;
    return ev;
  }
  bool conditioned(const EstimatorCore& c, Side s) const noexcept { return c.conditioned(rls_[s]); }
  std::uint64_t side_updates(Side s) const noexcept { return rls_[s].updates(); }
  std::uint64_t rls_skipped() const noexcept { return rls_.right.skipped() + rls_.left.skipped(); }

  PerSide<Rls<3>> rls_;
  PerSide<double> sa1_{}, sb1_{}, sc_{};  // the parameter set the free run uses per side
  Side sim_last_ = Side::right;
};
}  // namespace detail

/// What every estimator offers (the generic tester and AnyEstimator rely on it).
template <class E>
concept Estimator = std::constructible_from<E, const EstimatorConfig&> &&
                    requires(E e, const E ce, double x, Side s) {
                      { E::traits } -> std::convertible_to<ModelTraits>;
                      { e.step(x, x) } noexcept -> std::same_as<double>;
                      { e.restart() } noexcept;
                      { e.set_guess(s, x) } noexcept;
                      e.reset();
                      { ce.prediction() } noexcept -> std::same_as<double>;
                      { ce.simulated() } noexcept -> std::same_as<double>;
                      { ce.params(s) } noexcept -> std::same_as<SideParams>;
                      { ce.verdict(s) } noexcept -> std::same_as<Reason>;
                      { ce.identified() } noexcept -> std::same_as<bool>;
                      { ce.updates(s) } noexcept -> std::same_as<std::uint64_t>;
                      { ce.skipped() } noexcept -> std::same_as<std::uint64_t>;
                      { ce.fit_nrmse() } noexcept -> std::same_as<double>;
                      { ce.warmup() } noexcept -> std::same_as<std::uint32_t>;
                      { ce.warming_up() } noexcept -> std::same_as<bool>;
                      { ce.config() } noexcept -> std::same_as<const EstimatorConfig&>;
                    };

}  // namespace lash
