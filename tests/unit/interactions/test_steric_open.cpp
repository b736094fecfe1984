// Steric repulsion on an open rod (StericParams::closed = false): n − 1 segments, no closing
// segment, along-rod distance |k − l| (not the cyclic one); F = −∇E, cells = direct, Σ F = 0.
#include <gtest/gtest.h>

#include <cstdio>

#include "curves.hpp"
#include "interactions/interactions.hpp"

namespace ibrod::interactions {
namespace {

using namespace test;

constexpr double D = 20.0;
constexpr double g = kDefaultStericStiffness;

// The oracle: every pair of the n − 1 segments k < l with (l − k) Δs > 2D, by steric_pair.
double open_oracle(const std::vector<Vec3>& X, double ds) {
  const int n = int(X.size());
  double E = 0;
  std::array<Vec3, 4> f;
  for (int k = 0; k + 1 < n; ++k)
    for (int l = k + 1; l + 1 < n; ++l)
      if ((l - k) * ds > 2 * D) E += steric_pair(D, g, X[k], X[k + 1], X[l], X[l + 1], f);
  return E;
}

TEST(StericOpen, EndsThatMeetRepelAndNoClosingSegment) {
  // 24 points on a ring 14 Å across: the open rod's two ends meet. Closed, segments 0 and 22 are
  // 2 apart along the rod (cyclically) and skipped; open they are 22 apart and push apart.
  const auto X = circle(24, 13 * kDs / (2 * pi));
  StericParams p;
  p.stiffness = g;
  StericParams po = p;
  po.closed = false;
  Steric closed(p, 24), open(po, 24);
  const double Ec = closed.energy(X), Eo = open.energy(X);
  const double oracle = open_oracle(X, kDs);
  std::printf("  ring of 24, 14 Å across: E closed %.4g kT, open %.4g kT (oracle %.4g)\n", Ec / kT,
              Eo / kT, oracle / kT);
  ASSERT_GT(oracle, 0.0);
  EXPECT_NEAR(Eo, oracle, 1e-12 * oracle);
  EXPECT_GT(Eo, Ec);  // the open rod counts pairs across its free ends
  std::vector<Vec3> F(24, Vec3::Zero()), Fd(24, Vec3::Zero());
  EXPECT_NEAR(open.accumulate(X, F), oracle, 1e-12 * oracle);
  EXPECT_NEAR(open.accumulate_direct(X, Fd), oracle, 1e-12 * oracle);
  EXPECT_GT(F[0].norm(), 0.0);  // the first point is pushed by the far end
  // a straight open rod: nothing (the closed rod's closing segment would cross the whole rod)
  std::vector<Vec3> S(30);
  for (int k = 0; k < 30; ++k) S[k] = Vec3(k * kDs, 0.0, 0.0);
  EXPECT_EQ(Steric(po, 30).energy(S), 0.0);
  EXPECT_GT(Steric(p, 30).energy(S), 0.0);
}

TEST(StericOpen, RodForceIsMinusGradientAndCellListEqualsDirect) {
  // the collapsed supercoil (strands 18 Å apart) cut open: the cell list, the direct sum and
  // the oracle agree, Σ F = 0, F = −∇E by central differences
  const auto X0 = plectoneme(200, kDs, 9.0, 60.0);
  const int n = int(X0.size());
  StericParams p;
  p.stiffness = g;
  p.ds = mean_spacing(X0);
  p.closed = false;
  Steric st(p, n);
  std::vector<Vec3> F(n, Vec3::Zero()), Fd(n, Vec3::Zero());
  const double E = st.accumulate(X0, F);
  EXPECT_TRUE(st.used_cell_list());
  const double Ed = st.accumulate_direct(X0, Fd);
  ASSERT_GT(Ed, 0.0);
  EXPECT_NEAR(E, Ed, 1e-12 * Ed);
  EXPECT_LT(max_rel_diff(F, Fd), 1e-12);
  Vec3 sum = Vec3::Zero();
  double scale = 0;
  for (const Vec3& f : F) {
    sum += f;
    scale += f.norm();
  }
  EXPECT_LT(sum.norm(), 1e-13 * scale);
  auto X = X0;
  double err = 0, fmax = 0;
  const double step = 1e-6;
  for (int i : {0, 1, n / 3, n / 2, n - 2, n - 1})
    for (int a = 0; a < 3; ++a) {
      X[i][a] = X0[i][a] + step;
      const double Ep = st.energy(X);
      X[i][a] = X0[i][a] - step;
      const double Em = st.energy(X);
      X[i][a] = X0[i][a];
      err = std::max(err, std::abs(F[i][a] + (Ep - Em) / (2 * step)));
      fmax = std::max(fmax, std::abs(F[i][a]));
    }
  EXPECT_LT(err / std::max(fmax, 1e-30), 1e-6);
}

}  // namespace
}  // namespace ibrod::interactions
