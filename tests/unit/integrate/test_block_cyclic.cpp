// BlockCyclicCholesky against a dense solve of the same block-cyclic-tridiagonal SPD matrix, and
// of a block-tridiagonal one (its non-cyclic mode: an open rod).
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "integrate/block_cyclic.hpp"

namespace ibrod::integrate {
namespace {

using Mat6 = BlockCyclicCholesky::Mat6;

// n random blocks: diag SPD (diagonally dominant), lower arbitrary; S the dense matrix with them
// on its diagonal and sub-diagonal, cyclic (block (0, n − 1) from lower[n − 1]) or not
Eigen::MatrixXd random_blocks(int n, bool cyclic, std::mt19937_64& rng, std::vector<Mat6>& diag,
                              std::vector<Mat6>& lower) {
  std::normal_distribution<double> N(0, 1);
  diag.assign(n, Mat6::Zero());
  lower.assign(n, Mat6::Zero());
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(6 * n, 6 * n);
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < 36; ++i) lower[k](i) = N(rng);  // not cyclic: lower[n − 1] not read
    Mat6 G;
    for (int i = 0; i < 36; ++i) G(i) = N(rng);
    diag[k] = G * G.transpose() + 20 * Mat6::Identity();
    S.block<6, 6>(6 * k, 6 * k) = diag[k];
    if (cyclic || k + 1 < n) {
      const int k1 = (k + 1) % n;
      S.block<6, 6>(6 * k1, 6 * k) += lower[k];
      S.block<6, 6>(6 * k, 6 * k1) += lower[k].transpose();
    }
  }
  return S;
}

// c's solution of S x = b for a random b against the dense Cholesky's; returns x
Eigen::VectorXd solve_like_dense(const BlockCyclicCholesky& c, const Eigen::MatrixXd& S,
                                 std::mt19937_64& rng) {
  std::normal_distribution<double> N(0, 1);
  Eigen::VectorXd b(S.rows());
  for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = N(rng);
  Eigen::VectorXd x = b;
  c.solve(x);
  const Eigen::VectorXd ref = S.llt().solve(b);
  EXPECT_LT((x - ref).norm(), 1e-12 * ref.norm()) << S.rows() / 6;
  EXPECT_LT((S * x - b).norm(), 1e-12 * b.norm()) << S.rows() / 6;
  return x;
}

TEST(BlockCyclicCholesky, SolvesLikeADenseFactorisation) {
  for (int n : {3, 4, 7, 50}) {
    std::mt19937_64 rng(n);
    std::vector<Mat6> diag, lower;
    const Eigen::MatrixXd S = random_blocks(n, true, rng, diag, lower);
    BlockCyclicCholesky c;
    ASSERT_TRUE(c.factorize(diag, lower)) << n;
    solve_like_dense(c, S, rng);
  }
}

TEST(BlockCyclicCholesky, TridiagonalModeSolvesLikeADenseFactorisation) {
  for (int n : {1, 2, 3, 4, 7, 50}) {
    std::mt19937_64 rng(100 + n);
    std::vector<Mat6> diag, lower;
    const Eigen::MatrixXd S = random_blocks(n, false, rng, diag, lower);
    BlockCyclicCholesky c;
    ASSERT_TRUE(c.factorize(diag, lower, false)) << n;
    EXPECT_FALSE(c.cyclic());
    const Eigen::VectorXd x = solve_like_dense(c, S, rng);
    // a segment of a longer vector (several rods: each rod's block on its own range)
    Eigen::VectorXd b = S * x;  // (x solves S x = b to 1e-12; solve b again in place)
    Eigen::VectorXd xb = b;
    c.solve(xb);
    Eigen::VectorXd y = Eigen::VectorXd::Zero(6 * n + 12);
    y.segment(6, 6 * n) = b;
    c.solve(y.segment(6, 6 * n));
    EXPECT_EQ(Eigen::VectorXd(y.segment(6, 6 * n)), xb) << n;
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

// fits(n, cyclic), the band the implicit scheme asks about before it takes the block solver:
// exactly the sizes factorize takes (a cyclic band needs its corner apart from the band).
TEST(BlockCyclicCholesky, FitsExactlyTheBandsItFactorises) {
  for (bool cyclic : {true, false})
    for (int n = 1; n <= 5; ++n) {
      std::mt19937_64 rng(10 * n + cyclic);
      std::vector<Mat6> diag, lower;
      random_blocks(n, cyclic, rng, diag, lower);
      BlockCyclicCholesky c;
      bool factorised = false;
      try {
        factorised = c.factorize(diag, lower, cyclic);
      } catch (const std::invalid_argument&) {
        factorised = false;
      }
      EXPECT_EQ(BlockCyclicCholesky::fits(n, cyclic), factorised)
          << "n " << n << " cyclic " << cyclic;
    }
  EXPECT_FALSE(BlockCyclicCholesky::fits(2, true));
  EXPECT_TRUE(BlockCyclicCholesky::fits(3, true));
  EXPECT_TRUE(BlockCyclicCholesky::fits(1, false));
  EXPECT_FALSE(BlockCyclicCholesky::fits(0, false));
}

}  // namespace
}  // namespace ibrod::integrate
