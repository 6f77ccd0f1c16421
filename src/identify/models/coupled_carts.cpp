#include "lash/identify/models/coupled_carts.hpp"

#include "lash/identify/auto.hpp"

namespace lash {

void CoupledCartsModel::defaults(EstimatorConfig& c) { c.rls.lambda = 0.995; }  // E5 (lash settings)

void CoupledCartsModel::tune(EstimatorConfig& c, const DataTraits& d) {
  // a quantised position (linear scale) gives a quantised velocity: average it over 1000 samples
  if (d.quantum > 0.0) c.rls.lambda = 0.999;
  // stage 1 leaves out the pin's impacts: accelerations well above the record's usual ones
  if (d.yddot_p90 > 0.0) c.accel_limit = 3.0 * d.yddot_p90;
}

Reason CoupledCartsModel::deadband_reason() const noexcept {
  const double d = deadband();
  if (!std::isfinite(d)) return Reason::not_updated;
  return d >= 0.0 ? Reason::none : Reason::unphysical;
}

void CoupledCartsModel::refresh(const EstimatorCore& c, Side s) noexcept {
  const auto& e = rls_[s].eta();
  // The free run uses a side's set only when it is usable: enough updates, finite, a stable
  // first-order lag with a positive time constant (−1 < a1 < 0, τ = −T/ln(−a1); a1 ≤ −1
  // integrates or diverges and made the E5 square-wave free runs overflow), the deadzone edge on
  // its own side of zero (c_r ≥ 0 ≥ c_l, thesis §1.6.1) and the input not constant over the
  // side's updates (a constant v makes b1 and e inseparable: only b1·v + e is determined).
  const bool stable =
      std::isfinite(e[0]) && std::isfinite(e[1]) && std::isfinite(e[2]) && e[0] > -1.0 && e[0] < 0.0;
  const double edge = stable ? -e[2] / (1.0 + e[0]) : detail::kNaN;  // eq. 38: e = −c(1 + a1)
  const bool enough = rls_[s].updates() >= c.cfg.min_updates;
  if (enough && stable && std::isfinite(edge) && verdict_rules::physical_edge(edge, s) && c.vrange[s].several()) {
    hold(s, edge);  // the free run uses the last usable set of each side (never an unstable transient)
    valid_[s] = true;
  }
}

double CoupledCartsModel::update(EstimatorCore& c, const Conditioned& s, bool warming) noexcept {
  const double vel = s.ydot;  // free-cart velocity
  const int dir = direction(vel, c.cfg.noise.derivative_threshold);
  const double vel1 = vel1_, v1 = c.v1;
  const bool steady = std::fabs(vel - vel1) * (1.0 / c.cfg.dt_s) <= c.cfg.accel_limit;
  double vel_pred = 0.0;
  if (!warming && dir != 0 && dir == dir1_ && dir == dir2_ && steady) {
    const Side i = dir > 0 ? Side::right : Side::left;
    vel_pred = rls_[i].update({-vel1, v1, 1.0}, vel);  // stage 1 is plain RLS (no IV)
    c.seen(i, v1, vel1);
    refresh(c, i);
  } else if (dir1_ != 0) {
    vel_pred = rls_[dir1_ > 0 ? Side::right : Side::left].predict({-vel1, v1, 1.0});
  }
  vel1_ = vel;
  dir2_ = dir1_;
  dir1_ = dir;
  dir_ = dir;
  y_ = s.y;
  warming_ = warming;
  return c.y1 + c.cfg.dt_s * vel_pred;
}

void CoupledCartsModel::free_run(EstimatorCore& c) noexcept {
  // velocity model (output deadzone) → integrate (eq. 39–40) → deadband (eq. 41).
  // Only usable parameter sets drive it: a side never usable yet predicts no motion
  // (its linear state follows the other side's model if that one is usable).
  const Side ss = detail::free_run_side(x_, sc_, sim_last_);
  sim_last_ = ss;
  const Side other = opposite(ss);
  const Side ms = valid_[ss] ? ss : other;
  x_ = valid_[ms] ? -sa1_[ms] * x_ + sb1_[ms] * c.vraw1 : 0.0;
  wdot_ = valid_[ss] ? detail::deadzone(x_, sc_.left, sc_.right) : 0.0;
  w_ += c.cfg.dt_s * wdot_;
  // stage 2 (from stage2_start, once both sides are usable so that ŵ means something):
  // engaged, y − ŵ = o − d moving +, o + d moving − (y = w ∓ d). ŵ is an open-loop integral of
  // the velocity model, so o drifts; d is therefore taken per crossing of the slot, where the
  // drift cancels: when the free cart starts moving the other way, the change of y − ŵ since its
  // last moving sample is ±2d. d is the mean over crossings; o the least-squares offset given d.
  const int dir = dir_;
  if (!warming_ && k_ >= stage2_k_ && valid_.right && valid_.left && dir != 0) {
    const double r = y_ - w_;
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
  c.ysim = ydb_;
  ++k_;
}

template class SwitchingEstimator<CoupledCartsModel>;

}  // namespace lash
