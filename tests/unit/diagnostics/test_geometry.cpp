// Closest approach and mean spacing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <vector>

#include "curves.hpp"
#include "diagnostics/topology.hpp"

namespace ibrod::diagnostics {
namespace {

using namespace testing;

TEST(ClosestApproach, CircleIsTheChordOverMinSeparation) {
  const int n = 600;
  const double R = 170.0;
  const auto X = circle(n, R);
  const auto cp = closest_pair(X, 20);
  EXPECT_NEAR(cp.distance, 2 * R * std::sin(pi * 20 / n), 1e-10);
  EXPECT_EQ(std::min(cp.j - cp.i, n - (cp.j - cp.i)), 20);
  EXPECT_NEAR(closest_approach(X, 20), cp.distance, 0.0);
  EXPECT_NEAR(mean_spacing(X), 2 * R * std::sin(pi / n), 1e-12);
}

TEST(ClosestApproach, FigureEightWithAKnownGap) {
  // Lemniscate of Gerono lifted out of its plane: X(t) = (sin t, sin t cos t, h cos t). The two
  // passes through the crossing, t = 0 and t = π, are 2h apart, and no other non-local pair is
  // closer (|X(δ) − X(π+δ′)|² = 4h² + (2 − h²)(δ² + δ′²) + O(δ³)).
  const int n = 600;
  const double h = 0.05;
  std::vector<Vec3> X(n);
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    X[k] = Vec3(std::sin(t), std::sin(t) * std::cos(t), h * std::cos(t));
  }
  const auto cp = closest_pair(X, 20);
  EXPECT_NEAR(cp.distance, 2 * h, 1e-12);
  EXPECT_EQ(cp.i, 0);
  EXPECT_EQ(cp.j, n / 2);
}

TEST(ClosestApproach, MatchesBruteForceOverAllSeparations) {
  // The oracle visits every ordered pair and computes the cyclic distance with a modulo.
  std::mt19937_64 rng(9);
  const int n = 600;
  const auto X = random_fourier_curve(rng, 5).sample(n);
  for (int m : {-3, 0, 1, 2, 20, 151, 299, 300, 301}) {
    double best = std::numeric_limits<double>::infinity();
    const int mm = std::max(m, 1);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const int d = std::abs(i - j) % n;
        if (std::min(d, n - d) >= mm) best = std::min(best, (X[i] - X[j]).norm());
      }
    const double got = closest_approach(X, m);
    if (std::isinf(best)) {
      EXPECT_TRUE(std::isinf(got)) << "m = " << m;
      EXPECT_EQ(closest_pair(X, m).i, -1);
    } else {
      EXPECT_EQ(got, best) << "m = " << m;
    }
  }
}

TEST(MeanSpacing, Rectangle) {
  const std::vector<Vec3> X = {{0, 0, 0}, {1, 0, 0}, {1, 3, 0}, {0, 3, 0}};
  EXPECT_DOUBLE_EQ(mean_spacing(X), 2.0);
}

}  // namespace
}  // namespace ibrod::diagnostics
