#include "lash/identify/estimators.hpp"
#include "lash/io/numeric.hpp"

#include <algorithm>
#include <cmath>

namespace lash {

using detail::kNaN;

namespace {
const EstimatorConfig& checked(const EstimatorConfig& c) {
  c.validate();
  return c;
}
// x·0 is ±0 for a finite x and NaN for ±inf or NaN: one compare for both, no branch each
bool finite_all(double a, double b) noexcept { return a * 0.0 + b * 0.0 == 0.0; }

/// Whether a side's estimate (a1, b1, e) with deadzone edge c may drive the free-run simulation:
/// finite and stable (|a1| < 1: a1 ≤ −1 integrates or diverges, and such a transient made E3/E4
/// free runs overflow). The free run holds the last such set of each side. This is not the
/// verdict: a simulable set may still be unphysical (a square wave determines only b1·v + e and
/// its set reproduces the output it was fitted on) — verdict.hpp decides what is presented.
bool simulable(const std::array<double, 3>& e, double c) noexcept {
  return std::isfinite(e[0]) && std::isfinite(e[1]) && std::isfinite(e[2]) && std::fabs(e[0]) < 1.0 &&
         std::isfinite(c);
}
/// Verdict check 2's condition test. Least squares: P is the (scaled) inverse information
/// matrix. Instrumental variables: P = (Σ z φᵀ)⁻¹ is not symmetric and not a covariance, so
/// the test does not apply (the value-range checks still do).
template <std::size_t N>
bool conditioned(const EstimatorConfig& c, const Rls<N>& r) noexcept {
  return c.method == EstimationMethod::iv || verdict_rules::well_conditioned<N>(r.P());
}
std::uint64_t fit_start_index(const EstimatorConfig& c) {
  // A start beyond 2^64 samples is never reached.
  return ceil_to<std::uint64_t>(c.fit_start_s / c.dt_s - 1e-9).value_or(std::numeric_limits<std::uint64_t>::max());
}
}  // namespace

// ---------------------------------------------------------------- linear (eq. 9–16)

LinearEstimator::LinearEstimator(const EstimatorConfig& cfg)
    : cfg_(checked(cfg)), pre_(cfg.noise, cfg.dt_s), rls_(cfg.rls2()), warmup_(detail::warmup_samples(cfg, pre_)) {
  fit_.k0 = fit_start_index(cfg);
}

void LinearEstimator::restart() noexcept {
  pre_.reset();
  hist_ = {};
  y1_ = v1_ = 0.0;
  warm_ = warmup_;
}

double LinearEstimator::step(double v, double y) noexcept {
  if (!finite_all(v, y)) [[unlikely]] {
    ++skipped_;
    return yhat_ = kNaN;
  }
  const Conditioned s = pre_.step(v, y);
  const std::array<double, 2> phi{-y1_, v1_};
  const bool warming = warm_ > 0;  // after a gap: the regressors are not all from this side of it yet
  if (warming) {
    --warm_;
    yhat_ = rls_.predict(phi);
  } else if (cfg_.method == EstimationMethod::iv) {
    yhat_ = rls_.update_iv(phi, {-hist_.ago(1 + cfg_.iv_delay), v1_}, s.y);
  } else {
    yhat_ = rls_.update(phi, s.y);
  }
  if (!warming && rls_.updates() > 1) {  // the first update's regressors are the zero initial state, not data
    vrange_.add(v1_);
    yrange_.add(y1_);
  }
  hist_.push(s.y);
  y1_ = s.y;
  v1_ = s.v;
  x_ = -rls_.eta(0) * x_ + rls_.eta(1) * vraw1_;
  ysim_ = x_;
  vraw1_ = v;
  fit_.add(y, ysim_);
  return yhat_;
}

SideParams LinearEstimator::params() const noexcept {
  verdict_rules::Evidence ev;
  ev.updated = rls_.updates() >= cfg_.min_updates;
  ev.excited = vrange_.several() && yrange_.several();
  ev.a1 = rls_.eta(0);
  ev.b1 = rls_.eta(1);
  SideParams p;
  p.reason = verdict_rules::judge(ev);
  p.identified = p.reason == Reason::none;
  if (p.identified) {
    p.a1 = ev.a1;
    p.b1 = ev.b1;
  }
  return p;
}

Reason LinearEstimator::verdict(Side) const noexcept {
  return verdict_rules::finish(params().reason, conditioned(cfg_, rls_), fit_.nrmse(), cfg_.fit_threshold);
}

// ---------------------------------------------------------------- two-side deadzone estimators

namespace detail {

TwoSideEstimator::TwoSideEstimator(const EstimatorConfig& cfg)
    : cfg_(checked(cfg)),
      pre_(cfg.noise, cfg.dt_s),
      rls_{Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3())},
      warmup_(warmup_samples(cfg, pre_)) {
  fit_.k0 = fit_start_index(cfg);
}

void TwoSideEstimator::restart() noexcept {
  pre_.reset();
  hist_ = {};
  y1_ = v1_ = 0.0;
  warm_ = warmup_;
}

void TwoSideEstimator::refresh(Side s, double c, bool guess_ok) noexcept {
  const auto& e = rls_[s].eta();
  const bool enough = rls_[s].updates() >= cfg_.min_updates;
  if (enough && simulable(e, c)) {  // the free run holds the last stable set of each side (none yet: no output)
    sa1_[s] = e[0];
    sb1_[s] = e[1];
    sc_[s] = c;
  }
  verdict_rules::Evidence ev;
  ev.side = s;
  ev.updated = enough;
  ev.excited = vrange_[s].several() && yrange_[s].several();
  ev.a1 = e[0];
  ev.b1 = e[1];
  ev.has_c = true;
  ev.c = c;
  ev.guess_ok = guess_ok;
  SideParams& p = p_[s];
  p = SideParams{};
  p.reason = verdict_rules::judge(ev);
  p.identified = p.reason == Reason::none;
  if (p.identified) {
    p.a1 = e[0];
    p.b1 = e[1];
    p.c = c;
  }
}

double TwoSideEstimator::update(Side s, double y) noexcept {
  vrange_[s].add(v1_);
  yrange_[s].add(y1_);
  const std::array<double, 3> phi{-y1_, v1_, 1.0};
  if (cfg_.method == EstimationMethod::iv) return rls_[s].update_iv(phi, {-hist_.ago(1 + cfg_.iv_delay), v1_, 1.0}, y);
  return rls_[s].update(phi, y);
}

Reason TwoSideEstimator::verdict(Side s) const noexcept {
  return verdict_rules::finish(p_[s].reason, conditioned(cfg_, rls_[s]), fit_.nrmse(), cfg_.fit_threshold);
}

}  // namespace detail

// ---------------------------------------------------------------- input deadzone (§1.4.2)

InputDeadzoneEstimator::InputDeadzoneEstimator(const EstimatorConfig& cfg) : TwoSideEstimator(cfg) {
  sc_ = {cfg.guess_right, cfg.guess_left};
}

void InputDeadzoneEstimator::refresh(Side s) noexcept {
  const auto& e = rls_[s].eta();
  const double c = std::fabs(e[1]) > 1e-12 ? -e[2] / e[1] : kNaN;  // e = −b1·c (eq. 21–22)
  // the method's premise (eq. 18): the guesses lie outside the deadzone, c_l* < c < c_r*
  TwoSideEstimator::refresh(s, c, c > cfg_.guess_left && c < cfg_.guess_right);
}

void InputDeadzoneEstimator::set_guess(Side s, double guess) noexcept {
  (s == Side::right ? cfg_.guess_right : cfg_.guess_left) = guess;
  rls_[s].reset();
  p_[s] = SideParams{};
  vrange_[s] = {};
  yrange_[s] = {};
}

double InputDeadzoneEstimator::step(double v, double y) noexcept {
  if (!finite_all(v, y)) [[unlikely]] {
    ++skipped_;
    return yhat_ = kNaN;
  }
  const Conditioned s = pre_.step(v, y);
  const auto side = detail::guess_side(v1_, cfg_);
  if (warm_ > 0) --warm_;  // after a gap: no update (see restart())
  if (side && warm_ == 0) {
    yhat_ = update(*side, s.y);
    refresh(*side);
    last_ = *side;
  } else {
    yhat_ = -rls_[last_].eta(0) * y1_;  // inside the deadzone u = 0 (eq. 17), a1 of the side last used
  }
  hist_.push(s.y);
  y1_ = s.y;
  v1_ = s.v;
  // free-run simulation of eq. 17 driven by the raw v
  const Side ss = detail::free_run_side(vraw1_, sc_, sim_last_, cfg_.sim_side_by_sign);
  sim_last_ = ss;
  w_ = -sa1_[ss] * w_ + sb1_[ss] * detail::deadzone(vraw1_, sc_.left, sc_.right);
  ysim_ = w_;
  vraw1_ = v;
  fit_.add(y, ysim_);
  return yhat_;
}

// ---------------------------------------------------------------- output deadzone (§1.6.1)

OutputDeadzoneEstimator::OutputDeadzoneEstimator(const EstimatorConfig& cfg) : TwoSideEstimator(cfg) {}

void OutputDeadzoneEstimator::refresh(Side s) noexcept {
  const auto& e = rls_[s].eta();
  const double den = 1.0 + e[0];
  const double c = std::fabs(den) > 1e-9 ? -e[2] / den : kNaN;  // e = −c(1 + a1) (eq. 36)
  TwoSideEstimator::refresh(s, c, true);
}

double OutputDeadzoneEstimator::step(double v, double y) noexcept {
  if (!finite_all(v, y)) [[unlikely]] {
    ++skipped_;
    return yhat_ = kNaN;
  }
  const Conditioned s = pre_.step(v, y);
  const double y1 = y1_, v1 = v1_, z = cfg_.zero_threshold;
  // free-run simulation: x = G(v), y_sim = DZ(x); the side follows x against the deadzone
  {
    const Side ss = detail::free_run_side(x_, sc_, sim_last_);
    sim_last_ = ss;
    x_ = -sa1_[ss] * x_ + sb1_[ss] * vraw1_;
    ysim_ = detail::deadzone(x_, sc_.left, sc_.right);
    vraw1_ = v;
  }
  const bool warming = warm_ > 0;  // after a gap: no update (see restart())
  if (warming) --warm_;
  if (!warming && s.y > z && y1 > z) {
    yhat_ = update(Side::right, s.y);
    refresh(Side::right);
  } else if (!warming && s.y < -z && y1 < -z) {
    yhat_ = update(Side::left, s.y);
    refresh(Side::left);
  } else if (y1 > z) {
    yhat_ = rls_.right.predict({-y1, v1, 1.0});
    if (yhat_ < 0.0) yhat_ = 0.0;
  } else if (y1 < -z) {
    yhat_ = rls_.left.predict({-y1, v1, 1.0});
    if (yhat_ > 0.0) yhat_ = 0.0;
  } else {
    yhat_ = 0.0;
  }
  hist_.push(s.y);
  y1_ = s.y;
  v1_ = s.v;
  fit_.add(y, ysim_);
  return yhat_;
}

// ---------------------------------------------------------------- deadzone + deadband (§1.4.3)

DeadzoneDeadbandEstimator::DeadzoneDeadbandEstimator(const EstimatorConfig& cfg)
    : cfg_(checked(cfg)),
      pre_(cfg.noise, cfg.dt_s),
      rls_{Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3())},
      pooled_{Rls<4>(cfg.rls4()), Rls<4>(cfg.rls4())},
      warmup_(detail::warmup_samples(cfg, pre_)) {
  sc_ = {cfg.guess_right, cfg.guess_left};
  fit_.k0 = fit_start_index(cfg);
}

void DeadzoneDeadbandEstimator::restart() noexcept {
  pre_.reset();
  hist_ = {};
  y1_ = v1_ = 0.0;
  regime1_ = 0;
  run_ = 0;
  warm_ = warmup_;
}

void DeadzoneDeadbandEstimator::set_guess(Side s, double guess) noexcept {
  (s == Side::right ? cfg_.guess_right : cfg_.guess_left) = guess;
  for (const bool plus : {true, false}) {
    rls_[key(s, plus)].reset();
    count_[key(s, plus)] = 0;
  }
  pooled_[s].reset();
  usable_[s] = false;
  settled_[s] = since_[s] = 0;
  prev_c_[s] = prev_d_[s] = 0.0;
  vrange_[s] = {};
  yrange_[s] = {};
}

// simulate() and predict_free() run on every sample: defined here, before step(), and inlined
// into it (a call each cost about a tenth of the sample).
[[gnu::always_inline]] inline double DeadzoneDeadbandEstimator::predict_free(Side side, double y1, double v1) const noexcept {
  // Deadband logic in the y domain: moving up if the + model lands above y(k−1), down if the
  // − model lands below it, otherwise the output holds.
  double up, down;
  if (cfg_.pooled) {
    // φᵀη with φ = [−y1, v1, 1, ∓1]: the shared part once, then ∓g (the same sums as predict())
    const auto& e = pooled_[side].eta();
    const double base = (0.0 + -y1 * e[0] + v1 * e[1]) + e[2];
    up = base - e[3];
    down = base + e[3];
  } else {
    up = rls_[key(side, true)].predict({-y1, v1, 1.0});
    down = rls_[key(side, false)].predict({-y1, v1, 1.0});
  }
  if (up > y1) return up;
  if (down < y1) return down;
  return y1;
}

[[gnu::always_inline]] inline void DeadzoneDeadbandEstimator::simulate(double v) noexcept {
  const Side s = detail::free_run_side(vraw1_, sc_, sim_last_, cfg_.sim_side_by_sign);
  sim_last_ = s;
  const double u = detail::deadzone(vraw1_, sc_.left, sc_.right);
  const FreeRunSide& m = sim_[s];
  w_ = -m.a1 * w_ + m.b1 * u;
  const double d = m.d;
  if (w_ < ysim_ - d) ysim_ = w_ + d;
  else if (w_ > ysim_ + d) ysim_ = w_ - d;
  vraw1_ = v;
}

double DeadzoneDeadbandEstimator::step(double v, double y) noexcept {
  if (!finite_all(v, y)) [[unlikely]] {
    ++skipped_;
    return yhat_ = kNaN;
  }
  const Conditioned s = pre_.step(v, y);
  const int dir = direction(s.ydot, cfg_.noise.derivative_threshold);
  const double y1 = y1_, v1 = v1_;
  const std::optional<Side> side = detail::guess_side(v1, cfg_);
  // the direction hold: samples in a row with the same moving direction on the same side
  // (regime 0 = not moving: never counts; one compare instead of two and an optional's)
  const int regime = dir == 0 ? 0 : dir * (side ? 1 + static_cast<int>(*side) : 3);
  run_ = (regime != 0 && regime == regime1_) ? run_ + 1 : 1;
  regime1_ = regime;
  if (warm_ > 0) [[unlikely]] {  // after a gap (restart()): the direction hold starts again once the history is refilled
    --warm_;
    run_ = 0;
  }
  if (side && dir != 0 && run_ >= cfg_.direction_run) {
    const Side sd = *side;
    const Key k = key(sd, dir > 0);
    if (cfg_.pooled) {
      const double sg = dir > 0 ? -1.0 : 1.0;
      const std::array<double, 4> phi{-y1, v1, 1.0, sg};
      if (cfg_.method == EstimationMethod::iv)
        yhat_ = pooled_[sd].update_iv(phi, {-hist_.ago(1 + cfg_.iv_delay), v1, 1.0, sg}, s.y);
      else
        yhat_ = pooled_[sd].update(phi, s.y);
      ++count_[k];
    } else {
      const std::array<double, 3> phi{-y1, v1, 1.0};
      if (cfg_.method == EstimationMethod::iv)
        yhat_ = rls_[k].update_iv(phi, {-hist_.ago(1 + cfg_.iv_delay), v1, 1.0}, s.y);
      else
        yhat_ = rls_[k].update(phi, s.y);
      count_[k] = rls_[k].updates();
    }
    vrange_[sd].add(v1);
    yrange_[sd].add(y1);
    // Derived (a1, b1, c, d) are refreshed on every update until the side is usable, then
    // every 8th update (the free run lags at most 7 updates; params() is always current).
    if (!usable_[sd] || (++since_[sd] & 7u) == 0) [[unlikely]] refresh(sd);
    last_ = sd;
  } else {
    yhat_ = predict_free(side ? *side : last_, y1, v1);
  }
  hist_.push(s.y);
  y1_ = s.y;
  v1_ = s.v;
  simulate(v);
  fit_.add(y, ysim_);
  return yhat_;
}

std::uint64_t DeadzoneDeadbandEstimator::skipped() const noexcept {
  std::uint64_t n = skipped_;
  for (const auto& r : rls_) n += r.skipped();
  n += pooled_.right.skipped() + pooled_.left.skipped();
  return n;
}

DeadzoneDeadbandEstimator::Derived DeadzoneDeadbandEstimator::derive(Side side, bool with_verdict) const noexcept {
  const std::uint64_t np = count_[key(side, true)], nm = count_[key(side, false)];
  double a1, b1, c, d;
  const bool updated = np >= cfg_.min_updates && nm >= cfg_.min_updates;
  bool solvable;
  if (cfg_.pooled) {
    // η = [a1, b1, e0, g] with e± = e0 ∓ g, e0 = −b1·c, g = d(1 + a1)
    const auto& e = pooled_[side].eta();
    a1 = e[0];
    b1 = e[1];
    const double den = 1.0 + a1;
    solvable = std::fabs(den) > cfg_.singular_tol && std::fabs(b1) > 1e-12;
    c = -e[2] / b1;
    d = e[3] / den;
  } else {
    const auto& ep = rls_[key(side, true)].eta();
    const auto& em = rls_[key(side, false)].eta();
    // eq. 31/32: [−(1+a+)  −b+; (1+a−)  −b−] [d; c] = [e+; e−]
    const double t1 = (1.0 + ep[0]) * em[1], t2 = ep[1] * (1.0 + em[0]);
    const double det = t1 + t2;
    solvable = std::fabs(det) > cfg_.singular_tol * (std::fabs(t1) + std::fabs(t2));
    // one division for both the count-weighted mean (1/n) and the 2×2 solve (1/det)
    const double fp = static_cast<double>(np), fm = static_cast<double>(nm);
    const double n = fp + fm;  // ≥ 1: this side was just updated
    double inv, inv_n;
    if (det != 0.0 && std::isfinite(det)) {
      const double both = 1.0 / (n * det);
      inv = n * both;
      inv_n = det * both;
    } else {  // singular: no (d, c), but the model keeps its a1, b1
      inv = detail::kNaN;
      inv_n = 1.0 / n;
    }
    a1 = (fp * ep[0] + fm * em[0]) * inv_n;
    b1 = (fp * ep[1] + fm * em[1]) * inv_n;
    d = (-em[1] * ep[2] + ep[1] * em[2]) * inv;
    c = (-(1.0 + em[0]) * ep[2] - (1.0 + ep[0]) * em[2]) * inv;
  }
  const bool finite = std::isfinite(c) && std::isfinite(d) && std::isfinite(a1) && std::isfinite(b1);
  const bool guess_ok = c > cfg_.guess_left && c < cfg_.guess_right;
  Derived q;
  q.p.a1 = a1;  // raw values; `reason` tells whether they count
  q.p.b1 = b1;
  q.p.c = c;
  q.p.d = d;
  // usable for the free run (and the refresh cadence): the method's own premise (eq. 18): the
  // guesses lie outside the deadzone, c_l* < c < c_r*, and a deadband half-width is not
  // negative. An estimate outside that is a transient of a key that has not converged yet.
  q.usable = updated && solvable && finite && guess_ok && d >= 0.0;
  if (!with_verdict) return q;  // the free run's refresh reads only the values and `usable`
  verdict_rules::Evidence ev;
  ev.side = side;
  ev.updated = updated;
  ev.excited = solvable && vrange_[side].several() && yrange_[side].several();
  ev.a1 = a1;
  ev.b1 = b1;
  ev.has_c = ev.has_d = true;
  ev.c = c;
  ev.d = d;
  ev.guess_ok = guess_ok;
  q.p.reason = verdict_rules::judge(ev);
  q.p.identified = q.p.reason == Reason::none;
  return q;
}

void DeadzoneDeadbandEstimator::refresh(Side side) noexcept {
  const Derived q = derive(side, false);
  // settled: (c, d) stopped moving between refreshes (see EstimatorConfig::settle_tol)
  const bool still = std::fabs(q.p.c - prev_c_[side]) + std::fabs(q.p.d - prev_d_[side]) <=
                     cfg_.settle_tol * (std::fabs(q.p.c) + std::fabs(q.p.d));
  settled_[side] = still ? settled_[side] + 1 : 0;
  prev_c_[side] = q.p.c;
  prev_d_[side] = q.p.d;
  const bool ok = q.usable && settled_[side] >= cfg_.settle_updates;
  usable_[side] = ok;
  sim_[side].a1 = q.p.a1;
  sim_[side].b1 = q.p.b1;
  if (ok) {
    sc_[side] = q.p.c;
    sim_[side].d = q.p.d > 0.0 ? q.p.d : 0.0;
  }
}

SideParams DeadzoneDeadbandEstimator::params(Side s) const noexcept {
  Derived q = derive(s);  // always current, even between refreshes of the free-run model
  // a set whose (c, d) still move is a transient: not updated enough yet
  if (q.p.reason == Reason::none && settled_[s] < cfg_.settle_updates) q.p.reason = Reason::not_updated;
  if (q.p.reason != Reason::none) {
    SideParams p;
    p.reason = q.p.reason;
    return p;
  }
  return q.p;
}

Reason DeadzoneDeadbandEstimator::verdict(Side s) const noexcept {
  const bool cond = cfg_.pooled ? conditioned(cfg_, pooled_[s])
                                : conditioned(cfg_, rls_[key(s, true)]) && conditioned(cfg_, rls_[key(s, false)]);
  return verdict_rules::finish(params(s).reason, cond, fit_.nrmse(), cfg_.fit_threshold);
}

// ---------------------------------------------------------------- coupled carts (§1.6.3)

CoupledCartsEstimator::CoupledCartsEstimator(const EstimatorConfig& cfg)
    : cfg_(checked(cfg)),
      pre_(cfg.noise, cfg.dt_s),
      rls_{Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3())},
      warmup_(detail::warmup_samples(cfg, pre_)) {
  stage2_k_ = ceil_to<std::uint64_t>(cfg.stage2_start_s / cfg.dt_s - 1e-9).value_or(std::numeric_limits<std::uint64_t>::max());
  fit_.k0 = fit_start_index(cfg);
}

void CoupledCartsEstimator::restart() noexcept {
  pre_.reset();
  vel1_ = v1_ = y1_ = 0.0;
  dir1_ = dir2_ = 0;
  r_ok_ = false;  // a slot crossing is never measured across the gap
  warm_ = warmup_;
}

std::uint64_t CoupledCartsEstimator::skipped() const noexcept {
  return skipped_ + rls_.right.skipped() + rls_.left.skipped();
}

void CoupledCartsEstimator::refresh(Side s) noexcept {
  const auto& e = rls_[s].eta();
  // The free run uses a side's set only when it is usable: enough updates, finite, a stable
  // first-order lag with a positive time constant (−1 < a1 < 0, τ = −T/ln(−a1); a1 ≤ −1
  // integrates or diverges and made the E5 square-wave free runs overflow), the deadzone edge on
  // its own side of zero (c_r ≥ 0 ≥ c_l, thesis §1.6.1) and the input not constant over the
  // side's updates (a constant v makes b1 and e inseparable: only b1·v + e is determined).
  const bool stable =
      std::isfinite(e[0]) && std::isfinite(e[1]) && std::isfinite(e[2]) && e[0] > -1.0 && e[0] < 0.0;
  const double c = stable ? -e[2] / (1.0 + e[0]) : kNaN;  // eq. 38: e = −c(1 + a1)
  const bool enough = rls_[s].updates() >= cfg_.min_updates;
  const bool usable = enough && stable && std::isfinite(c) && verdict_rules::physical_edge(c, s) && vrange_[s].several();
  if (usable) {  // the free run uses the last usable set of each side (never an unstable transient)
    sa1_[s] = e[0];
    sb1_[s] = e[1];
    sc_[s] = c;
    valid_[s] = true;
  }
  verdict_rules::Evidence ev;
  ev.side = s;
  ev.updated = enough;
  ev.excited = vrange_[s].several() && yrange_[s].several();
  ev.a1 = e[0];
  ev.b1 = e[1];
  ev.has_c = true;
  ev.c = std::fabs(1.0 + e[0]) > 0.0 ? -e[2] / (1.0 + e[0]) : kNaN;
  ev.negative_a1 = true;
  SideParams& p = p_[s];
  p = SideParams{};
  p.reason = verdict_rules::judge(ev);
  p.identified = p.reason == Reason::none;
  if (p.identified) {
    p.a1 = e[0];
    p.b1 = e[1];
    p.c = c;
  }
}

SideParams CoupledCartsEstimator::params(Side s) const noexcept {
  SideParams p = p_[s];
  p.d = deadband();
  return p;
}

Reason CoupledCartsEstimator::verdict(Side s) const noexcept {
  return verdict_rules::finish(p_[s].reason, conditioned(cfg_, rls_[s]), fit_.nrmse(), cfg_.fit_threshold);
}

double CoupledCartsEstimator::deadband() const noexcept {
  return dcount_[0] + dcount_[1] > 0 ? dsum_ / static_cast<double>(dcount_[0] + dcount_[1]) : kNaN;
}

Reason CoupledCartsEstimator::deadband_reason() const noexcept {
  const double d = deadband();
  if (!std::isfinite(d)) return Reason::not_updated;
  return d >= 0.0 ? Reason::none : Reason::unphysical;
}

bool CoupledCartsEstimator::identified() const noexcept {
  return verdict(Side::right) == Reason::none && verdict(Side::left) == Reason::none &&
         deadband_reason() == Reason::none;
}

double CoupledCartsEstimator::step(double v, double y) noexcept {
  if (!finite_all(v, y)) [[unlikely]] {
    ++skipped_;
    return yhat_ = kNaN;
  }
  const Conditioned s = pre_.step(v, y);
  const double vel = s.ydot;  // free-cart velocity
  const int dir = direction(vel, cfg_.noise.derivative_threshold);
  const double vel1 = vel1_, v1 = v1_;
  const bool steady = std::fabs(vel - vel1) * (1.0 / cfg_.dt_s) <= cfg_.accel_limit;
  double vel_pred = 0.0;
  const bool warming = warm_ > 0;  // after a gap: no update (see restart())
  if (warming) --warm_;
  if (!warming && dir != 0 && dir == dir1_ && dir == dir2_ && steady) {
    const Side i = dir > 0 ? Side::right : Side::left;
    vel_pred = rls_[i].update({-vel1, v1, 1.0}, vel);
    vrange_[i].add(v1);
    yrange_[i].add(vel1);
    refresh(i);
  } else if (dir1_ != 0) {
    vel_pred = rls_[dir1_ > 0 ? Side::right : Side::left].predict({-vel1, v1, 1.0});
  }
  yhat_ = y1_ + cfg_.dt_s * vel_pred;
  // free-run: velocity model (output deadzone) → integrate (eq. 39–40) → deadband (eq. 41).
  // Only usable parameter sets drive it: a side never usable yet predicts no motion
  // (its linear state follows the other side's model if that one is usable).
  const Side ss = detail::free_run_side(x_, sc_, sim_last_);
  sim_last_ = ss;
  const Side other = ss == Side::right ? Side::left : Side::right;
  const Side ms = valid_[ss] ? ss : other;
  x_ = valid_[ms] ? -sa1_[ms] * x_ + sb1_[ms] * vraw1_ : 0.0;
  wdot_ = valid_[ss] ? detail::deadzone(x_, sc_.left, sc_.right) : 0.0;
  w_ += cfg_.dt_s * wdot_;
  vraw1_ = v;
  // stage 2 (from stage2_start, once both sides are usable so that ŵ means something):
  // engaged, y − ŵ = o − d moving +, o + d moving − (y = w ∓ d). ŵ is an open-loop integral of
  // the velocity model, so o drifts; d is therefore taken per crossing of the slot, where the
  // drift cancels: when the free cart starts moving the other way, the change of y − ŵ since its
  // last moving sample is ±2d. d is the mean over crossings; o the least-squares offset given d.
  if (!warming && k_ >= stage2_k_ && valid_.right && valid_.left && dir != 0) {
    const double r = s.y - w_;
    if (r_ok_ && dir != dir_last_) {
      dsum_ += 0.5 * (r - r_last_) * static_cast<double>(dir_last_);
      ++dcount_[dir > 0 ? 0 : 1];
    }
    osum_ += r;
    odir_ += static_cast<double>(dir);
    ++on_;
    r_last_ = r;
    r_ok_ = true;
  }
  if (dir != 0) dir_last_ = dir;
  const double dd = std::isfinite(deadband()) && deadband() > 0.0 ? deadband() : 0.0;
  const double o = on_ > 0 ? (osum_ + dd * odir_) / static_cast<double>(on_) : 0.0;
  const double wp = w_ + o;
  if (wp < ydb_ - dd) ydb_ = wp + dd;
  else if (wp > ydb_ + dd) ydb_ = wp - dd;
  ysim_ = ydb_;
  y1_ = s.y;
  v1_ = s.v;
  vel1_ = vel;
  dir2_ = dir1_;
  dir1_ = dir;
  ++k_;
  fit_.add(y, ysim_);
  return yhat_;
}

}  // namespace lash
