#include "lash/identify/estimators.hpp"

#include <algorithm>
#include <cmath>

namespace lash {

using detail::kNaN;

namespace {
const EstimatorConfig& checked(const EstimatorConfig& c) {
  c.validate();
  return c;
}
bool finite_all(double a, double b) noexcept { return std::isfinite(a) && std::isfinite(b); }

/// Whether side i's estimate (a1, b1, e) with deadzone edge c may drive the free-run simulation:
/// finite and stable (|a1| < 1: a1 ≤ −1 integrates or diverges, and such a transient made E3/E4
/// free runs overflow). The free run holds the last such set of each side.
bool simulable(const std::array<double, 3>& e, double c) noexcept {
  return std::isfinite(e[0]) && std::isfinite(e[1]) && std::isfinite(e[2]) && std::fabs(e[0]) < 1.0 &&
         std::isfinite(c);
}
/// Whether side i's deadzone edge is on its own side of zero (c_r ≥ 0 ≥ c_l: a deadzone from
/// friction or spool overlap contains zero, thesis §1.6.1). A simulable set that fails this still
/// reproduces the output it was fitted on (e.g. a square wave: only b1·v + e is determined) but is
/// not presented as identified — the thesis's "negative deadzones hidden by underestimated gains".
bool physical_edge(double c, int i) noexcept { return i == 0 ? c >= 0.0 : c <= 0.0; }
}  // namespace

// ---------------------------------------------------------------- linear (eq. 9–16)

LinearEstimator::LinearEstimator(const EstimatorConfig& cfg)
    : cfg_(checked(cfg)), pre_(cfg.noise, cfg.dt_s), rls_(cfg.rls2()) {}

double LinearEstimator::step(double v, double y) noexcept {
  if (!finite_all(v, y)) {
    ++skipped_;
    return yhat_ = kNaN;
  }
  const Conditioned s = pre_.step(v, y);
  const std::array<double, 2> phi{-y1_, v1_};
  if (cfg_.method == EstimationMethod::iv)
    yhat_ = rls_.update_iv(phi, {-hist_.ago(1 + cfg_.iv_delay), v1_}, s.y);
  else
    yhat_ = rls_.update(phi, s.y);
  hist_.push(s.y);
  y1_ = s.y;
  v1_ = s.v;
  x_ = -rls_.eta(0) * x_ + rls_.eta(1) * vraw1_;
  ysim_ = x_;
  vraw1_ = v;
  return yhat_;
}

SideParams LinearEstimator::params() const noexcept {
  SideParams p;
  p.identified = identified();
  if (p.identified) {
    p.a1 = rls_.eta(0);
    p.b1 = rls_.eta(1);
  }
  return p;
}

// ---------------------------------------------------------------- two-side deadzone estimators

namespace detail {

TwoSideEstimator::TwoSideEstimator(const EstimatorConfig& cfg)
    : cfg_(checked(cfg)), pre_(cfg.noise, cfg.dt_s), rls_{Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3())} {}

void TwoSideEstimator::refresh(int i, double c, bool plausible) noexcept {
  const auto& e = rls_[i].eta();
  SideParams& p = p_[i];
  const bool sim = rls_[i].updates() >= cfg_.min_updates && simulable(e, c);
  if (sim) {  // the free run holds the last stable set of each side (none yet: no output)
    sa1_[i] = e[0];
    sb1_[i] = e[1];
    sc_[i] = c;
  }
  p.identified = sim && physical_edge(c, i) && plausible;
  if (p.identified) {
    p.a1 = e[0];
    p.b1 = e[1];
    p.c = c;
  } else {
    p = SideParams{};
  }
}

double TwoSideEstimator::update(int i, double y) noexcept {
  const std::array<double, 3> phi{-y1_, v1_, 1.0};
  if (cfg_.method == EstimationMethod::iv) return rls_[i].update_iv(phi, {-hist_.ago(1 + cfg_.iv_delay), v1_, 1.0}, y);
  return rls_[i].update(phi, y);
}

}  // namespace detail

// ---------------------------------------------------------------- input deadzone (§1.4.2)

InputDeadzoneEstimator::InputDeadzoneEstimator(const EstimatorConfig& cfg) : TwoSideEstimator(cfg) {
  sc_ = {cfg.guess_right, cfg.guess_left};
}

void InputDeadzoneEstimator::refresh(int i) noexcept {
  const auto& e = rls_[i].eta();
  const double c = std::fabs(e[1]) > 1e-12 ? -e[2] / e[1] : kNaN;  // e = −b1·c (eq. 21–22)
  // plausibility (eq. 18): the guesses lie outside the deadzone, c_l* < c < c_r*
  TwoSideEstimator::refresh(i, c, c > cfg_.guess_left && c < cfg_.guess_right);
}

double InputDeadzoneEstimator::step(double v, double y) noexcept {
  if (!finite_all(v, y)) {
    ++skipped_;
    return yhat_ = kNaN;
  }
  const Conditioned s = pre_.step(v, y);
  const int side = v1_ > cfg_.guess_right ? 0 : (v1_ < cfg_.guess_left ? 1 : -1);
  if (side >= 0) {
    yhat_ = update(side, s.y);
    refresh(side);
    last_ = side;
  } else {
    yhat_ = -rls_[last_].eta(0) * y1_;  // inside the deadzone u = 0 (eq. 17), a1 of the side last used
  }
  hist_.push(s.y);
  y1_ = s.y;
  v1_ = s.v;
  // free-run simulation of eq. 17 driven by the raw v
  int ss;
  if (cfg_.sim_side_by_sign) ss = vraw1_ >= 0.0 ? 0 : 1;
  else ss = vraw1_ > sc_[0] ? 0 : (vraw1_ < sc_[1] ? 1 : sim_last_);
  sim_last_ = ss;
  w_ = -sa1_[ss] * w_ + sb1_[ss] * detail::deadzone(vraw1_, sc_[1], sc_[0]);
  ysim_ = w_;
  vraw1_ = v;
  return yhat_;
}

// ---------------------------------------------------------------- output deadzone (§1.6.1)

OutputDeadzoneEstimator::OutputDeadzoneEstimator(const EstimatorConfig& cfg) : TwoSideEstimator(cfg) {}

void OutputDeadzoneEstimator::refresh(int i) noexcept {
  const auto& e = rls_[i].eta();
  const double den = 1.0 + e[0];
  const double c = std::fabs(den) > 1e-9 ? -e[2] / den : kNaN;  // e = −c(1 + a1) (eq. 36)
  TwoSideEstimator::refresh(i, c, true);
}

double OutputDeadzoneEstimator::step(double v, double y) noexcept {
  if (!finite_all(v, y)) {
    ++skipped_;
    return yhat_ = kNaN;
  }
  const Conditioned s = pre_.step(v, y);
  const double y1 = y1_, v1 = v1_, z = cfg_.zero_threshold;
  const int side = (s.y > z && y1 > z) ? 0 : ((s.y < -z && y1 < -z) ? 1 : -1);
  // free-run simulation: x = G(v), y_sim = DZ(x); the side follows x against the deadzone
  {
    const int ss = x_ > sc_[0] ? 0 : (x_ < sc_[1] ? 1 : sim_last_);
    sim_last_ = ss;
    x_ = -sa1_[ss] * x_ + sb1_[ss] * vraw1_;
    ysim_ = detail::deadzone(x_, sc_[1], sc_[0]);
    vraw1_ = v;
  }
  if (side >= 0) {
    yhat_ = update(side, s.y);
    refresh(side);
  } else {
    const int ps = y1 > z ? 0 : (y1 < -z ? 1 : -1);
    yhat_ = ps >= 0 ? rls_[ps].predict({-y1, v1, 1.0}) : 0.0;
    if (ps == 0 && yhat_ < 0.0) yhat_ = 0.0;
    if (ps == 1 && yhat_ > 0.0) yhat_ = 0.0;
  }
  hist_.push(s.y);
  y1_ = s.y;
  v1_ = s.v;
  return yhat_;
}

// ---------------------------------------------------------------- deadzone + deadband (§1.4.3)

DeadzoneDeadbandEstimator::DeadzoneDeadbandEstimator(const EstimatorConfig& cfg)
    : cfg_(checked(cfg)),
      pre_(cfg.noise, cfg.dt_s),
      rls_{Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3())},
      pooled_{Rls<4>(cfg.rls4()), Rls<4>(cfg.rls4())} {
  sc_ = {cfg.guess_right, cfg.guess_left};
}

std::uint64_t DeadzoneDeadbandEstimator::skipped() const noexcept {
  std::uint64_t n = skipped_;
  for (const auto& r : rls_) n += r.skipped();
  for (const auto& r : pooled_) n += r.skipped();
  return n;
}

SideParams DeadzoneDeadbandEstimator::derive(int side) const noexcept {
  SideParams p;
  const std::uint64_t np = count_[side * 2], nm = count_[side * 2 + 1];
  double a1, b1, c, d;
  bool ok = np >= cfg_.min_updates && nm >= cfg_.min_updates;
  if (cfg_.pooled) {
    // η = [a1, b1, e0, g] with e± = e0 ∓ g, e0 = −b1·c, g = d(1 + a1)
    const auto& e = pooled_[side].eta();
    a1 = e[0];
    b1 = e[1];
    const double den = 1.0 + a1;
    ok = ok && std::fabs(den) > cfg_.singular_tol && std::fabs(b1) > 1e-12;
    c = -e[2] / b1;
    d = e[3] / den;
  } else {
    const auto& ep = rls_[side * 2].eta();
    const auto& em = rls_[side * 2 + 1].eta();
    // eq. 31/32: [−(1+a+)  −b+; (1+a−)  −b−] [d; c] = [e+; e−]
    const double t1 = (1.0 + ep[0]) * em[1], t2 = ep[1] * (1.0 + em[0]);
    const double det = t1 + t2;
    ok = ok && std::fabs(det) > cfg_.singular_tol * (std::fabs(t1) + std::fabs(t2));
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
  ok = ok && std::isfinite(c) && std::isfinite(d) && std::isfinite(a1) && std::isfinite(b1);
  // plausibility from the method's own premise (eq. 18): the guesses lie outside the deadzone,
  // c_l* < c < c_r*, and a deadband half-width is not negative. An estimate outside that is a
  // transient of a key that has not converged yet, reported as "not identified".
  ok = ok && c > cfg_.guess_left && c < cfg_.guess_right && d >= 0.0;
  p.a1 = a1;  // raw values; `identified` tells whether they count
  p.b1 = b1;
  p.c = c;
  p.d = d;
  p.identified = ok;
  return p;
}

void DeadzoneDeadbandEstimator::refresh(int side) noexcept {
  const SideParams q = derive(side);
  // settled: (c, d) stopped moving between refreshes (see EstimatorConfig::settle_tol)
  const bool still = std::fabs(q.c - prev_c_[side]) + std::fabs(q.d - prev_d_[side]) <=
                     cfg_.settle_tol * (std::fabs(q.c) + std::fabs(q.d));
  settled_[side] = still ? settled_[side] + 1 : 0;
  prev_c_[side] = q.c;
  prev_d_[side] = q.d;
  const bool ok = q.identified && settled_[side] >= cfg_.settle_updates;
  p_[side].identified = ok;
  sa1_[side] = q.a1;
  sb1_[side] = q.b1;
  if (ok) {
    sc_[side] = q.c;
    sd_[side] = q.d > 0.0 ? q.d : 0.0;
  }
}

SideParams DeadzoneDeadbandEstimator::params(Side s) const noexcept {
  const int i = detail::side_index(s);
  SideParams q = derive(i);  // always current, even between refreshes of the free-run model
  if (!(q.identified && settled_[i] >= cfg_.settle_updates)) return SideParams{};
  return q;
}

double DeadzoneDeadbandEstimator::predict_free(int side, double y1, double v1) const noexcept {
  // Deadband logic in the y domain: moving up if the + model lands above y(k−1), down if the
  // − model lands below it, otherwise the output holds.
  double up, down;
  if (cfg_.pooled) {
    up = pooled_[side].predict({-y1, v1, 1.0, -1.0});
    down = pooled_[side].predict({-y1, v1, 1.0, 1.0});
  } else {
    up = rls_[side * 2].predict({-y1, v1, 1.0});
    down = rls_[side * 2 + 1].predict({-y1, v1, 1.0});
  }
  if (up > y1) return up;
  if (down < y1) return down;
  return y1;
}

// ---------------------------------------------------------------- coupled carts (§1.6.3)

CoupledCartsEstimator::CoupledCartsEstimator(const EstimatorConfig& cfg)
    : cfg_(checked(cfg)), pre_(cfg.noise, cfg.dt_s), rls_{Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3())} {
  stage2_k_ = static_cast<std::uint64_t>(std::ceil(cfg.stage2_start_s / cfg.dt_s - 1e-9));
}

std::uint64_t CoupledCartsEstimator::skipped() const noexcept {
  return skipped_ + rls_[0].skipped() + rls_[1].skipped();
}

void CoupledCartsEstimator::refresh(int i) noexcept {
  const auto& e = rls_[i].eta();
  SideParams& p = p_[i];
  // A side is identified only when its model is usable for the free run and physically sensible:
  // enough updates, finite, a stable first-order lag with a positive time constant (−1 < a1 < 0,
  // τ = −T/ln(−a1); a1 ≤ −1 integrates or diverges and made the E5 square-wave free runs
  // overflow), the deadzone edge on its own side of zero (c_r ≥ 0 ≥ c_l, thesis §1.6.1) and the
  // input not constant over the side's updates (a constant v makes b1 and e inseparable: only
  // b1·v + e is determined — the square wave).
  const bool stable =
      std::isfinite(e[0]) && std::isfinite(e[1]) && std::isfinite(e[2]) && e[0] > -1.0 && e[0] < 0.0;
  const double c = stable ? -e[2] / (1.0 + e[0]) : kNaN;  // eq. 38: e = −c(1 + a1)
  const bool exciting = vrange_[i].several();
  p.identified = rls_[i].updates() >= cfg_.min_updates && stable && std::isfinite(c) &&
                 (i == 0 ? c >= 0.0 : c <= 0.0) && exciting;
  if (p.identified) {
    p.a1 = e[0];
    p.b1 = e[1];
    p.c = c;
    // the free run uses the last identified set of each side (never an unstable transient)
    sa1_[i] = e[0];
    sb1_[i] = e[1];
    sc_[i] = c;
    valid_[i] = true;
  } else {
    p = SideParams{};
  }
}

SideParams CoupledCartsEstimator::params(Side s) const noexcept {
  SideParams p = p_[detail::side_index(s)];
  p.d = deadband();
  return p;
}

double CoupledCartsEstimator::deadband() const noexcept {
  return dcount_[0] + dcount_[1] > 0 ? dsum_ / static_cast<double>(dcount_[0] + dcount_[1]) : kNaN;
}

bool CoupledCartsEstimator::identified() const noexcept {
  return p_[0].identified && p_[1].identified && std::isfinite(deadband());
}

double CoupledCartsEstimator::step(double v, double y) noexcept {
  if (!finite_all(v, y)) {
    ++skipped_;
    return yhat_ = kNaN;
  }
  const Conditioned s = pre_.step(v, y);
  const double vel = s.ydot;  // free-cart velocity
  const int dir = direction(vel, cfg_.noise.derivative_threshold);
  const double vel1 = vel1_, v1 = v1_;
  const bool steady = std::fabs(vel - vel1) * (1.0 / cfg_.dt_s) <= cfg_.accel_limit;
  double vel_pred = 0.0;
  if (dir != 0 && dir == dir1_ && dir == dir2_ && steady) {
    const int i = dir > 0 ? 0 : 1;
    vel_pred = rls_[i].update({-vel1, v1, 1.0}, vel);
    vrange_[i].add(v1);
    refresh(i);
  } else if (dir1_ != 0) {
    vel_pred = rls_[dir1_ > 0 ? 0 : 1].predict({-vel1, v1, 1.0});
  }
  yhat_ = y1_ + cfg_.dt_s * vel_pred;
  // free-run: velocity model (output deadzone) → integrate (eq. 39–40) → deadband (eq. 41).
  // Only identified parameter sets drive it: a side never identified yet predicts no motion
  // (its linear state follows the other side's model if that one is identified).
  const int ss = x_ > sc_[0] ? 0 : (x_ < sc_[1] ? 1 : sim_last_);
  sim_last_ = ss;
  const int ms = valid_[ss] ? ss : 1 - ss;
  x_ = valid_[ms] ? -sa1_[ms] * x_ + sb1_[ms] * vraw1_ : 0.0;
  wdot_ = valid_[ss] ? detail::deadzone(x_, sc_[1], sc_[0]) : 0.0;
  w_ += cfg_.dt_s * wdot_;
  vraw1_ = v;
  // stage 2 (from stage2_start, once both sides are identified so that ŵ means something):
  // engaged, y − ŵ = o − d moving +, o + d moving − (y = w ∓ d). ŵ is an open-loop integral of
  // the velocity model, so o drifts; d is therefore taken per crossing of the slot, where the
  // drift cancels: when the free cart starts moving the other way, the change of y − ŵ since its
  // last moving sample is ±2d. d is the mean over crossings; o the least-squares offset given d.
  if (k_ >= stage2_k_ && valid_[0] && valid_[1] && dir != 0) {
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
  return yhat_;
}

}  // namespace lash
