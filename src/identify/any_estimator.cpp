#include "lash/identify/any_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "lash/metrics/first_order.hpp"

namespace lash {

AnyEstimator::Variant AnyEstimator::make(const EstimatorConfig& c) {
  std::optional<Variant> v;
  if (!with_model(c.model, [&]<class Model>() { v.emplace(std::in_place_type<SwitchingEstimator<Model>>, c); }))
    throw std::invalid_argument("unknown model");
  return std::move(*v);
}

AnyEstimator::AnyEstimator(const EstimatorConfig& cfg) : cfg_(cfg), e_(make(cfg)) {}

std::vector<std::string> AnyEstimator::param_names() const { return lash::param_names(model_traits(cfg_.model)); }

std::vector<std::string> param_names(const ModelTraits& t) {
  if (!t.two_sided) return {"a1", "b1"};
  std::vector<std::string> n;
  for (const char* s : {"_r", "_l"}) {
    for (const char* p : {"a1", "b1", "c", "d"})
      if ((p[0] != 'c' || t.has_c) && (p[0] != 'd' || t.has_side_d)) n.push_back(p + std::string(s));
  }
  if (t.has_shared_d) n.emplace_back("d");
  return n;
}

void AnyEstimator::param_values(std::span<double> out) const noexcept {
  const ModelTraits& t = model_traits(cfg_.model);
  const SideParams r = params(Side::right), l = params(Side::left);
  std::size_t i = 0;
  auto put = [&](double x) noexcept {
    if (i < out.size()) out[i++] = x;
  };
  for (const SideParams* p : {&r, &l}) {
    put(p->a1);
    put(p->b1);
    if (!t.two_sided) return;
    if (t.has_c) put(p->c);
    if (t.has_side_d) put(p->d);
  }
  if (t.has_shared_d) put(r.d);
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
  const ModelTraits& t = model_traits(cfg_.model);
  rep.has_c = t.has_c;
  rep.has_side_d = t.has_side_d;
  rep.has_shared_d = t.has_shared_d;
  std::visit(
      [&](const auto& e) {
        using E = std::decay_t<decltype(e)>;
        rep.skipped = e.skipped();
        rep.fit_nrmse = e.fit_nrmse();
        auto counts = [&](Side s) -> std::vector<std::pair<std::string, std::uint64_t>> {
          if constexpr (E::traits.keys_by_direction) return {{"+", e.updates(s, true)}, {"-", e.updates(s, false)}};
          return {{"all", e.updates(s)}};
        };
        rep.right.updates = counts(Side::right);
        if constexpr (E::traits.two_sided) rep.left.updates = counts(Side::left);
        if constexpr (E::traits.has_shared_d) {
          rep.d = e.deadband();
          rep.d_reason = e.deadband_reason();
          rep.d_updates = {{"+", e.deadband_updates(true)}, {"-", e.deadband_updates(false)}};
        }
      },
      e_);
  return rep;
}

RecordColumns RecordColumns::of(std::span<const double> v, std::span<const double> y) {
  if (v.size() != y.size()) throw std::invalid_argument("v and y differ in length");
  RecordColumns r;
  r.store = ColumnStore({v, y});
  return r;
}

RecordColumns RecordColumns::of(std::span<const double> t, std::span<const double> v, std::span<const double> y) {
  if (v.size() != y.size() || t.size() != v.size()) throw std::invalid_argument("t, v and y differ in length");
  RecordColumns r;
  r.store = ColumnStore({t, v, y});
  r.t = 0;
  r.vy = {1, 2};
  return r;
}

EstimationRun run_estimator(const EstimatorConfig& cfg, const RecordColumns& rec, const RunOptions& o) {
  AnyEstimator est(cfg);
  EstimationRun run;
  const std::size_t n = rec.size();
  if (o.keep_outputs) {
    run.yhat.reserve(n);  // filled in step order below: no zero-filling pass over 2 x n doubles first
    run.ysim.reserve(n);
  }
  run.param_names = est.param_names();
  std::vector<double> pv(run.param_names.size());
  if (o.keep_trace) run.params.assign(pv.size(), std::vector<double>(n));
  const std::size_t s0 = std::min(o.score_begin, n), s1 = std::min(std::max(o.score_end, s0), n);
  NrmseAccumulator score;
  // the score reads y as given (an edited row's own value: the edits live apart from y)
  step_through(est, rec, 0, n, o.gap_rows, [&](std::size_t k, double yk, const auto& e) {
    if (o.keep_outputs) {
      run.yhat.push_back(e.prediction());  // k = run.yhat.size(): step_through goes 0, 1, ..., n - 1
      run.ysim.push_back(e.simulated());
    }
    if (k - s0 < s1 - s0) score.add(yk, e.simulated());  // s0 <= k < s1
    if (o.keep_trace || o.on_step) {
      est.param_values(pv);
      if (o.keep_trace)
        for (std::size_t p = 0; p < pv.size(); ++p) run.params[p][k] = pv[p];
      if (o.on_step) o.on_step(TraceRow{k, yk, e.prediction(), e.simulated(), pv});
    }
  }, o.y_edits);
  run.score = score;
  run.report = est.report();
  if (o.at_end) o.at_end(est);
  return run;
}

EstimationRun run_estimator(const EstimatorConfig& cfg, std::span<const double> v, std::span<const double> y,
                            const RunOptions& o) {
  return run_estimator(cfg, RecordColumns::of(v, y), o);
}

EstimationRun run_estimator(const EstimatorConfig& cfg, std::span<const double> v, std::span<const double> y,
                            bool keep_trace, const std::function<void(const AnyEstimator&)>& at_end,
                            std::span<const std::size_t> gap_rows) {
  RunOptions o;
  o.keep_trace = keep_trace;
  o.at_end = at_end;
  o.gap_rows = gap_rows;
  return run_estimator(cfg, v, y, o);
}

void add_intervals(EstimationRun& run, const EstimatorConfig& cfg, const RecordColumns& rec,
                   std::span<const std::size_t> gap_rows) {
  IntervalSettings s;
  s.gap_rows = gap_rows;
  const PerSide<SideParams> est{run.report.right.params, run.report.left.params};
  // model switching with λ = 1: its sides are often driven beyond the edge too seldom for a
  // section's estimate, and the estimate is a smooth function of sums over the samples
  attach_intervals(run.report,
                   cfg.model_switching && cfg.rls.lambda == 1.0 ? jackknife_intervals(cfg, rec, est, s)
                                                                : batch_means_intervals(cfg, rec, est, s),
                   cfg.ci_tolerance);
}

void add_intervals(EstimationRun& run, const EstimatorConfig& cfg, std::span<const double> v,
                   std::span<const double> y, std::span<const std::size_t> gap_rows) {
  add_intervals(run, cfg, RecordColumns::of(v, y), gap_rows);
}

void attach_intervals(EstimateReport& rep, const PerSide<SideIntervals>& ci, double ci_tolerance) {
  const bool two = model_traits(rep.model).two_sided;
  for (const Side s : {Side::right, Side::left}) {
    SideReport& r = rep[s];
    if (!r.params.identified) continue;
    r.ci95 = ci[s];
    if (interval_verdict(ci[s], s) == Reason::none &&
        precision_verdict(ci[s], ci_tolerance, rep.has_c, rep.has_side_d || rep.has_shared_d) == Reason::none)
      continue;
    r.params.reason = Reason::uncertain;
    r.params.identified = false;
    if (s == Side::right || two) rep.identified = false;
  }
}

}  // namespace lash
