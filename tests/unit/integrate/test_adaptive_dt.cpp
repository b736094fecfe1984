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

}  // namespace
}  // namespace ibrod::integrate
