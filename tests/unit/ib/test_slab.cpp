// The x-slab restriction of the coupling (ib::XSlab, used by `mpirun -np K ibrod run`): slabs
// that tile the grid spread, each into its own planes, exactly the whole-grid force density, and
// their partial interpolations add up to the whole-grid U and W (round-off: other summation
// order). Also: the whole grid given as a slab is the unrestricted Coupler bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "ib/coupler.hpp"

namespace ibrod::ib {
namespace {

struct Points {
  std::vector<Vec3> X, F, T;
};

// Random unwrapped points, plus points on the periodic seam and on slab boundaries.
Points random_points(const GridSpec& g, int count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(-g.L, 2 * g.L), val(-1.0, 1.0);
  Points p;
  const double h = g.h();
  for (double x : {0.0, -1e-12, g.L - 1e-12, 0.5 * g.L, 0.5 * g.L - 1e-9 * h, 0.25 * g.L + 0.5 * h})
    p.X.push_back({x, 0.3 * g.L, 0.7 * g.L});
  for (int k = 0; k < count; ++k) p.X.push_back({pos(rng), pos(rng), pos(rng)});
  for (std::size_t k = 0; k < p.X.size(); ++k) {
    p.F.push_back({val(rng), val(rng), val(rng)});
    p.T.push_back({val(rng), val(rng), val(rng)});
  }
  return p;
}

std::array<std::vector<double>, 3> zeros(std::size_t n) {
  return {std::vector<double>(n, 0.0), std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)};
}

class SlabCoupling : public ::testing::TestWithParam<std::tuple<int, int, int>> {};

TEST_P(SlabCoupling, SlabsTileTheWholeGridSpreadAndInterpolation) {
  const auto [n, m, ranks] = GetParam();
  const GridSpec g{n, 200.0};
  const Coupler whole(g, m);
  const Points p = random_points(g, 150, 7u + unsigned(n + m + ranks));
  const std::size_t np = p.X.size(), plane = std::size_t(n) * n;

  // whole-grid spread, and a random velocity field to interpolate from
  auto f = zeros(g.size());
  whole.spread(p.X, p.F, p.T, {f[0].data(), f[1].data(), f[2].data()});
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> val(-1.0, 1.0);
  auto u = zeros(g.size());
  for (auto& comp : u)
    for (double& v : comp) v = val(rng);
  std::vector<Vec3> U(np), W(np);
  whole.interpolate(p.X, {u[0].data(), u[1].data(), u[2].data()}, U, W);

  std::vector<Vec3> Usum(np, Vec3::Zero()), Wsum(np, Vec3::Zero());
  double fmax = 0;
  for (const auto& comp : f)
    for (double v : comp) fmax = std::max(fmax, std::abs(v));
  const int nx = n / ranks;
  for (int r = 0; r < ranks; ++r) {
    const int x0 = r * nx;
    const Coupler slab(g, m, XSlab{x0, nx});
    // spread into this slab's planes only: the whole-grid values there (the same additions in
    // the same order, so equal bit for bit; checked to round-off all the same)
    auto fl = zeros(std::size_t(nx) * plane);
    slab.spread(p.X, p.F, p.T, {fl[0].data(), fl[1].data(), fl[2].data()});
    for (int c = 0; c < 3; ++c)
      for (std::size_t q = 0; q < std::size_t(nx) * plane; ++q)
        ASSERT_NEAR(fl[c][q], f[c][std::size_t(x0) * plane + q], 1e-14 * fmax)
            << "slab " << r << " component " << c << " local index " << q;
    // interpolate from this slab's planes only: partial sums
    std::array<const double*, 3> ul{u[0].data() + x0 * plane, u[1].data() + x0 * plane,
                                    u[2].data() + x0 * plane};
    std::vector<Vec3> Ul(np), Wl(np);
    slab.interpolate(p.X, ul, Ul, Wl);
    for (std::size_t k = 0; k < np; ++k) {
      Usum[k] += Ul[k];
      Wsum[k] += Wl[k];
    }
  }
  double Umax = 0, Wmax = 0;
  for (std::size_t k = 0; k < np; ++k) {
    Umax = std::max(Umax, U[k].cwiseAbs().maxCoeff());
    Wmax = std::max(Wmax, W[k].cwiseAbs().maxCoeff());
  }
  for (std::size_t k = 0; k < np; ++k) {
    EXPECT_LE((Usum[k] - U[k]).cwiseAbs().maxCoeff(), 1e-13 * Umax) << "point " << k;
    EXPECT_LE((Wsum[k] - W[k]).cwiseAbs().maxCoeff(), 1e-13 * Wmax) << "point " << k;
  }
}

// n, kernel width m, slabs: thin slabs (narrower than the stencil), 2 slabs (both neighbours the
// same), a single plane per slab
INSTANTIATE_TEST_SUITE_P(Grids, SlabCoupling,
                         ::testing::Values(std::make_tuple(16, 1, 2), std::make_tuple(16, 1, 4),
                                           std::make_tuple(16, 1, 16), std::make_tuple(24, 2, 3),
                                           std::make_tuple(32, 1, 8)));

TEST(SlabCoupling, TheWholeGridAsASlabIsTheUnrestrictedCouplerBitForBit) {
  const GridSpec g{16, 200.0};
  const Points p = random_points(g, 100, 3);
  auto a = zeros(g.size()), b = zeros(g.size());
  Coupler(g, 1).spread(p.X, p.F, p.T, {a[0].data(), a[1].data(), a[2].data()});
  Coupler(g, 1, XSlab{0, 16}).spread(p.X, p.F, p.T, {b[0].data(), b[1].data(), b[2].data()});
  EXPECT_EQ(a, b);
}

TEST(SlabCoupling, RejectsASlabOutsideTheGrid) {
  const GridSpec g{16, 200.0};
  EXPECT_THROW(Coupler(g, 1, XSlab{16, 1}), std::invalid_argument);
  EXPECT_THROW(Coupler(g, 1, XSlab{0, 0}), std::invalid_argument);
  EXPECT_THROW(Coupler(g, 1, XSlab{-1, 4}), std::invalid_argument);
  EXPECT_THROW(Coupler(g, 1, XSlab{0, 17}), std::invalid_argument);
}

}  // namespace
}  // namespace ibrod::ib
