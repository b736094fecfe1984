// The rod collection's operations (rod/rod_set.hpp): what callers outside src/rod take instead of
// asking how many rods there are (ARCHITECTURE.md).
#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "rod/rod_set.hpp"

namespace ibrod::rod {
namespace {

TEST(RodSet, RangesLieEndToEndAndForEachRangeAgreesWithRangesOf) {
  std::vector<RodParams> p(3);
  p[0].n = 10;
  p[1].n = 7;
  p[1].closed = false;
  p[2].n = 4;
  p[2].ds = 2.0;
  const std::vector<RodRange> g = ranges_of(p);
  std::vector<RodRange> h;
  for_each_range(p, [&](std::size_t r, const RodRange& x) {
    EXPECT_EQ(r, h.size());
    h.push_back(x);
  });
  ASSERT_EQ(h.size(), 3u);
  for (std::size_t r = 0; r < 3; ++r) {
    EXPECT_EQ(h[r].offset, g[r].offset);
    EXPECT_EQ(h[r].n, g[r].n);
    EXPECT_EQ(h[r].closed, g[r].closed);
    EXPECT_EQ(h[r].ds, g[r].ds);
  }
  EXPECT_EQ(g[2].offset, 17);
  EXPECT_EQ(total_points(g), 21);
  EXPECT_EQ(total_points(p), 21);
}

TEST(RodSet, PairsInTheOrderOfThePairLinks) {
  const std::vector<RodRange> three = {{0, 5}, {5, 5}, {10, 5}};
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for_each_pair(three, [&](std::size_t a, std::size_t b) { pairs.push_back({a, b}); });
  const std::vector<std::pair<std::size_t, std::size_t>> want = {{0, 1}, {0, 2}, {1, 2}};
  EXPECT_EQ(pairs, want);
  int none = 0;
  for_each_pair(std::vector<RodRange>{{0, 5}}, [&](std::size_t, std::size_t) { ++none; });
  EXPECT_EQ(none, 0);  // a collection of one has no pairs
}

TEST(RodSet, OnlyACollectionOfSeveralNamesItsRods) {
  const std::vector<RodRange> one = {{0, 12, true}};
  const std::vector<RodRange> two = {{0, 12, true}, {12, 8, false}};
  EXPECT_FALSE(names_rods(one));
  EXPECT_TRUE(names_rods(two));
  EXPECT_EQ(message_prefix(one, 0), "");
  EXPECT_EQ(message_prefix(two, 1), "rod 1: ");
  EXPECT_EQ(describe(two), "20 rod points (rods: 2)");
  EXPECT_EQ(count_label(two), "2 rods");
  EXPECT_TRUE(one_ring(one));
  EXPECT_FALSE(one_ring(two));
  EXPECT_FALSE(one_ring(std::vector<RodRange>{{0, 12, false}}));  // an open rod
}

}  // namespace
}  // namespace ibrod::rod
