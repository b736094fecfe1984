// sim::rod_problem: the per-step sanity check of the rod names the point and the quantity.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/types.hpp"
#include "sim/rod_problem.hpp"

using namespace ibrod;
using ::testing::HasSubstr;

TEST(RodProblem, NamesThePointAndTheQuantity) {
  // a ring of 10 points at spacing Δs with orthonormal triads
  const double ds = 3.4, r = ds / (2 * std::sin(M_PI / 10));
  rod::RodState s;
  for (int k = 0; k < 10; ++k) {
    s.X.push_back(Vec3(r * std::cos(2 * M_PI * k / 10), r * std::sin(2 * M_PI * k / 10), 0));
    s.D.push_back(rotation(Vec3(0, 0, 0.1 * k)));
  }
  EXPECT_EQ(sim::rod_problem(s, ds), "");

  rod::RodState nan = s;
  nan.X[3][1] = std::nan("");
  EXPECT_THAT(sim::rod_problem(nan, ds), HasSubstr("position of point 3 is not finite"));
  rod::RodState stretched = s;
  stretched.X[4] *= 2.0;  // moves point 4 outwards by r = 5.5 Å = 1.6 Δs
  EXPECT_THAT(sim::rod_problem(stretched, ds), HasSubstr("spacing of points 3 and 4"));
  rod::RodState skew = s;
  skew.D[6](0, 1) += 0.01;
  EXPECT_THAT(sim::rod_problem(skew, ds), HasSubstr("triad of point 6 is off orthonormal"));
}

// sim::state_problem: what an initial shape or a state set from Python must be, besides sane.
TEST(RodProblem, AStateMustHaveTheRodsPointsAndRightHandedTriads) {
  const double ds = 3.4, r = ds / (2 * std::sin(M_PI / 10));
  rod::RodState s;
  for (int k = 0; k < 10; ++k) {
    s.X.push_back(Vec3(r * std::cos(2 * M_PI * k / 10), r * std::sin(2 * M_PI * k / 10), 0));
    s.D.push_back(rotation(Vec3(0, 0, 0.1 * k)));
  }
  EXPECT_EQ(sim::state_problem(s, 10, ds), "");
  EXPECT_THAT(sim::state_problem(s, 12, ds), HasSubstr("10 positions and 10 triads"));
  EXPECT_THAT(sim::state_problem(s, 12, ds), HasSubstr("12 points (rod.base_pairs)"));
  rod::RodState fewer = s;
  fewer.D.pop_back();
  EXPECT_THAT(sim::state_problem(fewer, 10, ds), HasSubstr("9 triads"));
  rod::RodState mirrored = s;
  mirrored.D[2].col(2) *= -1;  // orthonormal, but D³ = −D¹ × D²
  EXPECT_EQ(sim::rod_problem(mirrored, ds), "");
  EXPECT_THAT(sim::state_problem(mirrored, 10, ds), HasSubstr("point 2 is left-handed"));
  rod::RodState gap = s;
  gap.X[5] *= 2.0;  // 2.1 Δs from point 4: a spacing the run would call a blow-up
  EXPECT_THAT(sim::state_problem(gap, 10, ds), HasSubstr("spacing of points 4 and 5"));
}

// With per-link moduli (rod.moduli_file) the thermal spacing tolerance follows the softest link
// in use: one link 100× softer in stretch widens it 10×; an open rod's last row (no link) does not.
TEST(SpacingTolerance, FollowsTheSoftestLinkInUse) {
  rod::RodParams p;
  p.n = 50;
  const double kT = 414.2;
  const double base = sim::spacing_tolerance(p, 1e3 * kT);  // thermal: above the 0.5 floor
  ASSERT_GT(base, 0.5);
  p.a_k.assign(p.n, p.a);
  p.b_k.assign(p.n, p.b);
  EXPECT_EQ(sim::spacing_tolerance(p, 1e3 * kT), base);
  p.b_k[p.n - 1].z() /= 100;
  EXPECT_NEAR(sim::spacing_tolerance(p, 1e3 * kT), 10 * base, 1e-9 * base);
  p.closed = false;  // the last row is not a link of the open rod
  EXPECT_EQ(sim::spacing_tolerance(p, 1e3 * kT), base);
  p.b_k[3].x() /= 100;
  EXPECT_NEAR(sim::spacing_tolerance(p, 1e3 * kT), 10 * base, 1e-9 * base);
}
