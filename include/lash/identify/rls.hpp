#pragma once
/// @file rls.hpp
/// Recursive least squares with forgetting (thesis eq. 13–16, Åström & Wittenmark),
/// fixed size N, allocation-free and noexcept on the sample path.
///
/// Safety measures (docs/identification.md):
///  - P is kept exactly symmetric (upper triangle computed, mirrored).
///  - P stays bounded when excitation vanishes: either *directional forgetting*
///    (Kulhavý 1987; Bittanti, Bolzern & Campi 1990; form of Cao & Schwartz 2000),
///    which forgets only along the current regressor, or exponential forgetting with a
///    *trace bound* (the 1/λ inflation is skipped whenever it would take trace P above
///    `trace_max`; Åström & Wittenmark, Adaptive Control, 2nd ed., §11.2).
///  - an update with a non-finite φ or y is skipped and counted; the state is untouched.
///  - optional per-parameter bounds: the estimate is projected (clamped) onto the box
///    after each update (Goodwin & Sin 1984, §3.7).
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace lash {

enum class Forgetting : std::uint8_t {
  exponential,  ///< eq. 15–16 with λ, plus the trace bound
  directional   ///< Bittanti et al. (1990) directional forgetting with factor λ
};

template <std::size_t N>
struct RlsConfig {
  double lambda = 1.0;  ///< forgetting factor λ ∈ (0, 1]
  double p0 = 1000.0;   ///< P(0) = p0·I
  std::array<double, N> eta0{};  ///< η̂(0)
  Forgetting forgetting = Forgetting::exponential;
  /// Exponential forgetting: upper bound on trace P (the 1/λ inflation stops there).
  double trace_max = 1e12;
  std::array<double, N> lower = filled(-std::numeric_limits<double>::infinity());  ///< projection box
  std::array<double, N> upper = filled(std::numeric_limits<double>::infinity());

  static constexpr std::array<double, N> filled(double x) {
    std::array<double, N> a{};
    for (auto& v : a) v = x;
    return a;
  }
  /// Throws std::invalid_argument naming the offending setting.
  void validate() const {
    if (!(lambda > 0.0 && lambda <= 1.0)) throw std::invalid_argument("lambda must be in (0, 1]");
    if (!(std::isfinite(p0) && p0 > 0.0)) throw std::invalid_argument("p0 must be > 0 and finite");
    if (!(trace_max > 0.0)) throw std::invalid_argument("trace_max must be > 0");
    for (std::size_t i = 0; i < N; ++i) {
      if (!std::isfinite(eta0[i])) throw std::invalid_argument("eta0 must be finite");
      if (std::isnan(lower[i]) || std::isnan(upper[i]) || lower[i] > upper[i])
        throw std::invalid_argument("parameter bounds need lower <= upper (index " + std::to_string(i) + ")");
    }
  }
};

template <std::size_t N>
class Rls {
 public:
  using Vec = std::array<double, N>;
  using Mat = std::array<std::array<double, N>, N>;

  /// Not real-time safe only in that it may throw (invalid config).
  explicit Rls(const RlsConfig<N>& cfg = {}) : cfg_(cfg) {
    cfg_.validate();
    inv_lambda_ = 1.0 / cfg_.lambda;
    unit_lambda_ = cfg_.lambda == 1.0;
    for (std::size_t i = 0; i < N; ++i) bounded_ = bounded_ || std::isfinite(cfg_.lower[i]) || std::isfinite(cfg_.upper[i]);
    reset();
  }

  void reset() noexcept {
    eta_ = cfg_.eta0;
    project();
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < N; ++j) p_[i][j] = i == j ? cfg_.p0 : 0.0;
    updates_ = 0;
    skipped_ = 0;
  }

  /// ŷ = φᵀη̂ (eq. 14) with the current estimate.
  double predict(const Vec& phi) const noexcept {
    double s = 0.0;
    for (std::size_t i = 0; i < N; ++i) s += phi[i] * eta_[i];
    return s;
  }

  /// One RLS step (eq. 13–16). Returns the a-priori prediction ŷ = φᵀη̂(k−1);
  /// a non-finite φ or y leaves the state untouched, counts the skip and returns NaN.
  double update(const Vec& phi, double y) noexcept {
    if (!finite(phi, y)) {
      ++skipped_;
      return std::numeric_limits<double>::quiet_NaN();
    }
    const double yhat = predict(phi);
    Vec pphi{};  // P φ
    for (std::size_t i = 0; i < N; ++i) {
      double s = 0.0;
      for (std::size_t j = 0; j < N; ++j) s += p_[i][j] * phi[j];
      pphi[i] = s;
    }
    const double r = quad(phi);  // φᵀ P φ, summed as a tree (short dependency chain)
    const double err = y - yhat;
    if (cfg_.forgetting == Forgetting::exponential) {
      // eq. 16: q = Pφ / (λ + φᵀPφ); eq. 13: η += q e; eq. 15: P = (P − q φᵀ P)/λ.
      // Trace bound: the 1/λ inflation is skipped when trace(P(k−1))/λ would exceed trace_max;
      // since the subtracted term is positive semi-definite, trace P ≤ max(trace_max, trace P0).
      double tr = 0.0;
      for (std::size_t i = 0; i < N; ++i) tr += p_[i][i];
      const double scale = tr * inv_lambda_ > cfg_.trace_max ? 1.0 : inv_lambda_;
      const double inv = 1.0 / (cfg_.lambda + r);
      for (std::size_t i = 0; i < N; ++i) eta_[i] += pphi[i] * inv * err;
      if (unit_lambda_) {  // λ = 1: scale = 1 whatever the trace, and x·1 = x exactly
        for (std::size_t i = 0; i < N; ++i)
          for (std::size_t j = i; j < N; ++j) p_[i][j] = p_[i][j] - (pphi[i] * pphi[j]) * inv;
      } else {
        for (std::size_t i = 0; i < N; ++i)
          for (std::size_t j = i; j < N; ++j) p_[i][j] = p_[i][j] * scale - (pphi[i] * pphi[j] * scale) * inv;
      }
    } else {
      // Directional forgetting (Bittanti, Bolzern & Campi 1990; Cao & Schwartz 2000):
      // q = Pφ/(1 + r); P = P − Pφφᵀ P/(β⁻¹ + r), β = λ − (1 − λ)/r; P unchanged when r = 0.
      const double inv = 1.0 / (1.0 + r);
      for (std::size_t i = 0; i < N; ++i) eta_[i] += pphi[i] * inv * err;
      if (r > 0.0) {
        const double beta = cfg_.lambda - (1.0 - cfg_.lambda) / r;
        // 1/(β⁻¹ + r) = β/(1 + βr); 1 + βr = λ(1 + r) > 0 always.
        const double g = beta / (1.0 + beta * r);
        for (std::size_t i = 0; i < N; ++i)
          for (std::size_t j = i; j < N; ++j) p_[i][j] -= pphi[i] * pphi[j] * g;
      }
    }
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < i; ++j) p_[i][j] = p_[j][i];
    project();
    ++updates_;
    return yhat;
  }

  /// Recursive instrumental-variable step (Young 1970; Söderström & Stoica 1989, §8):
  /// q = Pz/(λ + φᵀPz), η += q(y − φᵀη), P = (P − qφᵀP)/λ. P is not symmetric in this
  /// mode (it estimates (Σ z φᵀ)⁻¹). Exponential forgetting and the trace bound apply.
  double update_iv(const Vec& phi, const Vec& z, double y) noexcept {
#if defined(__GNUC__)
    if constexpr (N == 4) return update_iv4(phi, z, y);
#endif
    if (!finite(phi, y) || !finite(z, 0.0)) {
      ++skipped_;
      return std::numeric_limits<double>::quiet_NaN();
    }
    const double yhat = predict(phi);
    Vec pz{}, phip{};  // P z and φᵀ P
    for (std::size_t i = 0; i < N; ++i) {
      double s = 0.0, t = 0.0;
      for (std::size_t j = 0; j < N; ++j) {
        s += p_[i][j] * z[j];
        t += phi[j] * p_[j][i];
      }
      pz[i] = s;
      phip[i] = t;
    }
    double r = 0.0;
    for (std::size_t i = 0; i < N; ++i) r += phi[i] * pz[i];
    const double den = cfg_.lambda + r;
    if (!(std::fabs(den) > 1e-300)) {
      ++skipped_;
      return yhat;
    }
    const double inv = 1.0 / den;
    const double err = y - yhat;
    for (std::size_t i = 0; i < N; ++i) eta_[i] += pz[i] * inv * err;
    if (unit_lambda_) {  // λ = 1: scale = 1 whatever the trace, and x·1 = x exactly
      for (std::size_t i = 0; i < N; ++i)
        for (std::size_t j = 0; j < N; ++j) p_[i][j] = p_[i][j] - pz[i] * phip[j] * inv;
    } else {
      double tr = 0.0;
      for (std::size_t i = 0; i < N; ++i) tr += p_[i][i];
      const double scale = tr * inv_lambda_ > cfg_.trace_max ? 1.0 : inv_lambda_;
      for (std::size_t i = 0; i < N; ++i)
        for (std::size_t j = 0; j < N; ++j) p_[i][j] = (p_[i][j] - pz[i] * phip[j] * inv) * scale;
    }
    project();
    ++updates_;
    return yhat;
  }

  const Vec& eta() const noexcept { return eta_; }
  double eta(std::size_t i) const noexcept { return eta_[i]; }
  const Mat& P() const noexcept { return p_; }
  double trace() const noexcept {
    double t = 0.0;
    for (std::size_t i = 0; i < N; ++i) t += p_[i][i];
    return t;
  }
  std::uint64_t updates() const noexcept { return updates_; }
  std::uint64_t skipped() const noexcept { return skipped_; }
  const RlsConfig<N>& config() const noexcept { return cfg_; }

 private:
  /// All of phi and y finite: x·0 is 0 for a finite x and NaN for ±inf or NaN, so the sum is 0
  /// exactly when every term is finite (no branch per element).
  static bool finite(const Vec& phi, double y) noexcept {
    double s = y * 0.0;
    for (std::size_t i = 0; i < N; ++i) s += phi[i] * 0.0;
    return s == 0.0;
  }
  /// φᵀPφ for symmetric P: the φ products do not depend on P, and the terms are added
  /// pairwise, so the chain from P(k−1) to the division is short (see bench/bench_identify.cpp).
  double quad(const Vec& phi) const noexcept {
    if constexpr (N == 3) {
      const double d = (p_[0][0] * (phi[0] * phi[0]) + p_[1][1] * (phi[1] * phi[1])) + p_[2][2] * (phi[2] * phi[2]);
      const double o = (p_[0][1] * (phi[0] * phi[1]) + p_[0][2] * (phi[0] * phi[2])) + p_[1][2] * (phi[1] * phi[2]);
      return d + 2.0 * o;
    } else {
      double d = 0.0, o = 0.0;
      for (std::size_t i = 0; i < N; ++i) {
        d += p_[i][i] * (phi[i] * phi[i]);
        for (std::size_t j = i + 1; j < N; ++j) o += p_[i][j] * (phi[i] * phi[j]);
      }
      return d + 2.0 * o;
    }
  }
#if defined(__GNUC__)
  /// update_iv for N = 4 (deadzone-deadband's pooled regression, lash's default method) in pairs
  /// of doubles (GCC/Clang vector extension: SSE2 on x86-64, NEON on AArch64; the same IEEE
  /// operations in the same order on either compiler). P is kept by rows, so φᵀP is a sum of
  /// scaled rows and Pz a dot product per row, summed as (P_i0 z0 + P_i2 z2) + (P_i1 z1 + P_i3 z3).
  /// The rank-1 update is P −= q (φᵀP) with q = Pz/(λ + φᵀPz) formed once (4 products instead of 16).
  __attribute__((always_inline)) double update_iv4(const Vec& phi, const Vec& z, double y) noexcept {
    using v2 = double __attribute__((vector_size(16)));
    auto load = [](const double* a) noexcept {
      v2 r;
      std::memcpy(&r, a, sizeof r);
      return r;
    };
    auto store = [](double* a, v2 r) noexcept { std::memcpy(a, &r, sizeof r); };
    // finite(phi, y) && finite(z): x·0 is 0 for a finite x and NaN for ±inf or NaN, so the sum of
    // the nine products is 0 exactly when all nine are finite (four vector products, no branch each)
    const v2 zero = {0.0, 0.0};
    const v2 nf = ((v2{phi[0], phi[1]} * zero + v2{phi[2], phi[3]} * zero) +
                   (v2{z[0], z[1]} * zero + v2{z[2], z[3]} * zero)) + v2{y, 0.0} * zero;
    if (!(nf[0] + nf[1] == 0.0)) [[unlikely]] {
      ++skipped_;
      return std::numeric_limits<double>::quiet_NaN();
    }
    const double yhat = predict(phi);
    v2 lo[4], hi[4];  // row i: [P_i0, P_i1], [P_i2, P_i3]
    for (std::size_t i = 0; i < 4; ++i) {
      lo[i] = load(&p_[i][0]);
      hi[i] = load(&p_[i][2]);
    }
    const v2 f0 = {phi[0], phi[0]}, f1 = {phi[1], phi[1]}, f2 = {phi[2], phi[2]}, f3 = {phi[3], phi[3]};
    const v2 phip_lo = (f0 * lo[0] + f1 * lo[1]) + (f2 * lo[2] + f3 * lo[3]);  // φᵀP
    const v2 phip_hi = (f0 * hi[0] + f1 * hi[1]) + (f2 * hi[2] + f3 * hi[3]);
    const v2 zl = {z[0], z[1]}, zh = {z[2], z[3]};
    v2 t[4];
    for (std::size_t i = 0; i < 4; ++i) t[i] = lo[i] * zl + hi[i] * zh;  // [P_i0 z0 + P_i2 z2, P_i1 z1 + P_i3 z3]
    const v2 pz_lo = v2{t[0][0], t[1][0]} + v2{t[0][1], t[1][1]};          // P z
    const v2 pz_hi = v2{t[2][0], t[3][0]} + v2{t[2][1], t[3][1]};
    const v2 rr = v2{phi[0], phi[1]} * pz_lo + v2{phi[2], phi[3]} * pz_hi;  // φᵀPz
    const double den = cfg_.lambda + (rr[0] + rr[1]);
    if (!(std::fabs(den) > 1e-300)) {
      ++skipped_;
      return yhat;
    }
    const double inv = 1.0 / den;
    const double err = y - yhat;
    const v2 q_lo = pz_lo * inv, q_hi = pz_hi * inv;  // q = Pz/(λ + φᵀPz)
    store(&eta_[0], load(&eta_[0]) + q_lo * err);
    store(&eta_[2], load(&eta_[2]) + q_hi * err);
    const double q[4] = {q_lo[0], q_lo[1], q_hi[0], q_hi[1]};
    if (unit_lambda_) {  // λ = 1: no scaling (x·1 = x)
      for (std::size_t i = 0; i < 4; ++i) {
        store(&p_[i][0], lo[i] - q[i] * phip_lo);
        store(&p_[i][2], hi[i] - q[i] * phip_hi);
      }
    } else {
      double tr = 0.0;
      for (std::size_t i = 0; i < 4; ++i) tr += p_[i][i];
      const double scale = tr * inv_lambda_ > cfg_.trace_max ? 1.0 : inv_lambda_;
      for (std::size_t i = 0; i < 4; ++i) {
        store(&p_[i][0], (lo[i] - q[i] * phip_lo) * scale);
        store(&p_[i][2], (hi[i] - q[i] * phip_hi) * scale);
      }
    }
    project();
    ++updates_;
    return yhat;
  }
#endif
  void project() noexcept {
    if (!bounded_) return;  // clamping onto (−inf, inf) is the identity (a NaN stays NaN either way)
    for (std::size_t i = 0; i < N; ++i)
      eta_[i] = eta_[i] < cfg_.lower[i] ? cfg_.lower[i] : (eta_[i] > cfg_.upper[i] ? cfg_.upper[i] : eta_[i]);
  }

  RlsConfig<N> cfg_;
  double inv_lambda_ = 1.0;
  bool unit_lambda_ = false;  // λ = 1 (no forgetting): the sample path skips the 1/λ scaling
  bool bounded_ = false;      // some projection bound is finite
  Vec eta_{};
  Mat p_{};
  std::uint64_t updates_ = 0;
  std::uint64_t skipped_ = 0;
};

}  // namespace lash
