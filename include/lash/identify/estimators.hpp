#pragma once
/// @file estimators.hpp
/// The switching RLS estimators of docs/method.md §A4 (thesis §1.4, §1.6): one skeleton,
/// SwitchingEstimator<Model> (estimator_skeleton.hpp), and one policy per model
/// (identify/models/*.hpp). Each takes one sample (v(k), y(k)) per step(), which is noexcept,
/// O(1) and allocation-free; construction validates the EstimatorConfig (std::invalid_argument)
/// and allocates the filters.
///
/// Every estimator exposes per side a1, b1 (and c, d where the model has them), update
/// counts per key, `identified`, the one-step prediction ŷ and a free-run simulated output
/// y_sim of the identified model driven by v alone. A parameter that is not identified yet
/// is NaN — never a huge number.
///
/// Regression (docs/method.md §A4): φ(k) = [−y(k−1), v(k−1), 1], η = [a1, b1, e].
///
/// restart() (after a gap in the record's timestamps, docs/identification.md "Gaps") clears the
/// signal history — filters, delays, derivative, the direction-hold counters, the previous samples
/// and the instruments — but keeps the parameter estimates, covariances, update counts and the
/// verdict's evidence. The next warmup() samples refill that history and update nothing, so no
/// regression ever mixes samples from both sides of a gap. The free-run simulation y_sim is a
/// model driven by v alone, not a regression: it runs on. restart() is noexcept and allocation-free.
///
/// Adding a model: a policy header + source under identify/models/ (its traits inside), its
/// ModelKind (config.hpp) and its entry in EstimatorModels below.
#include <array>
#include <cstddef>

#include "lash/identify/estimator_skeleton.hpp"
#include "lash/identify/models/coupled_carts.hpp"
#include "lash/identify/models/deadzone_deadband.hpp"
#include "lash/identify/models/input_deadzone.hpp"
#include "lash/identify/models/linear.hpp"
#include "lash/identify/models/output_deadzone.hpp"

namespace lash {

/// A list of model policies.
template <class... M>
struct ModelList {
  static constexpr std::size_t size = sizeof...(M);
  static constexpr std::array<ModelTraits, sizeof...(M)> traits{M::traits...};
};

/// The registration: every model lash knows, in ModelKind order.
using EstimatorModels =
    ModelList<LinearModel, InputDeadzoneModel, OutputDeadzoneModel, DeadzoneDeadbandModel, CoupledCartsModel>;

static_assert(Estimator<LinearEstimator>);
static_assert(Estimator<InputDeadzoneEstimator>);
static_assert(Estimator<OutputDeadzoneEstimator>);
static_assert(Estimator<DeadzoneDeadbandEstimator>);
static_assert(Estimator<CoupledCartsEstimator>);

namespace detail {
template <class... M>
constexpr bool in_kind_order(ModelList<M...>) {
  std::size_t i = 0;
  return ((static_cast<std::size_t>(M::traits.kind) == i++) && ...);
}
template <class... M, class F>
constexpr bool for_model(ModelList<M...>, ModelKind m, F& f) {
  return ((M::traits.kind == m && (f.template operator()<M>(), true)) || ...);
}
}  // namespace detail
static_assert(detail::in_kind_order(EstimatorModels{}), "EstimatorModels must list the models in ModelKind order");
static_assert(EstimatorModels::size == kModelCount, "every ModelKind needs its policy in EstimatorModels");

/// The traits of model m (every ModelKind has them).
constexpr const ModelTraits& model_traits(ModelKind m) noexcept {
  return EstimatorModels::traits[static_cast<std::size_t>(m)];
}

/// Calls f.template operator()<Policy>() with the policy of model m; false when m is none of
/// EstimatorModels' (then f is not called).
template <class F>
constexpr bool with_model(ModelKind m, F&& f) {
  return detail::for_model(EstimatorModels{}, m, f);
}

}  // namespace lash
