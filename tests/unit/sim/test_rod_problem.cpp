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
namespace {
// A ring of 10 points Δs apart in the z = 0 plane with triads D¹ = z, D² = outward, D³ = D¹ × D²
// along the tangent (turned by `twist` about it), centred at `centre`.
rod::RodState ring(double ds, double twist = 0, const Vec3& centre = Vec3::Zero()) {
  const double r = ds / (2 * std::sin(M_PI / 10));
  rod::RodState s;
  for (int k = 0; k < 10; ++k) {
    const double th = 2 * M_PI * k / 10;
    s.X.push_back(centre + Vec3(r * std::cos(th), r * std::sin(th), 0));
    Mat3 D;
    D.col(0) = Vec3(0, 0, 1);
    D.col(1) = Vec3(std::cos(th), std::sin(th), 0);
    D.col(2) = D.col(0).cross(D.col(1));
    s.D.push_back(rotation(twist * k * D.col(2)) * D);
  }
  return s;
}
}  // namespace

TEST(RodProblem, AStateMustHaveTheRodsPointsAndRightHandedTriads) {
  const double ds = 3.4;
  const rod::RodState s = ring(ds, 0.1);
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

// T3-11 (issue 26): an orthonormal, right-handed triad whose rows and columns were swapped passed
// every check above, and the run blew up at its first step blaming Δt. D³ must lie along the rod.
TEST(RodProblem, AStateWithD3OffTheTangentIsRefusedNamingThePoint) {
  const double ds = 3.4;
  const rod::RodState s = ring(ds, 0.3);
  ASSERT_EQ(sim::state_problem(s, 10, ds), "");
  rod::RodState swapped = s;
  for (Mat3& D : swapped.D) D.transposeInPlace();
  EXPECT_EQ(sim::rod_problem(swapped, ds), "");  // orthonormal: the per-step check passes it
  EXPECT_THAT(sim::state_problem(swapped, 10, ds), HasSubstr("off the rod's tangent"));
  // a sheared triad within 60° is a state, not an error; past it one point is named
  rod::RodState sheared = s;
  sheared.D[4] = rotation(Vec3(0, 0, 1) * (50 * M_PI / 180)) * sheared.D[4];
  EXPECT_EQ(sim::state_problem(sheared, 10, ds), "");
  sheared.D[4] = rotation(Vec3(0, 0, 1) * (25 * M_PI / 180)) * sheared.D[4];
  EXPECT_THAT(sim::state_problem(sheared, 10, ds), HasSubstr("point 4 has D³ 75° off"));
}

// T3-12 (issue 26): two rods placed on each other's periodic image ran through each other; the
// start check sees the periodic box.
TEST(RodProblem, TwoRodsOnEachOthersPeriodicImageOverlap) {
  const double ds = 3.4, box = 200;
  rod::RodParams p;
  p.n = 10;
  p.ds = ds;
  const std::vector<rod::RodParams> rods{p, p};
  rod::RodState both = ring(ds, 0, Vec3(100, 100, 100));
  const rod::RodState image = ring(ds, 0, Vec3(100 + box, 100, 100));
  both.X.insert(both.X.end(), image.X.begin(), image.X.end());
  both.D.insert(both.D.end(), image.D.begin(), image.D.end());
  EXPECT_EQ(sim::rods_state_problem(rods, both), "");  // unwrapped: 200 Å apart
  EXPECT_THAT(sim::rods_state_problem(rods, both, box), HasSubstr("overlap"));
  EXPECT_THAT(sim::rods_state_problem(rods, both, box), HasSubstr("in the periodic box"));
  EXPECT_EQ(sim::rods_state_problem(rods, both, 2 * box), "");  // a larger box: apart
}

// rod_problem and state_problem of one rod of a state laid out by rod::RodRange: points numbered
// within the rod; an open rod has no link from its last point back to its first.
TEST(RodProblem, ARodOfAStateByItsRangeAndKind) {
  const double ds = 3.4;
  rod::RodState all = ring(ds);  // rod 0: a ring of 10 points; rod 1: 6 points straight along x
  rod::RodState straight;
  for (int k = 0; k < 6; ++k) {
    straight.X.push_back(Vec3(100 + ds * k, 0, 0));
    Mat3 D;
    D.col(0) = Vec3(0, 1, 0);
    D.col(1) = Vec3(0, 0, 1);
    D.col(2) = Vec3(1, 0, 0);
    straight.D.push_back(D);
  }
  all.X.insert(all.X.end(), straight.X.begin(), straight.X.end());
  all.D.insert(all.D.end(), straight.D.begin(), straight.D.end());
  const rod::RodRange ring_range{0, 10, true, ds}, open{10, 6, false, ds}, closed{10, 6, true, ds};
  EXPECT_EQ(sim::rod_problem(all.X, all.D, ring_range, 0.5), "");
  EXPECT_EQ(sim::rod_problem(all.X, all.D, open, 0.5), "");
  // as a ring its closing link is 5 Δs long
  EXPECT_THAT(sim::rod_problem(all.X, all.D, closed, 0.5), HasSubstr("spacing of points 5 and 0"));
  EXPECT_EQ(sim::state_problem(straight, open), "");  // the offset is not read
  EXPECT_THAT(sim::state_problem(straight, closed), HasSubstr("spacing of points 5 and 0"));
  all.X[10 + 3].x() += 2 * ds;
  EXPECT_THAT(sim::rod_problem(all.X, all.D, open, 0.5), HasSubstr("spacing of points 2 and 3"));
  EXPECT_EQ(sim::rod_problem(all.X, all.D, ring_range, 0.5), "");  // rod 0 is untouched
}
