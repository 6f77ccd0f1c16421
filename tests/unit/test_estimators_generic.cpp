// One generic tester (in the manner of manif's invariant tester) run over all five estimators of
// docs/method.md §A4 and a sixth written in this test against the skeleton (sixth_model.hpp):
// every invariant of the sample path, on the same data, for every estimator type.
// This binary replaces the global operator new to count heap allocations inside update().
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <type_traits>
#include <vector>

#include "lash/identify/any_estimator.hpp"
#include "lash/identify/estimators.hpp"
#include "sixth_model.hpp"

// GCC 12 pairs the inlined std::allocator calls with these replacements and warns of a
// malloc/delete mismatch that does not exist (both sides of every pair below use malloc/free).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

namespace {
std::atomic<std::size_t> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace lash {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDt = 0.005;

/// Settings per estimator type (the switching guesses where the model needs them).
template <class E>
EstimatorConfig config_for() {
  EstimatorConfig c = EstimatorConfig::thesis(E::traits.kind, kDt);
  c.accel_limit = std::numeric_limits<double>::infinity();  // coupled carts: no acceleration gate
  c.guess_left = -350.0;
  c.guess_right = 350.0;
  return c;
}

/// A record that exercises every switching branch: a 1 Hz sine of amplitude 600 through the
/// input deadzone [−300, 200] and the first-order lags of thesis eq. 34, plus a small
/// deterministic disturbance (a linear congruential sequence, identical on every platform).
struct Record {
  std::vector<double> v, y;
};
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

/// Everything observable after a sample, compared bit for bit (NaN equals NaN).
template <class E>
std::vector<double> observe(const E& e) {
  std::vector<double> o{e.prediction(), e.simulated()};
  for (Side s : {Side::right, Side::left}) {
    const SideParams p = e.params(s);
    o.insert(o.end(), {p.a1, p.b1, p.c, p.d, static_cast<double>(p.identified), static_cast<double>(p.reason),
                       static_cast<double>(e.verdict(s)), static_cast<double>(e.updates(s))});
  }
  return o;
}
bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!(a[i] == b[i] || (std::isnan(a[i]) && std::isnan(b[i])))) return false;
  return true;
}

template <class E>
class EstimatorInvariants : public ::testing::Test {
 protected:
  const Record rec = make_record(6000);  // 30 s
};

using AllEstimators = ::testing::Types<LinearEstimator, InputDeadzoneEstimator, OutputDeadzoneEstimator,
                                       DeadzoneDeadbandEstimator, CoupledCartsEstimator, test::SymmetricDeadzoneEstimator>;
TYPED_TEST_SUITE(EstimatorInvariants, AllEstimators);

TYPED_TEST(EstimatorInvariants, IsAnEstimatorWithItsTraits) {
  static_assert(Estimator<TypeParam>);
  constexpr ModelTraits t = TypeParam::traits;
  if constexpr (t.kind != test::kSymmetricDeadzone) {
    // the library's registration: the traits the rest of lash reads are this estimator's
    EXPECT_EQ(model_traits(t.kind).name, t.name);
    EXPECT_EQ(parse_model_kind(t.name), t.kind);
    EXPECT_EQ(std::string_view(to_string(t.kind)), t.name);
    EXPECT_EQ(AnyEstimator(config_for<TypeParam>()).param_names(), param_names(t));
  }
  // dispatch by kind finds this policy (the sixth through the test's registration)
  bool found = false;
  auto check = [&]<class M>() { found = std::is_same_v<SwitchingEstimator<M>, TypeParam>; };
  EXPECT_TRUE(detail::for_model(test::SixModels{}, t.kind, check));
  EXPECT_TRUE(found);
}

// set_guess(s, g): the guess is stored; a model that switches on the guesses starts side s's
// recursion anew (no updates, not identified) and leaves the other side's estimates as they were,
// also while both go on (their regressions are separate) — the sixth model's sides share one.
TYPED_TEST(EstimatorInvariants, SetGuessRestartsOnlyThatSide) {
  TypeParam a(config_for<TypeParam>()), b(config_for<TypeParam>());
  static_assert(noexcept(b.set_guess(Side::right, 1.0)));
  const auto& r = this->rec;
  for (std::size_t k = 0; k < 3000; ++k) {
    a.step(r.v[k], r.y[k]);
    b.step(r.v[k], r.y[k]);
  }
  const std::size_t allocs = g_allocations.load();
  b.set_guess(Side::right, 360.0);
  EXPECT_EQ(g_allocations.load(), allocs) << "set_guess() allocated";
  EXPECT_EQ(b.config().guess_right, 360.0);
  EXPECT_EQ(b.config().guess_left, -350.0);
  if constexpr (!TypeParam::traits.uses_guesses) {
    for (std::size_t k = 3000; k < r.v.size(); ++k) {  // the guess is not read: nothing changes
      a.step(r.v[k], r.y[k]);
      b.step(r.v[k], r.y[k]);
      ASSERT_TRUE(same_bits(observe(a), observe(b))) << "sample " << k;
    }
    return;
  }
  ASSERT_GT(a.updates(Side::right), 0u);
  EXPECT_EQ(b.updates(Side::right), 0u);
  EXPECT_EQ(b.params(Side::right).reason, Reason::not_updated);
  constexpr bool shared = TypeParam::traits.kind == test::kSymmetricDeadzone;
  auto left = [](const TypeParam& e) {
    const SideParams p = e.params(Side::left);
    return std::vector<double>{p.a1, p.b1, p.c, p.d, static_cast<double>(p.reason), static_cast<double>(e.updates(Side::left))};
  };
  if (!shared) {
    ASSERT_TRUE(same_bits(left(a), left(b)));
  }
  for (std::size_t k = 3000; k < r.v.size(); ++k) {
    a.step(r.v[k], r.y[k]);
    b.step(r.v[k], r.y[k]);
    if (!shared) {
      ASSERT_TRUE(same_bits(left(a), left(b))) << "sample " << k;
    }
  }
  EXPECT_GT(b.updates(Side::right), 0u) << "side r is updated again";
  EXPECT_LT(b.updates(Side::right), a.updates(Side::right));
}

// The sixth model identifies its plant: a noise-free record of y(k) = 0.9·y(k−1) + 0.2·DZ(v(k−1); ±100)
// (a1 = −0.9, b1 = 0.2, c = 100), v = 400 sin(2π·0.5 t), guesses ±150: the shared regression is
// exact, so every parameter is reached to 1e-6.
TEST(SixthModel, IdentifiesASymmetricDeadzone) {
  EstimatorConfig c = EstimatorConfig::thesis(test::kSymmetricDeadzone, kDt);
  c.guess_left = -150.0;
  c.guess_right = 150.0;
  test::SymmetricDeadzoneEstimator e(c);
  double y = 0.0, v1 = 0.0;
  for (std::size_t k = 0; k < 4000; ++k) {
    y = 0.9 * y + 0.2 * detail::deadzone(v1, -100.0, 100.0);
    const double v = 400.0 * std::sin(2.0 * M_PI * 0.5 * static_cast<double>(k) * kDt);
    e.step(v, y);
    v1 = v;
  }
  for (Side s : {Side::right, Side::left}) {
    const SideParams p = e.params(s);
    ASSERT_TRUE(p.identified) << to_string(p.reason);
    EXPECT_NEAR(p.a1, -0.9, 1e-6);
    EXPECT_NEAR(p.b1, 0.2, 1e-6);
    EXPECT_NEAR(p.c, s == Side::right ? 100.0 : -100.0, 1e-6);
    EXPECT_EQ(e.verdict(s), Reason::none);
  }
  EXPECT_TRUE(e.identified());
  EXPECT_LT(e.fit_nrmse(), 1e-6);  // the free run of the identified model is the plant
  EXPECT_EQ(param_names(test::SymmetricDeadzoneModel::traits),
            (std::vector<std::string>{"a1_r", "b1_r", "c_r", "a1_l", "b1_l", "c_l"}));
}

TYPED_TEST(EstimatorInvariants, UpdateIsNoexcept) {
  TypeParam e(config_for<TypeParam>());
  static_assert(noexcept(e.step(0.0, 0.0)), "step() must be noexcept");
  static_assert(noexcept(e.params(Side::right)) && noexcept(e.verdict(Side::left)));
  static_assert(noexcept(e.prediction()) && noexcept(e.simulated()) && noexcept(e.skipped()));
  SUCCEED();
}

TYPED_TEST(EstimatorInvariants, NonFiniteSampleLeavesStateUntouched) {
  TypeParam a(config_for<TypeParam>()), b(config_for<TypeParam>());
  const auto& r = this->rec;
  for (std::size_t k = 0; k < 3000; ++k) {
    a.step(r.v[k], r.y[k]);
    b.step(r.v[k], r.y[k]);
  }
  const std::uint64_t skipped = b.skipped();
  EXPECT_TRUE(std::isnan(b.step(kNaN, 1.0)));
  EXPECT_TRUE(std::isnan(b.step(1.0, std::numeric_limits<double>::infinity())));
  EXPECT_TRUE(std::isnan(b.step(-std::numeric_limits<double>::infinity(), kNaN)));
  EXPECT_EQ(b.skipped(), skipped + 3);
  for (std::size_t k = 3000; k < r.v.size(); ++k) {
    const double ya = a.step(r.v[k], r.y[k]), yb = b.step(r.v[k], r.y[k]);
    ASSERT_TRUE(same_bits({ya}, {yb})) << "sample " << k;
    ASSERT_TRUE(same_bits(observe(a), observe(b))) << "sample " << k;
  }
}

TYPED_TEST(EstimatorInvariants, ResetRestoresTheInitialState) {
  TypeParam fresh(config_for<TypeParam>()), used(config_for<TypeParam>());
  const auto& r = this->rec;
  for (std::size_t k = 0; k < 4000; ++k) used.step(-r.v[k], 2.0 * r.y[k]);  // some other history
  used.reset();
  EXPECT_EQ(used.skipped(), 0u);
  ASSERT_TRUE(same_bits(observe(fresh), observe(used)));
  for (std::size_t k = 0; k < r.v.size(); ++k) {
    fresh.step(r.v[k], r.y[k]);
    used.step(r.v[k], r.y[k]);
    ASSERT_TRUE(same_bits(observe(fresh), observe(used))) << "sample " << k;
  }
}

TYPED_TEST(EstimatorInvariants, NothingIdentifiedBeforeEnoughUpdates) {
  EstimatorConfig c = config_for<TypeParam>();
  TypeParam e(c);
  const auto& r = this->rec;
  auto none_yet = [&](const char* when) {
    for (Side s : {Side::right, Side::left}) {
      const SideParams p = e.params(s);
      EXPECT_FALSE(p.identified) << when;
      EXPECT_EQ(p.reason, Reason::not_updated) << when;
      EXPECT_EQ(e.verdict(s), Reason::not_updated) << when;
      EXPECT_TRUE(std::isnan(p.a1) && std::isnan(p.b1) && std::isnan(p.c)) << when;
    }
    EXPECT_FALSE(e.identified()) << when;
  };
  none_yet("before any sample");
  // fewer samples than min_updates: no key can have min_updates updates yet
  for (std::size_t k = 0; k + 1 < c.min_updates; ++k) e.step(r.v[k], r.y[k]);
  none_yet("after min_updates - 1 samples");
}

TYPED_TEST(EstimatorInvariants, Deterministic) {
  TypeParam a(config_for<TypeParam>()), b(config_for<TypeParam>());
  const auto& r = this->rec;
  for (std::size_t k = 0; k < r.v.size(); ++k) {
    a.step(r.v[k], r.y[k]);
    b.step(r.v[k], r.y[k]);
    ASSERT_TRUE(same_bits(observe(a), observe(b))) << "sample " << k;
  }
}

TYPED_TEST(EstimatorInvariants, NoHeapAllocationInUpdate) {
  TypeParam e(config_for<TypeParam>());
  const auto& r = this->rec;
  const std::size_t before = g_allocations.load();
  double sink = 0.0;
  for (std::size_t k = 0; k < r.v.size(); ++k) {
    sink += e.step(r.v[k], r.y[k]);
    sink += e.simulated();
    const SideParams p = e.params(k % 2 ? Side::right : Side::left);
    sink += p.identified ? 1.0 : 0.0;
    sink += static_cast<double>(e.verdict(Side::right));
  }
  e.step(kNaN, 0.0);
  const std::size_t after = g_allocations.load();
  EXPECT_EQ(after - before, 0u) << "heap allocations inside step()/params()/verdict()";
  // the counter works: a vector allocates
  std::vector<double> probe(16, sink);
  EXPECT_GT(g_allocations.load(), after);
}

// restart() after a gap: the parameters, covariances and counts stay; the signal history goes.
/// The parameter side of observe(): what restart() must keep (not ŷ, y_sim or the fit verdict).
template <class E>
std::vector<double> estimates(const E& e) {
  std::vector<double> o;
  for (Side s : {Side::right, Side::left}) {
    const SideParams p = e.params(s);
    o.insert(o.end(), {p.a1, p.b1, p.c, p.d, static_cast<double>(p.reason), static_cast<double>(e.updates(s))});
  }
  return o;
}

TYPED_TEST(EstimatorInvariants, RestartKeepsEstimatesAndClearsTheSignalHistory) {
  TypeParam a(config_for<TypeParam>()), b(config_for<TypeParam>());
  static_assert(noexcept(a.restart()), "restart() must be noexcept");
  const auto& r = this->rec;
  for (std::size_t k = 0; k < 3000; ++k) {
    a.step(r.v[k], r.y[k]);
    b.step(r.v[k], r.y[k]);
  }
  const std::vector<double> before = estimates(a);
  const std::size_t allocs = g_allocations.load();
  a.restart();
  b.restart();
  EXPECT_EQ(g_allocations.load(), allocs) << "restart() allocated";
  ASSERT_TRUE(same_bits(estimates(a), before)) << "restart() changed an estimate";
  ASSERT_GE(b.warmup(), 3u);
  // b sees junk for less than its warm-up: nothing may be updated from it, and after a second
  // restart() nothing of it may remain — b then follows a bit for bit.
  for (std::uint32_t k = 0; k + 1 < b.warmup(); ++k) b.step(5000.0 * (k % 2 ? 1.0 : -1.0), -700.0 * k);
  ASSERT_TRUE(same_bits(estimates(b), before)) << "a sample of the warm-up updated an estimate";
  b.restart();
  for (std::size_t k = 3000; k < r.v.size(); ++k) {
    const double ya = a.step(r.v[k], r.y[k]), yb = b.step(r.v[k], r.y[k]);
    ASSERT_TRUE(same_bits({ya}, {yb})) << "sample " << k;
    ASSERT_TRUE(same_bits(estimates(a), estimates(b))) << "sample " << k;
  }
  EXPECT_GT(a.updates(Side::right) + a.updates(Side::left), static_cast<std::uint64_t>(before[5] + before[11]))
      << "updates resume after the warm-up";
}

// Verdict check 2 reads the regressors of the updates; those of the record's first samples still
// hold a moving average's zero initial state. A constant input through MA4 (v and y filtered, as
// lash chooses for a quantised output) ramps 0, 1, 2, 3, 4 V over them: without skipping them as
// evidence the side looked excited (reason unphysical instead of not_excited). Hand-made record:
// v = 4 V throughout, y an encoder velocity alternating between two counts per sample.
TEST(Verdict, ConstantInputThroughAMovingAverageIsNotExcited) {
  EstimatorConfig c(ModelKind::output_deadzone, 0.001);
  c.noise.filter_length = 4;
  c.noise.filter_input = true;
  OutputDeadzoneEstimator con(c), var(c);
  for (int k = 0; k < 5000; ++k) {
    const double y = (k % 3 == 0 ? 126.0 : 127.0) * 3e-3;  // [m/s]: counts of 3 µm per 1 ms
    con.step(4.0, y);
    var.step(k % 1000 < 500 ? 4.0 : 4.5, y);  // the same output, an input that does vary
  }
  EXPECT_GT(con.updates(Side::right), 4000u);
  EXPECT_EQ(con.params(Side::right).reason, Reason::not_excited);
  EXPECT_NE(var.params(Side::right).reason, Reason::not_excited);  // the check still sees a varying v
}

// verdict_rules: the order of the checks and the condition test, with hand-made cases.
TEST(Verdict, ChecksInOrder) {
  verdict_rules::Evidence e;
  e.side = Side::right;
  EXPECT_EQ(verdict_rules::judge(e), Reason::not_updated);
  e.updated = true;
  EXPECT_EQ(verdict_rules::judge(e), Reason::not_excited);
  e.excited = true;
  e.a1 = -1.2;
  e.b1 = 0.1;
  EXPECT_EQ(verdict_rules::judge(e), Reason::unstable);
  e.a1 = -0.96;
  e.b1 = -0.1;
  EXPECT_EQ(verdict_rules::judge(e), Reason::unphysical);  // b1 <= 0
  e.b1 = 0.1;
  e.has_c = true;
  e.c = -5.0;
  EXPECT_EQ(verdict_rules::judge(e), Reason::unphysical);  // right edge below zero
  e.c = 200.0;
  e.has_d = true;
  e.d = -1.0;
  EXPECT_EQ(verdict_rules::judge(e), Reason::unphysical);  // negative deadband
  e.d = 30.0;
  e.guess_ok = false;
  EXPECT_EQ(verdict_rules::judge(e), Reason::wrong_guess);
  e.guess_ok = true;
  EXPECT_EQ(verdict_rules::judge(e), Reason::none);
  e.negative_a1 = true;
  e.a1 = 0.5;
  EXPECT_EQ(verdict_rules::judge(e), Reason::unphysical);  // coupled carts: no positive tau
  EXPECT_EQ(verdict_rules::finish(Reason::none, true, 0.25, 0.2), Reason::poor_fit);
  EXPECT_EQ(verdict_rules::finish(Reason::none, true, 0.15, 0.2), Reason::none);
  EXPECT_EQ(verdict_rules::finish(Reason::none, true, kNaN, 0.2), Reason::none);
  EXPECT_EQ(verdict_rules::finish(Reason::none, false, 0.15, 0.2), Reason::not_excited);
  EXPECT_EQ(verdict_rules::finish(Reason::wrong_guess, false, 0.5, 0.2), Reason::wrong_guess);
  EXPECT_STREQ(to_string(Reason::poor_fit), "poor_fit");
}

TEST(Verdict, ConditionOfTheInformationMatrix) {
  // Information M = [[4, b], [b, 9]], P = M⁻¹ = [[9, −b], [−b, 4]] / (36 − b²). P scaled to
  // unit diagonal is [[1, −r], [−r, 1]] with r = b/6: eigenvalues 1 ± r, the smallest 1 − r.
  auto P_of = [](double b) {
    const double det = 36.0 - b * b;
    return std::array<std::array<double, 2>, 2>{{{9.0 / det, -b / det}, {-b / det, 4.0 / det}}};
  };
  EXPECT_TRUE(verdict_rules::well_conditioned<2>(P_of(5.4)));                // r = 0.9: min eigenvalue 0.1
  EXPECT_FALSE(verdict_rules::well_conditioned<2>(P_of(6.0 * (1 - 1e-12))));  // 1e-12 < 1e-10
  std::array<std::array<double, 2>, 2> bad{{{kNaN, 0.0}, {0.0, 1.0}}};
  EXPECT_FALSE(verdict_rules::well_conditioned<2>(bad));
  // 3×3 identity: perfectly conditioned
  std::array<std::array<double, 3>, 3> id{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  EXPECT_TRUE(verdict_rules::well_conditioned<3>(id));
}

}  // namespace
}  // namespace lash
