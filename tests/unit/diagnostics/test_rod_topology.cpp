// One rod's topology row of a collection (diagnostics::rod_topology on a rod::RodRange) and
// whether its link is defined (diagnostics::link_defined): against the functions it is made of,
// called directly on the rod's own points, for a ring and an open rod laid end to end, bitwise.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include "diagnostics/topology.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::diagnostics {
namespace {

constexpr double pi = std::numbers::pi;

TEST(RodTopology, LinkIsDefinedForClosedRodsOnly) {
  const rod::RodRange ring{0, 12, true, 3.4}, open{12, 7, false, 3.4};
  EXPECT_TRUE(link_defined(ring));
  EXPECT_FALSE(link_defined(open));
  const std::vector<rod::RodRange> rings = {ring, {12, 5, true, 3.4}};
  const std::vector<rod::RodRange> mixed = {ring, open};
  EXPECT_TRUE(link_defined(std::span<const rod::RodRange>(rings)));
  EXPECT_FALSE(link_defined(std::span<const rod::RodRange>(mixed)));
  EXPECT_TRUE(link_defined(std::span<const rod::RodRange>(rings).first(1)));
  EXPECT_FALSE(link_defined(std::span<const rod::RodRange>(mixed).last(1)));
}

// Two rods end to end in one point list: a wavy ring of 24 points (twisted ribbon), then an open
// wavy rod of 9 points; rod_topology of each range against the direct calls on its points.
TEST(RodTopology, EachRangeEqualsTheDirectCallsOnItsPoints) {
  std::vector<Vec3> X, d1;
  const int nr = 24, no = 9;
  for (int k = 0; k < nr; ++k) {
    const double t = 2 * pi * k / nr;
    X.emplace_back(20 * std::cos(t), 20 * std::sin(t), 3 * std::sin(3 * t));
    d1.emplace_back(std::cos(2 * t) * std::cos(t), std::cos(2 * t) * std::sin(t), std::sin(2 * t));
  }
  for (int k = 0; k < no; ++k) {
    X.emplace_back(100 + 3.4 * k, 2 * std::sin(0.7 * k), std::cos(0.5 * k));
    d1.emplace_back(0.0, std::cos(0.3 * k), std::sin(0.3 * k));
  }
  const std::vector<rod::RodRange> rods = {{0, nr, true, 3.4}, {nr, no, false, 3.4}};
  for (int min_sep : {1, 3}) {
    // the ring
    {
      const RodTopology t = rod_topology(X, d1, rods[0], min_sep);
      const std::span<const Vec3> x = std::span<const Vec3>(X).first(nr);
      const std::span<const Vec3> d = std::span<const Vec3>(d1).first(nr);
      EXPECT_EQ(t.writhe, writhe(x));
      EXPECT_EQ(t.twist, twist(x, d));
      EXPECT_EQ(t.link, writhe(x) + twist(x, d));
      EXPECT_EQ(t.closest, closest_approach(x, min_sep, true));
      EXPECT_EQ(t.spacing, mean_spacing(x, true));
      EXPECT_EQ(t.links, nr);
    }
    // the open rod: no writhe or link, its open twist, distances by |i − j|, n − 1 links
    {
      const RodTopology t = rod_topology(X, d1, rods[1], min_sep);
      const std::span<const Vec3> x = std::span<const Vec3>(X).subspan(nr, no);
      const std::span<const Vec3> d = std::span<const Vec3>(d1).subspan(nr, no);
      EXPECT_TRUE(std::isnan(t.writhe));
      EXPECT_TRUE(std::isnan(t.link));
      EXPECT_EQ(t.twist, twist_open(x, d));
      EXPECT_EQ(t.closest, closest_approach(x, min_sep, false));
      EXPECT_EQ(t.spacing, mean_spacing(x, false));
      EXPECT_EQ(t.links, no - 1);
    }
  }
}

// The smallest rods: a ring of 3 and open rods of 2 and 3 points.
TEST(RodTopology, SmallestRods) {
  const std::vector<Vec3> X = {{0, 0, 0}, {3, 0, 0}, {0, 4, 0}};
  const std::vector<Vec3> d1 = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  const RodTopology ring = rod_topology(X, d1, {0, 3, true, 3.4}, 1);
  EXPECT_EQ(ring.links, 3);
  EXPECT_EQ(ring.spacing, (3.0 + 5.0 + 4.0) / 3);
  EXPECT_EQ(ring.closest, 3.0);
  const RodTopology open3 = rod_topology(X, d1, {0, 3, false, 3.4}, 1);
  EXPECT_EQ(open3.links, 2);
  EXPECT_EQ(open3.spacing, (3.0 + 5.0) / 2);
  EXPECT_TRUE(std::isnan(open3.link));
  const RodTopology open2 = rod_topology(X, d1, {1, 2, false, 3.4}, 1);  // points 1 and 2
  EXPECT_EQ(open2.links, 1);
  EXPECT_EQ(open2.spacing, 5.0);
  EXPECT_EQ(open2.closest, 5.0);
}

}  // namespace
}  // namespace ibrod::diagnostics
