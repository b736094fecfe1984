// Unit tests of the adaptive time-step controller (issue 14): acceptance and rejection rules,
// growth up to dt_max, the floor, bad parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "integrate/adaptive_dt.hpp"

namespace ibrod::integrate {
namespace {

AdaptiveDtParams params() {
  AdaptiveDtParams p;
  p.dt_max = 2e-9;
  p.dt_min = 1e-12;
  p.max_displacement = 1.0;
  p.max_rotation = 0.2;
  p.energy_tolerance = 1e-3;
  p.shrink = 0.5;
  p.grow = 1.25;
  p.grow_after = 3;
  return p;
}

StepOutcome good() {
  StepOutcome o;
  o.max_displacement = 0.1;
  o.max_rotation = 0.01;
  o.energy_change = -1.0;
  return o;
}

TEST(AdaptiveDt, StartsAtTheMaximumAndAcceptsGoodSteps) {
  AdaptiveDt c(params());
  EXPECT_EQ(c.dt(), 2e-9);
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(c.judge(good()));
  EXPECT_EQ(c.dt(), 2e-9);  // never above dt_max
  EXPECT_EQ(c.rejections(), 0);
}

TEST(AdaptiveDt, TooLargeADisplacementRejectsAndShrinksInProportion) {
  AdaptiveDt c(params());
  StepOutcome o = good();
  o.max_displacement = 4.0;  // 4× the limit: the next try is at most 0.9/4 of the step
  EXPECT_FALSE(c.judge(o));
  EXPECT_NEAR(c.dt(), 2e-9 * 0.9 / 4, 1e-20);
  o.max_displacement = 1.5;  // a mild excess still halves (shrink)
  EXPECT_FALSE(c.judge(o));
  EXPECT_NEAR(c.dt(), 2e-9 * 0.9 / 4 * 0.5, 1e-20);
  EXPECT_EQ(c.rejections(), 2);
}

TEST(AdaptiveDt, RotationEnergyConvergenceAndFinitenessEachReject) {
  for (int which = 0; which < 4; ++which) {
    AdaptiveDt c(params());
    StepOutcome o = good();
    if (which == 0) o.max_rotation = 0.3;
    if (which == 1) o.energy_change = 2e-3;  // rise above the tolerance
    if (which == 2) o.converged = false;
    if (which == 3) {
      o.finite = false;
      o.max_displacement = NAN;
    }
    EXPECT_FALSE(c.judge(o)) << which;
    EXPECT_LT(c.dt(), 2e-9) << which;
  }
  AdaptiveDt c(params());
  StepOutcome o = good();
  o.energy_change = 0.5e-3;  // within the tolerance
  EXPECT_TRUE(c.judge(o));
}

TEST(AdaptiveDt, GrowsAfterARunOfGoodStepsUpToTheMaximum) {
  AdaptiveDt c(params(), 1e-10, 0);
  int accepted = 0;
  while (c.dt() < 2e-9 && accepted < 100) {
    ASSERT_TRUE(c.judge(good()));
    ++accepted;
  }
  EXPECT_EQ(c.dt(), 2e-9);
  // 1e-10 → 2e-9 by factors 1.25 every 3 steps: ceil(log(20)/log(1.25)) = 14 growths
  EXPECT_EQ(accepted, 3 * 14);
  // a displacement near the limit (≥ 0.7 of it) holds the step where it is
  AdaptiveDt h(params(), 1e-10, 0);
  StepOutcome o = good();
  o.max_displacement = 0.8;
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(h.judge(o));
  EXPECT_EQ(h.dt(), 1e-10);
}

TEST(AdaptiveDt, AtTheFloorAFiniteStepIsAccepted) {
  AdaptiveDtParams p = params();
  AdaptiveDt c(p, p.dt_min, 0);
  StepOutcome o = good();
  o.energy_change = 1.0;
  EXPECT_TRUE(c.judge(o));
  o.finite = false;
  EXPECT_FALSE(c.judge(o));
  EXPECT_EQ(c.dt(), p.dt_min);
}

TEST(AdaptiveDt, RejectsInconsistentParameters) {
  AdaptiveDtParams p = params();
  p.dt_min = 3e-9;
  EXPECT_THROW(AdaptiveDt{p}, std::invalid_argument);
  p = params();
  p.shrink = 1.0;
  EXPECT_THROW(AdaptiveDt{p}, std::invalid_argument);
  p = params();
  p.max_displacement = 0;
  EXPECT_THROW(AdaptiveDt{p}, std::invalid_argument);
  EXPECT_THROW(AdaptiveDt(params(), 0.0, 0), std::invalid_argument);
}

// ---- error control (issue 24): Δt follows the local error estimate, err ∝ Δt²
TEST(AdaptiveDt, ErrorControlRejectsAboveTheToleranceAndShrinksBySquareRoot) {
  AdaptiveDtParams p = params();
  p.error_tolerance = 0.1;
  AdaptiveDt c(p);
  StepOutcome o = good();
  o.error = 0.4;  // 4× the tolerance: reject, next Δt = 0.9 √(1/4) = 0.45 of the step
  EXPECT_FALSE(c.judge(o));
  EXPECT_NEAR(c.dt(), 2e-9 * 0.45, 1e-20);
  o.error = 100.0;  // never below 0.2 of the step at once
  EXPECT_FALSE(c.judge(o));
  EXPECT_NEAR(c.dt(), 2e-9 * 0.45 * 0.2, 1e-20);
  EXPECT_EQ(c.rejections(), 2);
  // without error control the same estimate is ignored
  AdaptiveDt off(params());
  EXPECT_TRUE(off.judge(o));
}

TEST(AdaptiveDt, ErrorControlGrowsTowardTheToleranceNotPastTheCap) {
  AdaptiveDtParams p = params();
  p.error_tolerance = 0.1;
  p.dt_max = 1e-8;
  AdaptiveDt c(p, 1e-9, 5);
  StepOutcome o = good();
  o.error = 0.1 / 1.44;  // asks for 0.9 × 1.2 = 1.08
  EXPECT_TRUE(c.judge(o));
  EXPECT_NEAR(c.dt(), 1.08e-9, 1e-20);
  o.error = 1e-9;  // asks for a lot: at most grow_max (2)
  EXPECT_TRUE(c.judge(o));
  EXPECT_NEAR(c.dt(), 2.16e-9, 1e-20);
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(c.judge(o));
  EXPECT_EQ(c.dt(), 1e-8);  // dt_max is the cap
  o.error = 0.1;            // at the tolerance: accepted, and Δt shrinks to 0.9
  EXPECT_TRUE(c.judge(o));
  EXPECT_NEAR(c.dt(), 0.9e-8, 1e-20);
}

TEST(AdaptiveDt, ErrorControlAfterARejectionAndForAShortenedStep) {
  AdaptiveDtParams p = params();
  p.error_tolerance = 0.1;
  AdaptiveDt c(p);
  StepOutcome o = good();
  o.error = 0.4;
  EXPECT_FALSE(c.judge(o));  // dt = 0.9e-9
  o.error = 1e-6;            // right after a rejection: accepted, no growth
  EXPECT_TRUE(c.judge(o));
  EXPECT_NEAR(c.dt(), 0.9e-9, 1e-20);
  // a step the caller shortened (o.dt < dt()) keeps dt() unless its own error asks for less
  o.dt = 1e-11;
  EXPECT_TRUE(c.judge(o));
  EXPECT_NEAR(c.dt(), 0.9e-9, 1e-20);
  o.error = 0.1 * 16;  // too large even for the short step: rejected, 0.9/4 of the short step
  EXPECT_FALSE(c.judge(o));
  EXPECT_NEAR(c.dt(), 1e-11 * 0.225, 1e-22);
}

}  // namespace
}  // namespace ibrod::integrate
