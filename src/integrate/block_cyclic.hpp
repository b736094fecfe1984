#pragma once
// Cholesky factorisation and solve of a symmetric positive definite block-cyclic-tridiagonal
// matrix with 6×6 blocks — the implicit scheme's local system M_loc⁻¹ + Δt K of a closed rod
// without steric contacts (issue 14): blocks S[k][k] and S[k+1][k] (indices mod n). The factor
// keeps the band and one block row of fill (the last), O(n · 6³) to factorise, O(n · 6²) to
// solve, against ~10× that for a general sparse Cholesky of the same matrix.
#include <Eigen/Dense>
#include <vector>

namespace ibrod::integrate {

class BlockCyclicCholesky {
 public:
  using Mat6 = Eigen::Matrix<double, 6, 6>;

  /// diag[k] = S[k][k], lower[k] = S[(k+1) mod n][k] (so S[k][k+1] = lower[k]ᵀ), n ≥ 3 blocks.
  /// Returns false (and holds no factor) if S is not positive definite.
  bool factorize(const std::vector<Mat6>& diag, const std::vector<Mat6>& lower);
  /// x ← S⁻¹ x, x of 6n values.
  void solve(Eigen::VectorXd& x) const;
  int blocks() const { return n_; }

 private:
  int n_ = 0;
  std::vector<Mat6> L_;    // [n−1] Cholesky factors of the pivots (lower triangular)
  std::vector<Mat6> sub_;  // [n−2] L[k+1][k]
  std::vector<Mat6> W_;    // [n−1] L[n−1][k] (the last block row: the fill)
  Mat6 last_;              // L[n−1][n−1]
};

}  // namespace ibrod::integrate
