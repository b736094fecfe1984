// BlockCyclicCholesky against a dense solve of the same block-cyclic-tridiagonal SPD matrix, and
// of a block-tridiagonal one (its non-cyclic mode: an open rod).
#include <gtest/gtest.h>

#include <random>

#include "integrate/block_cyclic.hpp"

namespace ibrod::integrate {
namespace {

using Mat6 = BlockCyclicCholesky::Mat6;

TEST(BlockCyclicCholesky, SolvesLikeADenseFactorisation) {
  for (int n : {3, 4, 7, 50}) {
    std::mt19937_64 rng(n);
    std::normal_distribution<double> N(0, 1);
    std::vector<Mat6> diag(n), lower(n);
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(6 * n, 6 * n);
    for (int k = 0; k < n; ++k) {
      for (int i = 0; i < 36; ++i) lower[k](i) = N(rng);
      Mat6 G;
      for (int i = 0; i < 36; ++i) G(i) = N(rng);
      diag[k] = G * G.transpose() + 20 * Mat6::Identity();  // diagonally dominant: SPD
      S.block<6, 6>(6 * k, 6 * k) = diag[k];
      const int k1 = (k + 1) % n;
      S.block<6, 6>(6 * k1, 6 * k) += lower[k];
      S.block<6, 6>(6 * k, 6 * k1) += lower[k].transpose();
    }
    BlockCyclicCholesky c;
    ASSERT_TRUE(c.factorize(diag, lower)) << n;
    Eigen::VectorXd b(6 * n);
    for (int i = 0; i < 6 * n; ++i) b[i] = N(rng);
    Eigen::VectorXd x = b;
    c.solve(x);
    const Eigen::VectorXd ref = S.llt().solve(b);
    EXPECT_LT((x - ref).norm(), 1e-12 * ref.norm()) << n;
    EXPECT_LT((S * x - b).norm(), 1e-12 * b.norm()) << n;
  }
}

TEST(BlockCyclicCholesky, TridiagonalModeSolvesLikeADenseFactorisation) {
  for (int n : {1, 2, 3, 4, 7, 50}) {
    std::mt19937_64 rng(100 + n);
    std::normal_distribution<double> N(0, 1);
    std::vector<Mat6> diag(n), lower(n);
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(6 * n, 6 * n);
    for (int k = 0; k < n; ++k) {
      for (int i = 0; i < 36; ++i) lower[k](i) = N(rng);  // lower[n − 1]: not read
      Mat6 G;
      for (int i = 0; i < 36; ++i) G(i) = N(rng);
      diag[k] = G * G.transpose() + 20 * Mat6::Identity();
      S.block<6, 6>(6 * k, 6 * k) = diag[k];
      if (k + 1 < n) {
        S.block<6, 6>(6 * (k + 1), 6 * k) = lower[k];
        S.block<6, 6>(6 * k, 6 * (k + 1)) = lower[k].transpose();
      }
    }
    BlockCyclicCholesky c;
    ASSERT_TRUE(c.factorize(diag, lower, false)) << n;
    EXPECT_FALSE(c.cyclic());
    Eigen::VectorXd b(6 * n);
    for (int i = 0; i < 6 * n; ++i) b[i] = N(rng);
    Eigen::VectorXd x = b;
    c.solve(x);
    const Eigen::VectorXd ref = S.llt().solve(b);
    EXPECT_LT((x - ref).norm(), 1e-12 * ref.norm()) << n;
    // a segment of a longer vector (several rods: each rod's block on its own range)
    Eigen::VectorXd y = Eigen::VectorXd::Zero(6 * n + 12);
    y.segment(6, 6 * n) = b;
    c.solve(y.segment(6, 6 * n));
    EXPECT_EQ(Eigen::VectorXd(y.segment(6, 6 * n)), x) << n;
    EXPECT_EQ(y.head(6).norm() + y.tail(6).norm(), 0.0);
  }
}

TEST(BlockCyclicCholesky, RefusesAnIndefiniteMatrix) {
  std::vector<Mat6> diag(5, Mat6::Identity()), lower(5, Mat6::Zero());
  diag[3](2, 2) = -1;
  BlockCyclicCholesky c;
  EXPECT_FALSE(c.factorize(diag, lower));
  Eigen::VectorXd x = Eigen::VectorXd::Ones(30);
  EXPECT_THROW(c.solve(x), std::logic_error);
  EXPECT_FALSE(c.factorize(diag, lower, false));
  EXPECT_THROW(c.solve(x), std::logic_error);
}

}  // namespace
}  // namespace ibrod::integrate
