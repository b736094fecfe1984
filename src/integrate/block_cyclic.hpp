#pragma once
// Cholesky factorisation and solve of a symmetric positive definite block-cyclic-tridiagonal
// matrix with 6×6 blocks — the implicit scheme's local system M_loc⁻¹ + Δt K of one rod without
// steric contacts (issue 14): blocks S[k][k] and S[k+1][k], indices mod n for a closed rod
// (cyclic), or without the corner S[0][n−1] for an open one (block-tridiagonal). The cyclic
// factor keeps the band and one block row of fill (the last), O(n · 6³) to factorise,
// O(n · 6²) to solve, against ~10× that for a general sparse Cholesky of the same matrix; the
// tridiagonal one keeps the band only.
#include <Eigen/Dense>
#include <vector>

namespace ibrod::integrate {

class BlockCyclicCholesky {
 public:
  using Mat6 = Eigen::Matrix<double, 6, 6>;

  /// diag[k] = S[k][k], lower[k] = S[k+1][k] (so S[k][k+1] = lower[k]ᵀ), n blocks each.
  /// cyclic: lower[n−1] = S[0][n−1] is the corner, n ≥ 3; not cyclic: lower[n−1] is not read,
  /// n ≥ 1. Returns false (and holds no factor) if S is not positive definite.
  bool factorize(const std::vector<Mat6>& diag, const std::vector<Mat6>& lower, bool cyclic = true);
  /// Whether factorize takes a band of n blocks: n ≥ 3 cyclic, n ≥ 1 not.
  static bool fits(int n, bool cyclic) { return n >= (cyclic ? 3 : 1); }
  /// x ← S⁻¹ x, x of 6n values (a segment of a longer vector too).
  void solve(Eigen::Ref<Eigen::VectorXd> x) const;
  int blocks() const { return n_; }
  bool cyclic() const { return cyclic_; }

 private:
  int n_ = 0;
  bool cyclic_ = true;
  std::vector<Mat6> L_;    // [n−1] Cholesky factors of the pivots (lower triangular)
  std::vector<Mat6> sub_;  // [n−2] L[k+1][k] (not cyclic: [n−1])
  std::vector<Mat6> W_;    // [n−1] L[n−1][k] (the last block row: the fill; cyclic only)
  Mat6 last_;              // L[n−1][n−1]
  bool factorize_tridiagonal(const std::vector<Mat6>& diag, const std::vector<Mat6>& lower);
  void solve_tridiagonal(Eigen::Ref<Eigen::VectorXd> x) const;
};

}  // namespace ibrod::integrate
