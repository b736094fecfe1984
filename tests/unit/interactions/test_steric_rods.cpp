// Steric repulsion between several rods (StericParams::rods): segments of different rods always
// count as a pair, even where their indices are neighbours in the point list (the last point of
// one rod and the first of the next are not a segment); the cell list equals the direct sum and
// an oracle over the rods' own segments; one chain equals the plain closed rod.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "curves.hpp"
#include "interactions/interactions.hpp"

namespace ibrod::interactions {
namespace {

using namespace test;

constexpr double D = 20.0;
constexpr double g = kDefaultStericStiffness;

TEST(StericRods, TwoRodsCellListEqualsDirectAndOracle) {
  // two 100-point strands of a plectoneme (18 Å apart), cut into two open rods
  const auto X = plectoneme(200, kDs, 9.0, 60.0);
  const int n = int(X.size());
  const int half = n / 2;
  StericParams p;
  p.stiffness = g;
  p.ds = mean_spacing(X);
  p.rods = {{0, half, false, p.ds}, {half, n - half, false, p.ds}};
  Steric st(p, n);
  std::vector<Vec3> F(n, Vec3::Zero()), Fd(n, Vec3::Zero());
  const double E = st.accumulate(X, F);
  const double Ed = st.accumulate_direct(X, Fd);
  // oracle: each rod's own pairs more than 2D apart along it, plus every pair across the rods
  double oracle = 0;
  std::array<Vec3, 4> f;
  auto seg = [&](int r, int k) { return std::pair<int, int>{r * half + k, r * half + k + 1}; };
  const int segs[2] = {half - 1, n - half - 1};
  for (int r = 0; r < 2; ++r)
    for (int q = r; q < 2; ++q)
      for (int k = 0; k < segs[r]; ++k)
        for (int l = (q == r ? k + 1 : 0); l < segs[q]; ++l) {
          if (q == r && (l - k) * p.ds <= 2 * D) continue;
          const auto [a0, a1] = seg(r, k);
          const auto [b0, b1] = seg(q, l);
          oracle += steric_pair(D, g, X[a0], X[a1], X[b0], X[b1], f);
        }
  std::printf("  two strands as two rods: E %.6g kT (direct %.6g, oracle %.6g), cells %d\n", E / kT,
              Ed / kT, oracle / kT, int(st.used_cell_list()));
  ASSERT_GT(oracle, 0.0);
  EXPECT_NEAR(E, oracle, 1e-12 * oracle);
  EXPECT_NEAR(Ed, oracle, 1e-12 * oracle);
  EXPECT_LT(max_rel_diff(F, Fd), 1e-12);
  // as one open rod, the strands' pairs within 2D of the hairpin are skipped: less energy
  StericParams one = p;
  one.rods.clear();
  one.closed = false;
  EXPECT_LT(Steric(one, n).energy(X), E);
  // a single chain is the plain rod, bit for bit
  StericParams chain = p;
  chain.rods = {{0, n, true, p.ds}};
  StericParams plain = p;
  plain.rods.clear();
  plain.closed = true;
  std::vector<Vec3> Fa(n, Vec3::Zero()), Fb(n, Vec3::Zero());
  EXPECT_EQ(Steric(chain, n).accumulate(X, Fa), Steric(plain, n).accumulate(X, Fb));
  EXPECT_EQ(Fa, Fb);
  // ranges that do not cover the points are refused
  StericParams gap = p;
  gap.rods = {{0, half, false, p.ds}, {half + 1, n - half - 1, false, p.ds}};
  EXPECT_THROW(Steric(gap, n), std::invalid_argument);
}

// steric_rods: the rods the hard core sees, StericParams::rods or one rod of every point
TEST(StericRods, SegmentsOfTheParamsRodsOrOneRodOfAllPoints) {
  StericParams p;
  p.ds = 2.5;
  p.closed = false;
  const std::vector<rod::RodRange> one = steric_rods(p, 40);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].offset, 0);
  EXPECT_EQ(one[0].n, 40);
  EXPECT_FALSE(one[0].closed);
  EXPECT_EQ(one[0].ds, 2.5);
  p.rods = {{0, 10, true, 3.4}, {10, 30, false, 3.0}};
  const std::vector<rod::RodRange> two = steric_rods(p, 40);
  ASSERT_EQ(two.size(), 2u);
  for (std::size_t r = 0; r < 2; ++r) {
    EXPECT_EQ(two[r].offset, p.rods[r].offset);
    EXPECT_EQ(two[r].n, p.rods[r].n);
    EXPECT_EQ(two[r].closed, p.rods[r].closed);
    EXPECT_EQ(two[r].ds, p.rods[r].ds);
  }
}

}  // namespace
}  // namespace ibrod::interactions
