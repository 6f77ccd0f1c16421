// The re-guessing rules of identify/reguess.hpp against hand computations (docs/method.md §A4.8).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "lash/identify/reguess.hpp"

using namespace lash;

// out: wrong_guess on 50 updates in a row moves the guess halfway to the furthest command:
// 100 + 0.5·(200 − 100) = 150 (left: the mirror, −150).
TEST(Reguess, OutRuleAfterConfirmedWrongGuess) {
  for (const Side s : {Side::right, Side::left}) {
    const double sg = s == Side::right ? 1.0 : -1.0;
    SideReguess r(s, sg * 100.0, ReguessSettings{}, 0.01);
    for (int k = 0; k < 49; ++k) ASSERT_FALSE(r.step(sg * 200.0, true, Reason::wrong_guess, sg * 90.0));
    ASSERT_TRUE(r.step(sg * 200.0, true, Reason::wrong_guess, sg * 90.0));
    EXPECT_DOUBLE_EQ(r.guess(), sg * 150.0);
    EXPECT_DOUBLE_EQ(r.last_old_guess(), sg * 100.0);
    EXPECT_EQ(r.last_rule(), ReguessRule::out);
    EXPECT_EQ(r.count(ReguessRule::out), 1u);
  }
}

// A run broken by an update with another reason starts again.
TEST(Reguess, OutRuleNeedsARun) {
  SideReguess r(Side::right, 100.0, ReguessSettings{}, 0.01);
  for (int k = 0; k < 49; ++k) ASSERT_FALSE(r.step(200.0, true, Reason::wrong_guess, 90.0));
  ASSERT_FALSE(r.step(200.0, true, Reason::not_excited, 90.0));
  for (int k = 0; k < 49; ++k) ASSERT_FALSE(r.step(200.0, true, Reason::wrong_guess, 90.0));
  EXPECT_EQ(r.count(), 0u);
}

// in: the edge 185, the command 465, the guess 450 > 185 + 0.8·280 = 409: after one memory (4 s =
// 400 samples at 10 ms) the guess moves to 185 + 0.5·280 = 325; there (325 < 409) it stays.
TEST(Reguess, InRuleAndItsFixedPoint) {
  SideReguess r(Side::right, 450.0, ReguessSettings{}, 0.01);
  for (int k = 0; k < 399; ++k) ASSERT_FALSE(r.step(465.0, false, Reason::not_updated, 185.0)) << k;
  ASSERT_TRUE(r.step(465.0, false, Reason::not_updated, 185.0));
  EXPECT_DOUBLE_EQ(r.guess(), 325.0);
  EXPECT_EQ(r.last_rule(), ReguessRule::in);
  for (int k = 0; k < 10000; ++k) ASSERT_FALSE(r.step(465.0, k % 3 == 0, Reason::none, 185.0));
  EXPECT_EQ(r.count(), 1u);
}

// No edge estimate (NaN): the in rule waits; disabled: nothing moves.
TEST(Reguess, NoEvidenceNoMove) {
  SideReguess r(Side::right, 450.0, ReguessSettings{}, 0.01);
  for (int k = 0; k < 2000; ++k) ASSERT_FALSE(r.step(465.0, false, Reason::not_updated, std::nan("")));
  ReguessSettings off;
  off.enabled = false;
  SideReguess o(Side::right, 100.0, off, 0.01);
  for (int k = 0; k < 2000; ++k) ASSERT_FALSE(o.step(200.0, true, Reason::wrong_guess, 90.0));
  EXPECT_THROW([] { ReguessSettings b; b.reach_fraction = 0.4; b.validate(); }(), std::invalid_argument);
}
