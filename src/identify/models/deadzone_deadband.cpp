#include "lash/identify/models/deadzone_deadband.hpp"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "lash/identify/auto.hpp"

namespace lash {

void DeadzoneDeadbandModel::defaults(EstimatorConfig& c) {
  // E2's method (docs/identification.md "E2: what got how far"): consistent MA40 on v and y,
  // switching on a filtered derivative with a dead band, direction held over the filter window
  // (direction_run 41, pooled: the struct's defaults), one pooled 4-parameter regression per
  // side solved by recursive IV, every sample kept.
  c.method = EstimationMethod::iv;
  c.iv_delay = 45;
  c.rls.lambda = 1.0;
  c.noise.filter_length = 40;
  c.noise.filter_input = true;
  c.noise.derivative_filter_length = 20;
  c.noise.derivative_threshold = 150.0;
  c.noise.align_delay = 10;
}

void DeadzoneDeadbandModel::tune(EstimatorConfig& c, const DataTraits& d) {
  constexpr double kRateShare = 0.10;  // dead band on ẏ as a share of the output's typical rate (docs)
  // Dead band on ẏ: 3σ of the derivative filter's noise output (||h||₂ of
  // MA20 ∘ difference/T ∘ MA40 on white noise of the record's σ), and at least one
  // encoder step per derivative window.
  const double m = static_cast<double>(c.noise.filter_length);
  const double m2 = static_cast<double>(c.noise.derivative_filter_length);
  // h = MA_m2 * (δ − δ₁)/T * MA_m: its taps are (box_m − box_m shifted by 1)/(m·m2·T) summed
  // m2 times; the difference of two boxes shifted by 1..m2 has 2·min(j, m) nonzero taps.
  double h2 = 0.0;
  {
    // exact ||h||² from the taps, computed on a small buffer
    const auto L = static_cast<std::size_t>(m + m2 + 1);
    std::vector<double> box(L, 0.0), h(L, 0.0);
    for (std::size_t i = 0; i < static_cast<std::size_t>(m); ++i) box[i] = 1.0 / m;
    for (std::size_t j = 0; j < static_cast<std::size_t>(m2); ++j)
      for (std::size_t i = 0; i + 1 < L; ++i) {
        if (i + j < L) h[i + j] += box[i] / (m2 * c.dt_s);
        if (i + j + 1 < L) h[i + j + 1] -= box[i] / (m2 * c.dt_s);
      }
    for (double x : h) h2 += x * x;
  }
  const double noise = 3.0 * d.noise_sigma * std::sqrt(h2);
  const double quant = d.quantum > 0.0 ? d.quantum / (m2 * c.dt_s) : 0.0;
  c.noise.derivative_threshold = std::max({noise, quant, kRateShare * d.ydot_p90});
  // a whole record: the switching estimate is refined by output error (docs/method.md §A4.4c)
  c.output_error = true;
}

DeadzoneDeadbandModel::DeadzoneDeadbandModel(const EstimatorConfig& cfg)
    : rls_{Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3()), Rls<3>(cfg.rls3())},
      pooled_{Rls<4>(cfg.rls4()), Rls<4>(cfg.rls4())},
      pooled_mode_(cfg.pooled) {
  sc_ = {cfg.guess_right, cfg.guess_left};
  if (!cfg.model_switching) return;
  // an estimator that could never update must not pass for one that has not updated yet
  if (!cfg.switch_model.right.usable() || !cfg.switch_model.left.usable())
    throw std::invalid_argument(
        "model-switching: needs a switching model for both sides (a1, b1, c, d); lash estimate iterates it over a "
        "whole record (docs/method.md §A4.4b), an online estimator has none");
  for (const Side sd : {Side::right, Side::left}) {  // the free run starts from the switching model
    const auto& m = cfg.switch_model[sd];
    sc_[sd] = m.c;
    sim_[sd] = {m.a1, m.b1, m.d};
  }
}

// predict_free() and free_run() run on every sample: defined before update() and inlined into
// the step (a call each cost about a tenth of the sample).
[[gnu::always_inline]] inline double DeadzoneDeadbandModel::predict_free(const EstimatorCore& c, Side side, double y1,
                                                                         double v1) const noexcept {
  // Deadband logic in the y domain: moving up if the + model lands above y(k−1), down if the
  // − model lands below it, otherwise the output holds.
  double up, down;
  if (c.cfg.pooled) {
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

[[gnu::always_inline]] inline void DeadzoneDeadbandModel::free_run(EstimatorCore& c) noexcept {
  c.ysim = detail::dzdb_free_run(c.vraw1, sc_, sim_, c.cfg.sim_side_by_sign, sim_last_, w_, c.ysim);
}

[[gnu::always_inline]] inline double DeadzoneDeadbandModel::update(EstimatorCore& c, const Conditioned& s,
                                                                   bool warming) noexcept {
  if (c.cfg.model_switching) [[unlikely]]
    return update_switched(c, s, warming);
  const int dir = direction(s.ydot, c.cfg.noise.derivative_threshold);
  const double y1 = c.y1, v1 = c.v1;
  const std::optional<Side> side = detail::guess_side(v1, c.cfg);
  // the direction hold: samples in a row with the same moving direction on the same side
  // (regime 0 = not moving: never counts; one compare instead of two and an optional's)
  const int regime = dir == 0 ? 0 : dir * (side ? 1 + static_cast<int>(*side) : 3);
  run_ = (regime != 0 && regime == regime1_) ? run_ + 1 : 1;
  regime1_ = regime;
  if (warming) [[unlikely]]  // after a gap (restart()): the direction hold starts again once the history is refilled
    run_ = 0;
  if (!(side && dir != 0 && run_ >= c.cfg.direction_run)) return predict_free(c, side ? *side : last_, y1, v1);
  const Side sd = *side;
  const Key k = key(sd, dir > 0);
  double yhat;
  if (c.cfg.pooled) {
    yhat = c.regress(pooled_[sd], std::array<double, 4>{-y1, v1, 1.0, dir > 0 ? -1.0 : 1.0}, s.y);
    ++count_[k];
  } else {
    yhat = c.regress(rls_[k], std::array<double, 3>{-y1, v1, 1.0}, s.y);
    count_[k] = rls_[k].updates();
  }
  c.seen(sd, v1, y1);
  // Derived (a1, b1, c, d) are refreshed on every update until the side is usable, then
  // every 8th update (the free run lags at most 7 updates; params() is always current).
  if (!usable_[sd] || (++since_[sd] & 7u) == 0) [[unlikely]] refresh(c, sd);
  last_ = sd;
  return yhat;
}

double DeadzoneDeadbandModel::update_switched(EstimatorCore& c, const Conditioned& s, bool warming) noexcept {
  // docs/method.md §A4.4b: the switching model (a1, b1, c, d per side, fixed through the run,
  // usable on both sides: the constructor checked) is driven by v alone. Its deadband says when
  // the output is pushed up or down; its edges say which side's regression a sample belongs to,
  // beyond the edge (φ = [−y(k−1), v(k−1), 1, ∓1]) or inside the deadzone on that side of zero
  // (u = 0: φ = [−y(k−1), 0, 0, ∓1]); its output ŷ(k−1) is the instrument for y(k−1).
  const PerSide<EstimatorConfig::SwitchSide>& m = c.cfg.switch_model;
  const double v1 = c.v1, y1 = c.y1;
  if (!sw_.started) {  // the first sample (or the first after a gap): the model starts at rest at y
    sw_ = {};
    sw_.w = sw_.y = s.y;
    sw_.started = true;
    return predict_free(c, last_, y1, v1);
  }
  const double z0 = -sw_.y;  // the model's y(k−1)
  const Side zs = v1 > m.right.c ? Side::right : (v1 < m.left.c ? Side::left : sw_.last);
  sw_.last = zs;
  sw_.w = -m[zs].a1 * sw_.w + m[zs].b1 * detail::deadzone(v1, m.left.c, m.right.c);
  const bool positive = v1 >= 0.0;
  const double d = m[positive ? Side::right : Side::left].d;
  int engaged = 0;
  if (sw_.w < sw_.y - d) {
    sw_.y = sw_.w + d;
    engaged = -1;
  } else if (sw_.w > sw_.y + d) {
    sw_.y = sw_.w - d;
    engaged = 1;
  }
  sw_.run = (engaged != 0 && engaged == sw_.engaged && positive == sw_.positive) ? sw_.run + 1 : 0;
  sw_.engaged = engaged;
  sw_.positive = positive;
  // the region of v(k−1): beyond an edge or inside the deadzone, on the side of its sign (the
  // side whose d acts), clear of the edge by the margin
  const Side sd = positive ? Side::right : Side::left;
  const double edge = m[sd].c, sg = positive ? 1.0 : -1.0;
  const double clear = c.cfg.switch_margin * std::fabs(edge);
  const bool beyond = sg * (v1 - edge) > clear;
  const bool inside = sg * (edge - v1) > clear;
  if (warming || sw_.run < c.cfg.switch_hold || !(beyond || inside)) return predict_free(c, last_, y1, v1);
  const double b = beyond ? 1.0 : 0.0;
  const std::array<double, 4> phi{-y1, b * v1, b, engaged > 0 ? -1.0 : 1.0};
  std::array<double, 4> z = phi;
  z[0] = z0;
  const double yhat = pooled_[sd].update_iv(phi, z, s.y);
  ++count_[key(sd, engaged > 0)];
  if (beyond) {
    ++beyond_[sd];
    c.seen(sd, v1, y1);
  }
  if (!usable_[sd] || (++since_[sd] & 7u) == 0) [[unlikely]] refresh(c, sd);
  last_ = sd;
  return yhat;
}

std::uint64_t DeadzoneDeadbandModel::rls_skipped() const noexcept {
  std::uint64_t n = 0;
  for (const auto& r : rls_) n += r.skipped();
  return n + pooled_.right.skipped() + pooled_.left.skipped();
}

DeadzoneDeadbandModel::Derived DeadzoneDeadbandModel::derive(const EstimatorCore& core, Side side) const noexcept {
  const EstimatorConfig& cfg = core.cfg;
  const std::uint64_t np = count_[key(side, true)], nm = count_[key(side, false)];
  Derived q;
  q.updated = np >= cfg.min_updates && nm >= cfg.min_updates &&
              (!cfg.model_switching || beyond_[side] >= cfg.min_updates);  // b1 and c need samples beyond the edge
  if (cfg.pooled) {
    // η = [a1, b1, e0, g] with e± = e0 ∓ g, e0 = −b1·c, g = d(1 + a1)
    const EstimatorConfig::SwitchSide r = pooled_params(side);
    q.a1 = r.a1;
    q.b1 = r.b1;
    q.solvable = std::fabs(1.0 + q.a1) > cfg.singular_tol && std::fabs(q.b1) > 1e-12;
    q.c = r.c;
    q.d = r.d;
  } else {
    const auto& ep = rls_[key(side, true)].eta();
    const auto& em = rls_[key(side, false)].eta();
    // eq. 31/32: [−(1+a+)  −b+; (1+a−)  −b−] [d; c] = [e+; e−]
    const double t1 = (1.0 + ep[0]) * em[1], t2 = ep[1] * (1.0 + em[0]);
    const double det = t1 + t2;
    q.solvable = std::fabs(det) > cfg.singular_tol * (std::fabs(t1) + std::fabs(t2));
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
    q.a1 = (fp * ep[0] + fm * em[0]) * inv_n;
    q.b1 = (fp * ep[1] + fm * em[1]) * inv_n;
    q.d = (-em[1] * ep[2] + ep[1] * em[2]) * inv;
    q.c = (-(1.0 + em[0]) * ep[2] - (1.0 + ep[0]) * em[2]) * inv;
  }
  const bool finite = std::isfinite(q.c) && std::isfinite(q.d) && std::isfinite(q.a1) && std::isfinite(q.b1);
  q.guess_ok = q.c > cfg.guess_left && q.c < cfg.guess_right;
  // usable for the free run (and the refresh cadence): the method's own premise (eq. 18): the
  // guesses lie outside the deadzone, c_l* < c < c_r*, and a deadband half-width is not
  // negative. An estimate outside that is a transient of a key that has not converged yet.
  q.usable = q.updated && q.solvable && finite && q.guess_ok && q.d >= 0.0;
  return q;
}

verdict_rules::Evidence DeadzoneDeadbandModel::evidence(const EstimatorCore& c, Side s) const noexcept {
  const Derived q = derive(c, s);  // always current, even between refreshes of the free-run model
  verdict_rules::Evidence ev;
  ev.side = s;
  ev.updated = q.updated;
  ev.excited = q.solvable && c.excited(s);
  ev.a1 = q.a1;
  ev.b1 = q.b1;
  ev.has_c = ev.has_d = true;
  ev.c = q.c;
  ev.d = q.d;
  ev.guess_ok = q.guess_ok;
  return ev;
}

void DeadzoneDeadbandModel::refresh(const EstimatorCore& c, Side side) noexcept {
  const Derived q = derive(c, side);
  // settled: (c, d) stopped moving between refreshes (see EstimatorConfig::settle_tol)
  const bool still = std::fabs(q.c - prev_c_[side]) + std::fabs(q.d - prev_d_[side]) <=
                     c.cfg.settle_tol * (std::fabs(q.c) + std::fabs(q.d));
  settled_[side] = still ? settled_[side] + 1 : 0;
  prev_c_[side] = q.c;
  prev_d_[side] = q.d;
  const bool ok = q.usable && settled_[side] >= c.cfg.settle_updates;
  usable_[side] = ok;
  // model switching: the free run keeps the switching model until the side's own estimate is usable
  if (!c.cfg.model_switching || ok) {
    sim_[side].a1 = q.a1;
    sim_[side].b1 = q.b1;
  }
  if (ok) {
    sc_[side] = q.c;
    sim_[side].d = q.d > 0.0 ? q.d : 0.0;
  }
}

void DeadzoneDeadbandModel::restart_side(EstimatorCore& c, Side s) noexcept {
  for (bool plus : {true, false}) {
    rls_[key(s, plus)].reset();
    count_[key(s, plus)] = 0;
  }
  pooled_[s].reset();
  beyond_[s] = 0;
  usable_[s] = false;
  sim_[s] = {};  // no output from that side until its new estimate is usable
  sc_[s] = c.cfg.guess(s);
  prev_c_[s] = prev_d_[s] = 0.0;
  settled_[s] = since_[s] = 0;
}

template class SwitchingEstimator<DeadzoneDeadbandModel>;

}  // namespace lash
