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
