#include "lash/identify/config_file.hpp"

#include <cmath>
#include <stdexcept>

#include "lash/io/error.hpp"

namespace lash {

namespace {
std::size_t count(TomlTable& t, std::string_view key, std::size_t fallback, std::int64_t lo, std::int64_t hi) {
  const auto v = t.integer_opt(key);
  if (!v) return fallback;
  if (*v < lo || *v > hi) t.fail(key, "must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
  return static_cast<std::size_t>(*v);
}
std::array<double, 3> triple(TomlTable& t, std::string_view key, std::array<double, 3> fallback) {
  const auto v = t.numbers_opt(key);
  if (!v) return fallback;
  if (v->size() != 3) t.fail(key, "expected 3 numbers [a1, b1, e]");
  return {(*v)[0], (*v)[1], (*v)[2]};
}
}  // namespace

void read_estimator_config(TomlTable& t, EstimatorConfig& c, EstimationJob* job) {
  if (auto m = t.string_opt("model")) {
    try {
      c.model = parse_model_kind(*m);
    } catch (const std::invalid_argument& e) {
      t.fail("model", e.what());
    }
  }
  if (auto m = t.string_opt("method")) {
    try {
      c.method = parse_method(*m);
    } catch (const std::invalid_argument& e) {
      t.fail("method", e.what());
    }
  }
  c.guess_left = t.number_or("guess_left", c.guess_left);
  c.guess_right = t.number_or("guess_right", c.guess_right);
  if (auto b = t.boolean_opt("pooled")) c.pooled = *b;
  if (auto b = t.boolean_opt("sim_side_by_sign")) c.sim_side_by_sign = *b;
  c.iv_delay = count(t, "iv_delay", c.iv_delay, 1, 60);
  c.direction_run = static_cast<std::uint32_t>(count(t, "direction_run", c.direction_run, 2, 1000000));
  c.min_updates = count(t, "min_updates", c.min_updates, 1, 1000000000);
  c.singular_tol = t.number_or("singular_tol", c.singular_tol);
  c.settle_tol = t.number_or("settle_tol", c.settle_tol);
  c.settle_updates = static_cast<std::uint32_t>(count(t, "settle_updates", c.settle_updates, 0, 1000000));
  c.zero_threshold = t.number_or("zero_threshold", c.zero_threshold);
  c.accel_limit = t.number_or("accel_limit", c.accel_limit);
  c.stage2_start_s = t.number_or("stage2_start", c.stage2_start_s);
  c.fit_threshold = t.number_or("fit_threshold", c.fit_threshold);
  c.fit_start_s = t.number_or("fit_start", c.fit_start_s);
  if (job) {
    if (auto cols = t.strings_opt("columns")) {
      if (cols->size() != 3) t.fail("columns", "expected three names [t, v, y]");
      job->columns = *cols;
    }
    if (auto w = t.numbers_opt("nrmse_window")) {
      if (w->size() != 2 || !((*w)[0] < (*w)[1])) t.fail("nrmse_window", "expected [t0, t1] with t0 < t1 [s]");
      job->nrmse_t0_s = (*w)[0];
      job->nrmse_t1_s = (*w)[1];
    }
  }
  if (auto r = t.table_opt("rls")) {
    c.rls.lambda = r->number_or("lambda", c.rls.lambda);
    c.rls.p0 = r->number_or("p0", c.rls.p0);
    c.rls.eta0 = triple(*r, "eta0", c.rls.eta0);
    c.rls.lower = triple(*r, "lower", c.rls.lower);
    c.rls.upper = triple(*r, "upper", c.rls.upper);
    c.rls.trace_max = r->number_or("trace_max", c.rls.trace_max);
    if (auto f = r->string_opt("forgetting")) {
      try {
        c.rls.forgetting = parse_forgetting(*f);
      } catch (const std::invalid_argument& e) {
        r->fail("forgetting", e.what());
      }
    }
    r->finish();
  }
  if (auto n = t.table_opt("noise")) {
    c.noise.filter_length = count(*n, "filter_length", c.noise.filter_length, 1, 100000);
    if (auto b = n->boolean_opt("filter_input")) c.noise.filter_input = *b;
    c.noise.input_delay = count(*n, "input_delay", c.noise.input_delay, 0, 100000);
    c.noise.derivative_prefilter_length =
        count(*n, "derivative_prefilter_length", c.noise.derivative_prefilter_length, 0, 100000);
    c.noise.derivative_filter_length =
        count(*n, "derivative_filter_length", c.noise.derivative_filter_length, 1, 100000);
    c.noise.derivative_threshold = n->number_or("derivative_threshold", c.noise.derivative_threshold);
    c.noise.align_delay = count(*n, "align_delay", c.noise.align_delay, 0, 100000);
    n->finish();
  }
  t.finish();
}

}  // namespace lash
