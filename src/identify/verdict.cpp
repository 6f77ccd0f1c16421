#include "lash/identify/verdict.hpp"

#include <Eigen/Dense>

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
  }
  return "?";
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

template <std::size_t N>
bool well_conditioned(const std::array<std::array<double, N>, N>& P) noexcept {
  using M = Eigen::Matrix<double, int(N), int(N)>;
  M p;
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < N; ++j) p(Eigen::Index(i), Eigen::Index(j)) = P[i][j];
  if (!p.allFinite()) return false;
  const M sym = 0.5 * (p + p.transpose());
  Eigen::LDLT<M> ldlt(sym);
  if (ldlt.info() != Eigen::Success) return false;
  M info = ldlt.solve(M::Identity());
  info = 0.5 * (info + info.transpose());
  if (!info.allFinite()) return false;
  Eigen::Matrix<double, int(N), 1> s;
  for (Eigen::Index i = 0; i < Eigen::Index(N); ++i) {
    if (!(info(i, i) > 0.0)) return false;
    s(i) = 1.0 / std::sqrt(info(i, i));
  }
  const M scaled = s.asDiagonal() * info * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<M> eig(scaled, Eigen::EigenvaluesOnly);
  if (eig.info() != Eigen::Success) return false;
  return eig.eigenvalues()(0) > kMinScaledEigenvalue;
}

template bool well_conditioned<2>(const std::array<std::array<double, 2>, 2>&) noexcept;
template bool well_conditioned<3>(const std::array<std::array<double, 3>, 3>&) noexcept;
template bool well_conditioned<4>(const std::array<std::array<double, 4>, 4>&) noexcept;

}  // namespace verdict_rules
}  // namespace lash
