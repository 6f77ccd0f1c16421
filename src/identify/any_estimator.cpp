#include "lash/identify/any_estimator.hpp"

#include <algorithm>
#include <cmath>

#include "lash/metrics/first_order.hpp"

namespace lash {

namespace {
using Var = std::variant<LinearEstimator, InputDeadzoneEstimator, OutputDeadzoneEstimator, DeadzoneDeadbandEstimator,
                         CoupledCartsEstimator>;
Var make(const EstimatorConfig& c) {
  switch (c.model) {
    case ModelKind::linear: return Var(std::in_place_type<LinearEstimator>, c);
    case ModelKind::input_deadzone: return Var(std::in_place_type<InputDeadzoneEstimator>, c);
    case ModelKind::output_deadzone: return Var(std::in_place_type<OutputDeadzoneEstimator>, c);
    case ModelKind::deadzone_deadband: return Var(std::in_place_type<DeadzoneDeadbandEstimator>, c);
    case ModelKind::coupled_carts: return Var(std::in_place_type<CoupledCartsEstimator>, c);
  }
  throw std::invalid_argument("unknown model");
}
}  // namespace

AnyEstimator::AnyEstimator(const EstimatorConfig& cfg) : cfg_(cfg), e_(make(cfg)) {}

std::vector<std::string> AnyEstimator::param_names() const {
  switch (cfg_.model) {
    case ModelKind::linear: return {"a1", "b1"};
    case ModelKind::input_deadzone:
    case ModelKind::output_deadzone: return {"a1_r", "b1_r", "c_r", "a1_l", "b1_l", "c_l"};
    case ModelKind::deadzone_deadband: return {"a1_r", "b1_r", "c_r", "d_r", "a1_l", "b1_l", "c_l", "d_l"};
    case ModelKind::coupled_carts: return {"a1_r", "b1_r", "c_r", "a1_l", "b1_l", "c_l", "d"};
  }
  return {};
}

void AnyEstimator::param_values(std::span<double> out) const noexcept {
  const SideParams r = params(Side::right), l = params(Side::left);
  std::size_t i = 0;
  auto put = [&](double x) noexcept {
    if (i < out.size()) out[i++] = x;
  };
  switch (cfg_.model) {
    case ModelKind::linear: put(r.a1); put(r.b1); break;
    case ModelKind::input_deadzone:
    case ModelKind::output_deadzone:
      put(r.a1); put(r.b1); put(r.c); put(l.a1); put(l.b1); put(l.c);
      break;
    case ModelKind::deadzone_deadband:
      put(r.a1); put(r.b1); put(r.c); put(r.d); put(l.a1); put(l.b1); put(l.c); put(l.d);
      break;
    case ModelKind::coupled_carts:
      put(r.a1); put(r.b1); put(r.c); put(l.a1); put(l.b1); put(l.c); put(r.d);
      break;
  }
}

EstimateReport AnyEstimator::report() const {
  EstimateReport rep;
  rep.model = cfg_.model;
  rep.samples = samples_;
  rep.identified = identified();
  auto fill = [this](SideReport& r, Side s) {
    SideParams p = params(s);
    p.reason = verdict(s);
    p.identified = p.reason == Reason::none;
    r.K = static_gain(p.a1, p.b1);
    r.tau_s = time_constant_s(p.a1, cfg_.dt_s);
    r.params = p;
  };
  fill(rep.right, Side::right);
  fill(rep.left, Side::left);
  std::visit(
      [&](const auto& e) {
        using E = std::decay_t<decltype(e)>;
        rep.skipped = e.skipped();
        rep.fit_nrmse = e.fit_nrmse();
        if constexpr (std::is_same_v<E, LinearEstimator>) {
          rep.right.updates = {{"all", e.updates()}};
        } else if constexpr (std::is_same_v<E, DeadzoneDeadbandEstimator>) {
          rep.has_c = rep.has_side_d = true;
          rep.right.updates = {{"+", e.updates(Side::right, true)}, {"-", e.updates(Side::right, false)}};
          rep.left.updates = {{"+", e.updates(Side::left, true)}, {"-", e.updates(Side::left, false)}};
        } else {
          rep.has_c = true;
          rep.right.updates = {{"all", e.updates(Side::right)}};
          rep.left.updates = {{"all", e.updates(Side::left)}};
          if constexpr (std::is_same_v<E, CoupledCartsEstimator>) {
            rep.has_shared_d = true;
            rep.d = e.deadband();
            rep.d_reason = e.deadband_reason();
            rep.d_updates = {{"+", e.deadband_updates(true)}, {"-", e.deadband_updates(false)}};
          }
        }
      },
      e_);
  return rep;
}

EstimationRun run_estimator(const EstimatorConfig& cfg, std::span<const double> v, std::span<const double> y,
                            bool keep_trace, const std::function<void(const AnyEstimator&)>& at_end,
                            std::span<const std::size_t> gap_rows) {
  if (v.size() != y.size()) throw std::invalid_argument("v and y differ in length");
  AnyEstimator est(cfg);
  EstimationRun run;
  const std::size_t n = v.size();
  run.yhat.reserve(n);  // filled in step order below: no zero-filling pass over 2 x n doubles first
  run.ysim.reserve(n);
  run.param_names = est.param_names();
  std::vector<double> pv(run.param_names.size());
  if (keep_trace) run.params.assign(pv.size(), std::vector<double>(n));
  step_through(est, v, y, 0, n, gap_rows, [&](std::size_t k, const auto& e) {
    run.yhat.push_back(e.prediction());  // k = run.yhat.size(): step_through goes 0, 1, ..., n - 1
    run.ysim.push_back(e.simulated());
    if (keep_trace) {
      est.param_values(pv);
      for (std::size_t p = 0; p < pv.size(); ++p) run.params[p][k] = pv[p];
    }
  });
  run.report = est.report();
  if (at_end) at_end(est);
  return run;
}

void add_intervals(EstimationRun& run, const EstimatorConfig& cfg, std::span<const double> v,
                   std::span<const double> y, std::span<const std::size_t> gap_rows) {
  IntervalSettings s;
  s.gap_rows = gap_rows;
  const auto ci = batch_means_intervals(cfg, v, y, {run.report.right.params, run.report.left.params}, s);
  if (run.report.right.params.identified) run.report.right.ci95 = ci.right;
  if (run.report.left.params.identified) run.report.left.ci95 = ci.left;
}

}  // namespace lash
