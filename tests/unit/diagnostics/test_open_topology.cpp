// Diagnostics of an open rod (issue 17): the twist of an open ribbon, the closest approach by
// |i − j| (not the cyclic distance), the mean spacing over n − 1 edges.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "diagnostics/topology.hpp"

namespace ibrod::diagnostics {
namespace {

constexpr double pi = std::numbers::pi;

TEST(OpenTopology, TwistOfAStraightRibbonIsItsTotalTurn) {
  // d1 turns by ψ(s) = 2.3 turns × s/L (plus a wobble) about a straight axis: Tw = 2.3 exactly
  const int n = 101;
  std::vector<Vec3> X(n), d1(n);
  for (int k = 0; k < n; ++k) {
    const double u = double(k) / (n - 1);
    const double psi = 2 * pi * 2.3 * u + 0.2 * std::sin(2 * pi * u);
    X[k] = Vec3(3.4 * k, 0.0, 0.0);
    d1[k] = Vec3(0.0, std::cos(psi), std::sin(psi));
  }
  EXPECT_NEAR(twist_open(X, d1), 2.3, 1e-12);
}

TEST(OpenTopology, TwistOfAnOpenHelixRibbonFollowsItsTorsion) {
  // a helix of curvature κ and torsion τ with its Frenet normal as d1: the ribbon does not turn
  // relative to parallel transport beyond the torsion, Tw = τ L / 2π (to O(Δs²))
  const double kappa = 0.02, tau = 0.015, ds = 1.0;
  const double w = std::hypot(kappa, tau), r = kappa / (w * w), c = tau / (w * w);
  const int n = 2001;
  std::vector<Vec3> X(n), d1(n);
  for (int k = 0; k < n; ++k) {
    const double t = w * k * ds;
    X[k] = Vec3(r * std::cos(t), r * std::sin(t), c * t);
    d1[k] = Vec3(-std::cos(t), -std::sin(t), 0.0);  // the principal normal
  }
  const double expected = tau * (n - 1) * ds / (2 * pi);
  EXPECT_NEAR(twist_open(X, d1), expected, 1e-3 * expected);
}

TEST(OpenTopology, ClosestApproachAndSpacingUseTheOpenIndexDistance) {
  // a U: points 0 … 49 along x, 50 … 99 back 10 Å away; ends 0 and 99 are 10 Å apart but only
  // 1 apart cyclically
  std::vector<Vec3> X(100);
  for (int k = 0; k < 50; ++k) X[k] = Vec3(3.0 * k, 0.0, 0.0);
  for (int k = 50; k < 100; ++k) X[k] = Vec3(3.0 * (99 - k), 10.0, 0.0);
  const ClosestPair open = closest_pair(X, 60, false);
  EXPECT_NEAR(open.distance, 10.0, 1e-12);  // e.g. 19 and 80, |i − j| = 61 ≥ 60
  EXPECT_GE(open.j - open.i, 60);
  EXPECT_TRUE(std::isinf(closest_approach(X, 60, true)));  // cyclic distance ≤ 50 < 60
  EXPECT_NEAR(mean_spacing(X, false), (98 * 3.0 + 10.0) / 99, 1e-12);
  EXPECT_NEAR(mean_spacing(X, true), (98 * 3.0 + 10.0 + 10.0) / 100, 1e-12);
}

}  // namespace
}  // namespace ibrod::diagnostics
