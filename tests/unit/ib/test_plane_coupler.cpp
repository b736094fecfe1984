// The plane-by-plane coupling of the time step (ib::PlaneCoupler): spreading into every x-plane
// and sampling every x-plane must reproduce Coupler::spread and Coupler::interpolate (the
// oracles, themselves tested against the direct definitions in test_coupler.cpp) to round-off,
// for the padded vector rows, the generic rows, stencils that cross the periodic seam, several
// kernel widths and grid sizes, and whatever the order in which the planes are visited.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "ib/plane_coupler.hpp"

namespace ibrod::ib {
namespace {

constexpr double kH = 725.0 / 64;  // the reference grid spacing, Å

using Field = std::array<std::vector<double>, 3>;

Field zeros(const GridSpec& g) {
  return {std::vector<double>(g.size()), std::vector<double>(g.size()),
          std::vector<double>(g.size())};
}

std::array<double*, 3> plane_of(Field& f, const GridSpec& g, int i) {
  const std::size_t np = std::size_t(g.n) * g.n;
  return {f[0].data() + i * np, f[1].data() + i * np, f[2].data() + i * np};
}

double max_abs(const Field& f) {
  double r = 0;
  for (const auto& v : f)
    for (double x : v) r = std::max(r, std::abs(x));
  return r;
}

// Random unwrapped points, plus points whose stencils cross the periodic seam in every axis and
// points whose z stencil ends exactly at the end of a grid row (the padded-row boundary).
std::vector<Vec3> points(std::mt19937_64& rng, const GridSpec& g, int m, int nrandom) {
  const double L = g.L, h = g.h();
  std::uniform_real_distribution<double> uni(-L, 2 * L);
  std::vector<Vec3> X = {{0.0, 0.0, 0.0}, {L - 0.3 * h, 0.2 * h, L - 1e-9}, {-0.5 * h, L, 0.5 * h}};
  // first z index z0 = ⌊z/h⌋ − 2m: z0 + S = n, n − 1, n + 1 and z0 + 8 = n ± 1
  for (int z0 :
       {g.n - (4 * m + 2), g.n - (4 * m + 2) + 1, g.n - (4 * m + 2) - 1, g.n - 8, g.n - 9, g.n - 7})
    X.push_back({0.37 * L, 0.61 * L, (z0 + 2 * m + 0.4) * h});
  for (int t = 0; t < nrandom; ++t) X.push_back({uni(rng), uni(rng), uni(rng)});
  return X;
}

struct Case {
  int n, m;
};

class PlaneCouplerTest : public ::testing::TestWithParam<Case> {};

TEST_P(PlaneCouplerTest, SpreadingPlaneByPlaneEqualsWholeGridSpreading) {
  const auto [n, m] = GetParam();
  const GridSpec g{n, n * kH};
  std::mt19937_64 rng(11 + n + m);
  const auto X = points(rng, g, m, 40);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  std::vector<Vec3> F(X.size()), T(X.size());
  for (std::size_t k = 0; k < X.size(); ++k) {
    F[k] = {uni(rng), uni(rng), uni(rng)};
    T[k] = {uni(rng) * 30, uni(rng) * 30, uni(rng) * 30};
  }
  const Coupler cp(g, m);
  Field ref = zeros(g), got = zeros(g);
  cp.spread(X, F, T, {ref[0].data(), ref[1].data(), ref[2].data()});

  PlaneCoupler pc(cp, int(X.size()));
  pc.prepare(X, F, T);
  for (int i = n - 1; i >= 0; --i) pc.add_plane(i, plane_of(got, g, i));  // any plane order

  double diff = 0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t q = 0; q < g.size(); ++q)
      diff = std::max(diff, std::abs(got[c][q] - ref[c][q]));
  EXPECT_GT(max_abs(ref), 0.0);
  EXPECT_LE(diff, 1e-13 * max_abs(ref)) << "n = " << n << ", m = " << m;
}

TEST_P(PlaneCouplerTest, SamplingPlaneByPlaneEqualsWholeGridInterpolation) {
  const auto [n, m] = GetParam();
  const GridSpec g{n, n * kH};
  std::mt19937_64 rng(23 + n + m);
  const auto X = points(rng, g, m, 40);
  Field u = zeros(g);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (auto& v : u)
    for (double& x : v) x = uni(rng);
  const Coupler cp(g, m);
  std::vector<Vec3> U(X.size()), W(X.size()), U2(X.size()), W2(X.size());
  cp.interpolate(X, {u[0].data(), u[1].data(), u[2].data()}, U, W);

  PlaneCoupler pc(cp, int(X.size()));
  pc.prepare(X, {}, {});
  for (int i = 0; i < n; i += 2) {  // even planes first, then odd: the order must not matter
    const auto p = plane_of(u, g, i);
    pc.sample_plane(i, {p[0], p[1], p[2]});
  }
  for (int i = 1; i < n; i += 2) {
    const auto p = plane_of(u, g, i);
    pc.sample_plane(i, {p[0], p[1], p[2]});
  }
  pc.finish_interpolation(U2, W2);
  double su = 0, sw = 0, du = 0, dw = 0;
  for (std::size_t k = 0; k < X.size(); ++k) {
    su = std::max(su, U[k].cwiseAbs().maxCoeff());
    sw = std::max(sw, W[k].cwiseAbs().maxCoeff());
    du = std::max(du, (U2[k] - U[k]).cwiseAbs().maxCoeff());
    dw = std::max(dw, (W2[k] - W[k]).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(su, 0.0);
  EXPECT_GT(sw, 0.0);
  EXPECT_LE(du, 1e-13 * su) << "n = " << n << ", m = " << m;
  EXPECT_LE(dw, 1e-13 * sw) << "n = " << n << ", m = " << m;

  // W may be left out; U is then the same
  std::vector<Vec3> U3(X.size());
  pc.finish_interpolation(U3, {});
  for (std::size_t k = 0; k < X.size(); ++k) EXPECT_EQ(U3[k], U2[k]);
}

// m = 1 (S = 6, padded to 8: vector rows), m = 2 (S = 10 → 12: generic rows), m = 3 on a grid
// just wide enough; n = 16 makes most z stencils touch the row end.
INSTANTIATE_TEST_SUITE_P(KernelWidthsAndGrids, PlaneCouplerTest,
                         ::testing::Values(Case{16, 1}, Case{32, 1}, Case{64, 1}, Case{32, 2},
                                           Case{16, 3}));

TEST(PlaneCoupler, RejectsMorePointsThanItsBuffersAndMismatchedForces) {
  const GridSpec g{16, 16 * kH};
  const Coupler cp(g, 1);
  PlaneCoupler pc(cp, 2);
  const std::vector<Vec3> X3(3, Vec3(1, 2, 3)), F2(2, Vec3::Zero());
  EXPECT_THROW(pc.prepare(X3, {}, {}), std::invalid_argument);
  const std::vector<Vec3> X2(2, Vec3(1, 2, 3)), F1(1, Vec3::Zero());
  EXPECT_THROW(pc.prepare(X2, F1, {}), std::invalid_argument);
  std::vector<Vec3> U1(1);
  pc.prepare(X2, F2, {});
  EXPECT_THROW(pc.finish_interpolation(U1, {}), std::invalid_argument);
}

TEST(PlaneCoupler, SamplingTheFirstPointsOnlyGivesTheirVelocities) {
  // the stochastic drift's force pairs are spread, not sampled (sample_plane's `points`): the
  // first points' U, W are those of sampling every point, bit for bit
  const GridSpec g{16, 16 * kH};
  const Coupler cp(g, 1);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(0.0, g.L), val(-1.0, 1.0);
  std::vector<Vec3> X(30);
  for (Vec3& x : X) x = Vec3(pos(rng), pos(rng), pos(rng));
  std::vector<double> u(3 * g.size());
  for (double& v : u) v = val(rng);
  const std::array<const double*, 3> uc{u.data(), u.data() + g.size(), u.data() + 2 * g.size()};
  auto sample = [&](std::size_t points, std::vector<Vec3>& U, std::vector<Vec3>& W) {
    PlaneCoupler pc(cp, 30);
    pc.prepare(X, {}, {});
    const std::size_t np = std::size_t(g.n) * g.n;
    for (int i = 0; i < g.n; ++i)
      pc.sample_plane(i, {uc[0] + i * np, uc[1] + i * np, uc[2] + i * np}, points);
    pc.finish_interpolation(U, W, points);
  };
  std::vector<Vec3> Ua(30), Wa(30), Ub(12), Wb(12);
  sample(std::size_t(-1), Ua, Wa);
  sample(12, Ub, Wb);
  for (int k = 0; k < 12; ++k) {
    EXPECT_EQ(Ua[k], Ub[k]);
    EXPECT_EQ(Wa[k], Wb[k]);
  }
  std::vector<Vec3> Uc(30), Wc(30);
  EXPECT_THROW(sample(12, Uc, Wc), std::invalid_argument);  // U of 30 for 12 sampled
}

}  // namespace
}  // namespace ibrod::ib
