#include "lash/identify/verdict.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>

namespace lash {

const char* to_string(Reason r) noexcept {
  switch (r) {
    case Reason::none: return "none";
    case Reason::not_updated: return "not_updated";
    case Reason::not_excited: return "not_excited";
    case Reason::unstable: return "unstable";
    case Reason::unphysical: return "unphysical";
    case Reason::poor_fit: return "poor_fit";
    case Reason::wrong_guess: return "wrong_guess";
    case Reason::uncertain: return "uncertain";
  }
  return "?";
}

void both_sides_reason(std::span<char> out, const char* right, const char* left) noexcept {
  if (!out.empty()) std::snprintf(out.data(), out.size(), "right: %s; left: %s", right, left);
}

namespace verdict_rules {

Reason judge(const Evidence& e) noexcept {
  if (!e.updated) return Reason::not_updated;
  if (!e.excited) return Reason::not_excited;
  if (!(std::isfinite(e.a1) && std::isfinite(e.b1)) || !(std::fabs(e.a1) < 1.0)) return Reason::unstable;
  if (!(e.b1 > 0.0)) return Reason::unphysical;
  if (e.negative_a1 && !(e.a1 < 0.0)) return Reason::unphysical;
  if (e.has_c && !(std::isfinite(e.c) && physical_edge(e.c, e.side))) return Reason::unphysical;
  if (e.has_d && !(std::isfinite(e.d) && e.d >= 0.0)) return Reason::unphysical;
  if (!e.guess_ok) return Reason::wrong_guess;
  return Reason::none;
}

namespace {
template <std::size_t N>
using Mat = std::array<std::array<double, N>, N>;

/// Smallest eigenvalue of a symmetric matrix (cyclic Jacobi rotations, Golub & Van Loan §8.5).
template <std::size_t N>
double min_eigenvalue(Mat<N> a) noexcept {
  for (int sweep = 0; sweep < 50; ++sweep) {
    double off = 0.0;
    for (std::size_t p = 0; p < N; ++p)
      for (std::size_t q = p + 1; q < N; ++q) off += a[p][q] * a[p][q];
    if (off < 1e-30) break;
    for (std::size_t p = 0; p < N; ++p)
      for (std::size_t q = p + 1; q < N; ++q) {
        if (a[p][q] == 0.0) continue;
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (std::size_t k = 0; k < N; ++k) {  // A ← A·J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (std::size_t k = 0; k < N; ++k) {  // A ← Jᵀ·A
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
      }
  }
  double m = a[0][0];
  for (std::size_t i = 1; i < N; ++i) m = std::min(m, a[i][i]);
  return m;
}
}  // namespace

template <std::size_t N>
bool well_conditioned(const std::array<std::array<double, N>, N>& P) noexcept {
  // cond(P⁻¹) = cond(P): scale the symmetrised covariance to unit diagonal (removes the units of
  // the regressors) and look at its smallest eigenvalue. No inversion: a nearly singular
  // information matrix is a P with one huge eigenvalue, which the scaling turns into a
  // smallest eigenvalue near 0 that the Jacobi rotations resolve to rounding (1e-16).
  std::array<double, N> s{};
  for (std::size_t i = 0; i < N; ++i) {
    if (!(P[i][i] > 0.0) || !std::isfinite(P[i][i])) return false;
    s[i] = 1.0 / std::sqrt(P[i][i]);
  }
  Mat<N> scaled{};
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < N; ++j) {
      if (!std::isfinite(P[i][j])) return false;
      scaled[i][j] = s[i] * (0.5 * (P[i][j] + P[j][i])) * s[j];
    }
  return min_eigenvalue<N>(scaled) > kMinScaledEigenvalue;
}

template bool well_conditioned<2>(const std::array<std::array<double, 2>, 2>&) noexcept;
template bool well_conditioned<3>(const std::array<std::array<double, 3>, 3>&) noexcept;
template bool well_conditioned<4>(const std::array<std::array<double, 4>, 4>&) noexcept;

}  // namespace verdict_rules
}  // namespace lash
