// The kernels that answer a rod's kind, closed ring or open rod (rod/rod_set.hpp: wraps, links,
// along / before / after, point_before / point_after, arc_separation, arc_distance): each against
// a direct computation, on rings and open rods of every size from 0 (1 for the walks) to 9, the
// n = 2 and n = 3 edge cases among them.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "rod/rod_set.hpp"

namespace ibrod::rod {
namespace {

RodRange range(int n, bool closed, int offset = 0) { return {offset, n, closed, 3.4}; }

// The point o steps from k by single steps: round a ring (n − 1 → 0 and back), stopping (−1) at an
// open rod's end.
int walk(int n, bool closed, int k, int o) {
  for (int s = 0; s < (o < 0 ? -o : o); ++s) {
    k += o < 0 ? -1 : 1;
    if (k < 0 || k >= n) {
      if (!closed) return -1;
      k = k < 0 ? n - 1 : 0;
    }
  }
  return k;
}

// The fewest single steps from i to j either way along the rod (never round an open rod's ends).
int fewest_steps(int n, bool closed, int i, int j) {
  for (int s = 0; s < n; ++s)
    if (walk(n, closed, i, s) == j || walk(n, closed, i, -s) == j) return s;
  return -1;
}

TEST(RodKinds, WrapsIsTheRing) {
  EXPECT_TRUE(wraps(range(5, true)));
  EXPECT_FALSE(wraps(range(5, false)));
  EXPECT_TRUE(wraps(RodRange{}));  // the default layout is a ring
}

TEST(RodKinds, LinksAreTheSegmentsBetweenNeighbours) {
  for (bool closed : {true, false})
    for (int n = 0; n <= 9; ++n) {
      // a link k → k+1 for every point k whose next point exists (a ring's last: back to 0)
      int direct = 0;
      for (int k = 0; k < n; ++k)
        if (walk(n, closed, k, 1) >= 0) ++direct;
      EXPECT_EQ(links(range(n, closed)), direct) << "n " << n << " closed " << closed;
      EXPECT_EQ(links(range(n, closed)), half_points(n, closed));
      RodParams p;
      p.n = n;
      p.closed = closed;
      EXPECT_EQ(links(p), direct);
    }
  EXPECT_EQ(links(range(2, true)), 2);  // a ring of 2: there and back
  EXPECT_EQ(links(range(2, false)), 1);
  EXPECT_EQ(links(range(3, true)), 3);
  EXPECT_EQ(links(range(3, false)), 2);
}

TEST(RodKinds, AlongWalksRoundARingAndStopsAtAnOpenEnd) {
  for (bool closed : {true, false})
    for (int n = 1; n <= 9; ++n)
      for (int k = 0; k < n; ++k)
        for (int o = -2 * n - 1; o <= 2 * n + 1; ++o) {
          const RodRange g = range(n, closed, 100);  // the offset is not the kernels' business
          EXPECT_EQ(along(g, k, o), walk(n, closed, k, o))
              << "n " << n << " closed " << closed << " k " << k << " o " << o;
        }
}

TEST(RodKinds, BeforeAndAfterAreOneStep) {
  for (bool closed : {true, false})
    for (int n = 1; n <= 9; ++n)
      for (int k = 0; k < n; ++k) {
        const RodRange g = range(n, closed);
        EXPECT_EQ(before(g, k), walk(n, closed, k, -1));
        EXPECT_EQ(after(g, k), walk(n, closed, k, 1));
      }
  // the edge cases spelled out: a ring of 2 has the other point on both sides
  EXPECT_EQ(before(range(2, true), 0), 1);
  EXPECT_EQ(after(range(2, true), 0), 1);
  EXPECT_EQ(before(range(2, false), 0), -1);
  EXPECT_EQ(after(range(2, false), 1), -1);
  EXPECT_EQ(before(range(3, true), 0), 2);
  EXPECT_EQ(after(range(3, true), 2), 0);
}

TEST(RodKinds, CentralDifferencePointsAreOneSidedAtOpenEnds) {
  for (bool closed : {true, false})
    for (int n = 1; n <= 9; ++n)
      for (int k = 0; k < n; ++k) {
        const RodRange g = range(n, closed);
        const int b = walk(n, closed, k, -1), a = walk(n, closed, k, 1);
        EXPECT_EQ(point_before(g, k), b >= 0 ? b : k);
        EXPECT_EQ(point_after(g, k), a >= 0 ? a : k);
        EXPECT_EQ(point_before(g, k), point_before(k, n, closed));
        EXPECT_EQ(point_after(g, k), point_after(k, n, closed));
      }
}

TEST(RodKinds, ArcSeparationIsTheFewestStepsAlongTheRod) {
  for (bool closed : {true, false})
    for (int n = 1; n <= 9; ++n)
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const RodRange g = range(n, closed);
          EXPECT_EQ(arc_separation(g, i, j), fewest_steps(n, closed, i, j))
              << "n " << n << " closed " << closed << " i " << i << " j " << j;
          EXPECT_EQ(arc_separation(g, i, j), arc_separation(g, j, i));
        }
  EXPECT_EQ(arc_separation(range(3, true), 0, 2), 1);  // round the ring
  EXPECT_EQ(arc_separation(range(3, false), 0, 2), 2);
  EXPECT_EQ(arc_separation(range(2, true), 0, 1), 1);
}

TEST(RodKinds, ArcDistanceIsTheShorterWayAlongTheLinks) {
  // uneven links: the length walked link by link from point i to point j either way (an open rod:
  // the one way there is), against arc_distance of their arc lengths from point 0
  for (bool closed : {true, false})
    for (int n = 2; n <= 9; ++n) {
      const RodRange g = range(n, closed);
      std::vector<double> len(std::size_t(links(g)));
      for (std::size_t h = 0; h < len.size(); ++h) len[h] = 1.0 + 0.37 * double(h % 3) + 0.05 * h;
      double total = 0;
      for (double l : len) total += l;
      std::vector<double> arc(std::size_t(n), 0.0);  // from point 0, forward
      for (int k = 1; k < n; ++k)
        arc[std::size_t(k)] = arc[std::size_t(k - 1)] + len[std::size_t(k - 1)];
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          // the length walked from i to j by steps of +1 or −1; −1: an open rod's end in the way
          const auto walked = [&](int step) {
            double l = 0;
            for (int k = i; k != j;) {
              const int next = along(g, k, step);
              if (next < 0) return -1.0;
              l += len.at(std::size_t(step > 0 ? k : next));  // the link between k and next
              k = next;
            }
            return l;
          };
          const double forward = walked(1), backward = walked(-1);
          const double direct = forward < 0    ? backward
                                : backward < 0 ? forward
                                               : std::min(forward, backward);
          EXPECT_NEAR(arc_distance(g, arc[std::size_t(i)], arc[std::size_t(j)], total), direct,
                      1e-12)
              << "n " << n << " closed " << closed << " i " << i << " j " << j;
        }
    }
}

}  // namespace
}  // namespace ibrod::rod
