// Issue 30, "tell the user what to do": side_advice (identify/estimate_report.hpp) on hand-made
// runs — the counts it prints are the report's update counts, and a side identified or failing for
// a reason that is not the input's gets none.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "lash/identify/auto.hpp"
#include "lash/identify/estimate_report.hpp"

using namespace lash;

namespace {
AutoRun run_with(Reason right, std::uint64_t up, std::uint64_t down) {
  AutoRun ar;
  ar.cfg = EstimatorConfig(ModelKind::deadzone_deadband, 0.005);
  EstimateReport& r = ar.run.report;
  r.model = ModelKind::deadzone_deadband;
  r.has_c = r.has_side_d = true;
  r.right.params.reason = right;
  r.right.params.identified = right == Reason::none;
  r.right.updates = {{"+", up}, {"-", down}};
  r.left.params = {-0.97, 0.05, -150.0, 20.0, true, Reason::none};
  r.left.updates = {{"+", 900}, {"-", 800}};
  ar.right = {75.6, GuessSource::searched, false, std::numeric_limits<double>::quiet_NaN()};
  ar.left = {-180.0, GuessSource::searched, false, -150.0};
  return ar;
}
}  // namespace

TEST(Advice, NotUpdatedOneDirection) {
  const AutoRun ar = run_with(Reason::not_updated, 461, 0);
  const SideAdvice a = side_advice(ar, Side::right);
  ASSERT_TRUE(a.given);
  EXPECT_EQ(a.up, 461u);
  EXPECT_EQ(a.down, 0u);
  EXPECT_EQ(a.min_updates, 50u);
  EXPECT_DOUBLE_EQ(a.beyond, 75.6);
  EXPECT_NE(a.text.find("right side: 461 updates moving up beyond +75.6, none moving down (50 needed each way)"),
            std::string::npos)
      << a.text;
  EXPECT_NE(a.text.find("so the output also moves down there"), std::string::npos) << a.text;
  // bounds from the guesses (left: the edge seen / c, 180 > 150) -> a sine over twice them
  EXPECT_DOUBLE_EQ(a.excite_left, -180.0);
  EXPECT_DOUBLE_EQ(a.excite_right, 75.6);
  EXPECT_FALSE(a.from_input);
  EXPECT_NE(a.text.find("e.g. a sine between -360 and 151.2 (lash excite --edges=-180,75.6 --dt 0.005"), std::string::npos)
      << a.text;
  EXPECT_FALSE(side_advice(ar, Side::left).given);  // identified
  // with the record's input range (0.1/99.9 % quantiles -500/+500): half of it as the bounds
  DataTraits d;
  d.v_lo = -500, d.v_hi = 500;
  const SideAdvice b = side_advice(ar, Side::right, &d);
  EXPECT_TRUE(b.from_input);
  EXPECT_DOUBLE_EQ(b.excite_left, -250.0);
  EXPECT_DOUBLE_EQ(b.excite_right, 250.0);
  EXPECT_NE(b.text.find("e.g. a sine between -500 and 500 (lash excite --edges=-250,250"), std::string::npos) << b.text;
  // the JSON carries the same numbers under "advice"
  const auto j = nlohmann::json::parse(estimate_auto_json(ar, Preset::lash, ReportFit{}));
  EXPECT_EQ(j["right"]["advice"]["text"], a.text);
  EXPECT_EQ(j["right"]["advice"]["updates_up"], 461);
  EXPECT_EQ(j["right"]["advice"]["updates_down"], 0);
  EXPECT_EQ(j["right"]["updates"]["+"], 461);
  EXPECT_TRUE(j["left"]["advice"].is_null());
  EXPECT_NE(estimate_auto_text(ar, 0.005, ReportFit{}).find("advice: " + a.text + "\n"), std::string::npos);
}

TEST(Advice, OnlyForTheInputsReasons) {
  for (const Reason r : {Reason::unstable, Reason::unphysical, Reason::poor_fit, Reason::uncertain, Reason::none})
    EXPECT_FALSE(side_advice(run_with(r, 900, 900), Side::right).given) << to_string(r);
  const SideAdvice ne = side_advice(run_with(Reason::not_excited, 900, 900), Side::right);
  ASSERT_TRUE(ne.given);
  EXPECT_NE(ne.text.find("900 updates moving up beyond +75.6, 900 moving down"), std::string::npos) << ne.text;
  EXPECT_NE(ne.text.find("hardly varied"), std::string::npos) << ne.text;
  AutoRun wg = run_with(Reason::none, 900, 900);
  wg.right.wrong_side = true;
  wg.right.edge = 210.0;
  const SideAdvice w = side_advice(wg, Side::right);
  ASSERT_TRUE(w.given);
  EXPECT_NE(w.text.find("the guess +75.6 lies inside the deadzone (edge seen at +210); give --guess-right"),
            std::string::npos)
      << w.text;
  EXPECT_DOUBLE_EQ(w.excite_right, 210.0);
  // the linear model has no sides to advise on
  AutoRun lin = run_with(Reason::not_updated, 0, 0);
  lin.run.report.model = ModelKind::linear;
  EXPECT_FALSE(side_advice(lin, Side::right).given);
}

// Check 8 (ci_tolerance): the advice names the widest judged interval, its half-width over its
// centre, and the record length that would narrow it to the tolerance, (w / tol)^2 x the record
// (intervals narrow as 1/sqrt(length)); by hand: d [28, 32] is 2/30 = 6.667 %, K [2.45, 2.55]
// 2 %, tau 1 %, c 0.5 %; 40 000 samples of 5 ms = 200 s -> 200 x (6.667/5)^2 = 355.6 s.
TEST(Advice, PrecisionNamesTheWidestInterval) {
  AutoRun ar = run_with(Reason::uncertain, 900, 900);
  ar.cfg.ci_tolerance = 0.05;
  ar.run.report.samples = 40000;
  SideIntervals& ci = ar.run.report.right.ci95;
  ci.K = {2.45, 2.55};
  ci.tau_s = {0.099, 0.101};
  ci.c = {199.0, 201.0};
  ci.d = {28.0, 32.0};
  const WidestInterval w = widest_interval(ci, true, true);
  EXPECT_STREQ(w.name, "d");
  EXPECT_NEAR(w.relative, 2.0 / 30.0, 1e-12);
  const SideAdvice a = side_advice(ar, Side::right);
  ASSERT_TRUE(a.given);
  EXPECT_EQ(a.widest, "d");
  EXPECT_NEAR(a.record_s_needed, 200.0 * (2.0 / 30.0 / 0.05) * (2.0 / 30.0 / 0.05), 1e-9);
  EXPECT_NE(a.text.find("right side: the 95 % interval of d is +-6.67 % of its centre, wider than --ci-tolerance 5 %"),
            std::string::npos)
      << a.text;
  EXPECT_NE(a.text.find("about 356 s of the same input (this record: 200 s)"), std::string::npos) << a.text;
  const auto j = nlohmann::json::parse(estimate_auto_json(ar, Preset::lash, ReportFit{}));
  EXPECT_EQ(j["right"]["advice"]["widest_interval"]["parameter"], "d");
  EXPECT_NEAR(j["right"]["advice"]["widest_interval"]["record_s_needed"].get<double>(), a.record_s_needed, 1e-9);
  // no interval computed: named as such, no length suggested
  ar.run.report.right.ci95 = {};
  const SideAdvice n = side_advice(ar, Side::right);
  ASSERT_TRUE(n.given);
  EXPECT_EQ(n.widest, "K");  // the first missing one
  EXPECT_TRUE(std::isinf(n.widest_relative));
  EXPECT_TRUE(std::isnan(n.record_s_needed));
  EXPECT_NE(n.text.find("right side: no 95 % interval"), std::string::npos) << n.text;
  // check 7 (an impossible value) is not a precision matter: no advice
  ar.run.report.right.ci95 = ci;
  ar.run.report.right.ci95.d = {-1.0, 3.0};
  EXPECT_FALSE(side_advice(ar, Side::right).given);
  // without a tolerance an uncertain side gets none (check 7's)
  ar.cfg.ci_tolerance = 0.0;
  ar.run.report.right.ci95 = ci;
  EXPECT_FALSE(side_advice(ar, Side::right).given);
}
