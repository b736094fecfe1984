// The kernel overlap O = 𝒥𝒮 (integrate/local_mobility.hpp) against its direct definition:
// spread (F, T) with the reference Coupler, interpolate the same field back.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "ib/coupler.hpp"
#include "integrate/local_mobility.hpp"

namespace ibrod::integrate {
namespace {

void check_against_coupler(const GridSpec& grid, int m, const std::vector<Vec3>& X, unsigned seed) {
  const int n = static_cast<int>(X.size());
  const Eigen::SparseMatrix<double> O = kernel_overlap(X, grid, m);
  ASSERT_EQ(O.rows(), 6 * n);
  ib::Coupler cp(grid, m);
  std::mt19937 rng(seed);
  std::normal_distribution<double> N01;
  std::vector<Vec3> F(n), T(n), U(n), W(n);
  Eigen::VectorXd g(6 * n);
  for (int k = 0; k < n; ++k) {
    F[k] = Vec3(N01(rng), N01(rng), N01(rng));
    T[k] = Vec3(N01(rng), N01(rng), N01(rng)) * grid.h();
    g.segment<3>(6 * k) = F[k];
    g.segment<3>(6 * k + 3) = T[k];
  }
  std::vector<double> fx(grid.size(), 0.0), fy(grid.size(), 0.0), fz(grid.size(), 0.0);
  cp.spread(X, F, T, {fx.data(), fy.data(), fz.data()});
  cp.interpolate(X, {fx.data(), fy.data(), fz.data()}, U, W);
  const Eigen::VectorXd og = O * g;
  double scale_u = 0, scale_w = 0;
  for (int k = 0; k < n; ++k) {
    scale_u = std::max(scale_u, U[k].norm());
    scale_w = std::max(scale_w, W[k].norm());
  }
  for (int k = 0; k < n; ++k) {
    EXPECT_LT((og.segment<3>(6 * k) - U[k]).norm(), 1e-12 * scale_u) << "point " << k;
    EXPECT_LT((og.segment<3>(6 * k + 3) - W[k]).norm(), 1e-12 * scale_w) << "point " << k;
  }
  // symmetric (𝒥 = 𝒮ᵀ) and positive semi-definite
  EXPECT_LT((Eigen::MatrixXd(O) - Eigen::MatrixXd(O).transpose()).norm(),
            1e-14 * Eigen::MatrixXd(O).norm());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(O), Eigen::EigenvaluesOnly);
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-12 * es.eigenvalues().maxCoeff());
}

TEST(KernelOverlap, EqualsSpreadingThenInterpolation) {
  // a helix of close points (many overlapping pairs) crossing the periodic faces, plus two
  // points near a face and a far one
  const GridSpec grid{16, 100.0};
  std::vector<Vec3> X;
  for (int k = 0; k < 40; ++k) {
    const double s = 0.25 * k;
    X.emplace_back(95.0 + 2.1 * k, 20 * std::cos(s) + 3.0, 20 * std::sin(s) - 1.0);
  }
  X.emplace_back(-0.4, 50.0, 99.9);
  X.emplace_back(99.8, 51.0, 0.3);
  X.emplace_back(50.0, 50.0, 50.0);
  check_against_coupler(grid, 1, X, 1);
}

TEST(KernelOverlap, EqualsSpreadingThenInterpolationForAWiderKernel) {
  const GridSpec grid{24, 120.0};
  std::vector<Vec3> X;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-130.0, 250.0);
  for (int k = 0; k < 25; ++k) X.emplace_back(U(rng), U(rng), U(rng));
  check_against_coupler(grid, 2, X, 2);
}

TEST(KernelOverlap, ShareTheMobilitysNearNullSpace) {
  // a straight periodic line of points 0.3 h apart: a pattern of wavelength 3 spacings is
  // averaged away by the kernel, so O hardly moves it, while a long wave it moves like ~9 points
  const GridSpec grid{16, 16.0};
  const int n = 160;
  std::vector<Vec3> X;
  for (int k = 0; k < n; ++k) X.emplace_back(0.1 * k + 0.03, 5.37, 8.61);
  const Eigen::SparseMatrix<double> O = kernel_overlap(X, grid, 1);
  auto rayleigh = [&](int waves) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(6 * n);
    for (int k = 0; k < n; ++k) g[6 * k + 1] = std::cos(2 * M_PI * waves * k / n);
    return g.dot(O * g) / g.squaredNorm() / O.coeff(1, 1);
  };
  EXPECT_GT(rayleigh(1), 8.0);
  EXPECT_LT(rayleigh(n / 3), 1e-3);
  EXPECT_LT(rayleigh(n / 2), 1e-3);
}

TEST(KernelOverlap, TheChainTaperKeepsItPositiveAndDropsDistantStrands) {
  // a closed chain folded back on itself (two strands 15 Å apart, within the kernel's reach):
  // the taper scales block (j, k) by 1 − d/window, d the distance along the ring, drops the
  // strands' mutual overlap beyond the window, and stays positive semi-definite
  const GridSpec grid{16, 160.0};
  std::vector<Vec3> X;
  const int n = 80;
  for (int k = 0; k < n / 2; ++k) X.emplace_back(20.0 + 3.0 * k, 50.0, 50.0);
  for (int k = 0; k < n / 2; ++k) X.emplace_back(20.0 + 3.0 * (n / 2 - 1 - k), 65.0, 52.0);
  const double window = 30;
  const Eigen::SparseMatrix<double> O = kernel_overlap(X, grid, 1);
  const std::vector<rod::RodRange> ring = {{0, n, true, 3.0}};
  const Eigen::SparseMatrix<double> T = kernel_overlap(X, grid, 1, window, ring);
  int across = 0;
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < n; ++k) {
      const int d = std::min(std::abs(j - k), n - std::abs(j - k));
      const double f = std::max(0.0, 1 - d / window);
      const Eigen::MatrixXd bo = Eigen::MatrixXd(O.block(6 * j, 6 * k, 6, 6));
      const Eigen::MatrixXd bt = Eigen::MatrixXd(T.block(6 * j, 6 * k, 6, 6));
      ASSERT_LT((bt - f * bo).norm(), 1e-12 * (1 + bo.norm())) << j << " " << k;
      across += d >= window && bo.norm() > 0;
    }
  EXPECT_GT(across, 100);  // the folded strands overlap, and the taper drops them
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(T), Eigen::EigenvaluesOnly);
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-12 * es.eigenvalues().maxCoeff());
  EXPECT_THROW(kernel_overlap(X, grid, 1, 41.0, ring), std::invalid_argument);  // n < 2 window
}

TEST(KernelOverlap, TheTaperOverSeveralRodsDropsEveryPairOfTwoRods) {
  // two open rods side by side, 12 Å apart (their stencils overlap): tapered along each rod,
  // nothing between them, still positive semi-definite
  const GridSpec grid{16, 160.0};
  std::vector<Vec3> X;
  for (int k = 0; k < 30; ++k) X.emplace_back(20.0 + 3.0 * k, 50.0, 50.0);
  for (int k = 0; k < 20; ++k) X.emplace_back(20.0 + 3.0 * k, 62.0, 51.0);
  const std::vector<rod::RodRange> rods = {{0, 30, false, 3.0}, {30, 20, false, 3.0}};
  const double window = 8;
  const Eigen::SparseMatrix<double> O = kernel_overlap(X, grid, 1);
  const Eigen::SparseMatrix<double> T = kernel_overlap(X, grid, 1, window, rods);
  int across = 0;
  for (int j = 0; j < 50; ++j)
    for (int k = 0; k < 50; ++k) {
      const bool same = (j < 30) == (k < 30);
      const double f = same ? std::max(0.0, 1 - std::abs(j - k) / window) : 0.0;
      const Eigen::MatrixXd bo = Eigen::MatrixXd(O.block(6 * j, 6 * k, 6, 6));
      const Eigen::MatrixXd bt = Eigen::MatrixXd(T.block(6 * j, 6 * k, 6, 6));
      ASSERT_LT((bt - f * bo).norm(), 1e-12 * (1 + bo.norm())) << j << " " << k;
      across += !same && bo.norm() > 0;
    }
  EXPECT_GT(across, 50);  // the rods' stencils overlap, and the taper drops them
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(T), Eigen::EigenvaluesOnly);
  EXPECT_GT(es.eigenvalues().minCoeff(), -1e-12 * es.eigenvalues().maxCoeff());
  // the rods must cover X
  EXPECT_THROW(kernel_overlap(X, grid, 1, window, {{0, 30, false, 3.0}}), std::invalid_argument);
}

TEST(KernelOverlap, RefusesAKernelWiderThanTheGrid) {
  const std::vector<Vec3> X{Vec3(1, 1, 1)};
  EXPECT_THROW(kernel_overlap(X, GridSpec{8, 10.0}, 2), std::invalid_argument);
  EXPECT_THROW(kernel_overlap(X, GridSpec{10, 10.0}, 1), std::invalid_argument);  // 2·6 > 10
  EXPECT_NO_THROW(kernel_overlap(X, GridSpec{12, 10.0}, 1));
  EXPECT_THROW(kernel_overlap(X, GridSpec{8, 10.0}, 0), std::invalid_argument);
}

}  // namespace
}  // namespace ibrod::integrate
