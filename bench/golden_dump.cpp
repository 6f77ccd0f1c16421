// Golden dump of the estimators (scripts/golden_estimators.sh): every estimator of
// docs/method.md §A4 under several settings, stepped through the generic tester's record
// (tests/unit/test_estimators_generic.cpp) with non-finite samples and gaps (restart()), and
// everything observable after every sample folded into a 64-bit FNV-1a hash of the bits, plus the
// final values printed exactly (%a). Two builds whose dumps are byte-identical computed the same
// numbers, bit for bit. Written against the estimators' public interface only.
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "lash/identify/estimators.hpp"

namespace {

using namespace lash;
constexpr double kDt = 0.005;

struct Record {
  std::vector<double> v, y;
};
// The generic tester's record: 1 Hz sine of amplitude 600 through DZ(−300, 200) and eq. 34's lags.
Record make_record(std::size_t n) {
  Record r;
  double y = 0.0;
  std::uint64_t state = 12345;
  for (std::size_t k = 0; k < n; ++k) {
    const double v = 600.0 * std::sin(2.0 * M_PI * 1.0 * static_cast<double>(k) * kDt);
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const double noise = (static_cast<double>(state >> 11) * 0x1.0p-53 - 0.5) * 2.0;
    r.v.push_back(v);
    r.y.push_back(y + noise);
    const bool right = v >= 0.0;
    const double u = v > 200.0 ? v - 200.0 : (v < -300.0 ? v + 300.0 : 0.0);
    y = -(right ? -0.96 : -0.94) * y + (right ? 0.1 : 0.15) * u;
  }
  return r;
}

struct Hash {
  std::uint64_t h = 1469598103934665603ULL;
  void add(double x) {
    std::uint64_t b;
    std::memcpy(&b, &x, 8);
    if (std::isnan(x)) b = 0x7ff8000000000000ULL;  // one NaN
    for (int i = 0; i < 8; ++i) {
      h ^= (b >> (8 * i)) & 0xffu;
      h *= 1099511628211ULL;
    }
  }
};

template <class E>
std::vector<double> observe(const E& e, double yhat) {
  std::vector<double> o{yhat, e.prediction(), e.simulated(), static_cast<double>(e.skipped()), e.fit_nrmse(),
                        static_cast<double>(e.identified()), static_cast<double>(e.warming_up())};
  for (Side s : {Side::right, Side::left}) {
    const SideParams p = e.params(s);
    o.insert(o.end(), {p.a1, p.b1, p.c, p.d, static_cast<double>(p.identified), static_cast<double>(p.reason),
                       static_cast<double>(e.verdict(s)), static_cast<double>(e.updates(s))});
    if constexpr (std::is_same_v<E, DeadzoneDeadbandEstimator>)
      o.insert(o.end(), {static_cast<double>(e.updates(s, true)), static_cast<double>(e.updates(s, false))});
  }
  if constexpr (std::is_same_v<E, CoupledCartsEstimator>)
    o.insert(o.end(), {e.deadband(), static_cast<double>(e.deadband_reason()),
                       static_cast<double>(e.deadband_updates(true)), static_cast<double>(e.deadband_updates(false)),
                       e.simulated_velocity()});
  return o;
}

template <class E>
void dump(const char* name, const EstimatorConfig& c, const Record& r) {
  E e(c);
  Hash h;
  std::vector<double> last;
  for (std::size_t k = 0; k < r.v.size(); ++k) {
    if (k == 2500 || k == 4100) e.restart();  // two gaps
    double v = r.v[k], y = r.y[k];
    if (k == 1000) v = std::numeric_limits<double>::quiet_NaN();
    if (k == 1700) y = std::numeric_limits<double>::infinity();
    const double yhat = e.step(v, y);
    last = observe(e, yhat);
    for (double x : last) h.add(x);
  }
  std::printf("%-40s hash %016" PRIx64 " warmup %u\n ", name, h.h, static_cast<unsigned>(e.warmup()));
  for (double x : last) std::printf(" %a", x);
  std::printf("\n");
}

EstimatorConfig base(ModelKind m, bool thesis) {
  EstimatorConfig c = thesis ? EstimatorConfig::thesis(m, kDt) : EstimatorConfig(m, kDt);
  c.guess_left = -350.0;
  c.guess_right = 350.0;
  if (m == ModelKind::coupled_carts) c.accel_limit = std::numeric_limits<double>::infinity();
  return c;
}

template <class E>
void all_settings(const char* model, ModelKind m, const Record& r) {
  const std::string n(model);
  dump<E>((n + " thesis").c_str(), base(m, true), r);
  dump<E>((n + " lash").c_str(), base(m, false), r);
  if (m != ModelKind::coupled_carts) {
    EstimatorConfig c = base(m, true);
    c.method = EstimationMethod::iv;
    c.iv_delay = 3;
    dump<E>((n + " thesis iv").c_str(), c, r);
  }
  EstimatorConfig f = base(m, true);
  f.noise.filter_length = 5;
  f.noise.filter_input = true;
  f.min_updates = 20;
  f.fit_start_s = 1.0;
  dump<E>((n + " filtered").c_str(), f, r);
  if (m == ModelKind::input_deadzone || m == ModelKind::deadzone_deadband) {
    EstimatorConfig c = base(m, true);
    c.sim_side_by_sign = true;
    dump<E>((n + " sim-side-by-sign").c_str(), c, r);
    c = base(m, true);
    c.guess_left = -250.0;
    c.guess_right = 150.0;  // inside the deadzone: wrong guesses
    dump<E>((n + " wrong guesses").c_str(), c, r);
  }
  if (m == ModelKind::deadzone_deadband) {
    EstimatorConfig c = base(m, true);
    c.pooled = true;
    dump<E>((n + " thesis pooled").c_str(), c, r);
    c = base(m, false);
    c.pooled = false;
    c.direction_run = 5;
    dump<E>((n + " lash separate").c_str(), c, r);
  }
  if (m == ModelKind::output_deadzone) {
    EstimatorConfig c = base(m, true);
    c.zero_threshold = 0.5;
    dump<E>((n + " zero-threshold").c_str(), c, r);
  }
  if (m == ModelKind::coupled_carts) {
    EstimatorConfig c = base(m, true);
    c.stage2_start_s = 2.0;
    c.accel_limit = 500.0;
    dump<E>((n + " stage2 2 s, accel 500").c_str(), c, r);
  }
}

}  // namespace

int main() {
  const Record r = make_record(6000);
  all_settings<LinearEstimator>("linear", ModelKind::linear, r);
  all_settings<InputDeadzoneEstimator>("input-deadzone", ModelKind::input_deadzone, r);
  all_settings<OutputDeadzoneEstimator>("output-deadzone", ModelKind::output_deadzone, r);
  all_settings<DeadzoneDeadbandEstimator>("deadzone-deadband", ModelKind::deadzone_deadband, r);
  all_settings<CoupledCartsEstimator>("coupled-carts", ModelKind::coupled_carts, r);
  return 0;
}
