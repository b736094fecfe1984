#include "integrate/block_cyclic.hpp"

#include <stdexcept>

namespace ibrod::integrate {

bool BlockCyclicCholesky::factorize(const std::vector<Mat6>& diag, const std::vector<Mat6>& lower,
                                    bool cyclic) {
  const int n = int(diag.size());
  n_ = 0;
  cyclic_ = cyclic;
  if (!cyclic) {
    if (n < 1 || lower.size() != diag.size())
      throw std::invalid_argument("BlockCyclicCholesky: need n >= 1 diagonal and n lower blocks");
    return factorize_tridiagonal(diag, lower);
  }
  if (n < 3 || lower.size() != diag.size())
    throw std::invalid_argument("BlockCyclicCholesky: need n >= 3 diagonal and n lower blocks");
  L_.resize(n - 1);
  sub_.resize(n - 2);
  W_.resize(n - 1);
  Mat6 last_acc = diag[n - 1];  // S[n−1][n−1] − Σ_k W_k W_kᵀ
  for (int k = 0; k < n - 1; ++k) {
    // pivot: S[k][k] − L[k][k−1] L[k][k−1]ᵀ
    Mat6 A = diag[k];
    if (k > 0) A.noalias() -= sub_[k - 1] * sub_[k - 1].transpose();
    Eigen::LLT<Mat6> llt(A);
    if (llt.info() != Eigen::Success) return false;
    L_[k] = llt.matrixL();
    const auto Lk = L_[k].triangularView<Eigen::Lower>();
    // X L_kᵀ = B  ⇔  L_k Xᵀ = Bᵀ
    auto right_solve = [&](const Mat6& B) -> Mat6 { return Lk.solve(B.transpose()).transpose(); };
    if (k + 1 <= n - 2) sub_[k] = right_solve(lower[k]);
    // last block row: (S[n−1][k] − L[n−1][k−1] L[k][k−1]ᵀ) L_k⁻ᵀ; S[n−1][k] is the corner
    // S[n−1][0] = lower[n−1]ᵀ for k = 0, the band's lower[n−2] for k = n−2, else 0
    Mat6 B = Mat6::Zero();
    if (k == 0) B += lower[n - 1].transpose();
    if (k == n - 2) B += lower[n - 2];
    if (k > 0) B.noalias() -= W_[k - 1] * sub_[k - 1].transpose();
    W_[k] = right_solve(B);
    last_acc.noalias() -= W_[k] * W_[k].transpose();
  }
  Eigen::LLT<Mat6> llt(last_acc);
  if (llt.info() != Eigen::Success) return false;
  last_ = llt.matrixL();
  n_ = n;
  return true;
}

void BlockCyclicCholesky::solve(Eigen::Ref<Eigen::VectorXd> x) const {
  if (n_ == 0) throw std::logic_error("BlockCyclicCholesky::solve: no factor");
  if (!cyclic_) {
    solve_tridiagonal(x);
    return;
  }
  const int n = n_;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  // L y = b
  Vec6 acc = x.segment<6>(6 * (n - 1));
  for (int k = 0; k < n - 1; ++k) {
    Vec6 b = x.segment<6>(6 * k);
    if (k > 0) b.noalias() -= sub_[k - 1] * x.segment<6>(6 * (k - 1));
    L_[k].triangularView<Eigen::Lower>().solveInPlace(b);
    x.segment<6>(6 * k) = b;
    acc.noalias() -= W_[k] * b;
  }
  last_.triangularView<Eigen::Lower>().solveInPlace(acc);
  // Lᵀ x = y
  last_.triangularView<Eigen::Lower>().transpose().solveInPlace(acc);
  x.segment<6>(6 * (n - 1)) = acc;
  for (int k = n - 2; k >= 0; --k) {
    Vec6 y = x.segment<6>(6 * k);
    if (k + 1 <= n - 2) y.noalias() -= sub_[k].transpose() * x.segment<6>(6 * (k + 1));
    y.noalias() -= W_[k].transpose() * acc;
    L_[k].triangularView<Eigen::Lower>().transpose().solveInPlace(y);
    x.segment<6>(6 * k) = y;
  }
}

// An open rod: S block-tridiagonal, L lower block-bidiagonal (pivots L_[k], k = 0 … n−1 with
// L_[n−1] in last_, and sub_[k] = L[k+1][k]).
bool BlockCyclicCholesky::factorize_tridiagonal(const std::vector<Mat6>& diag,
                                                const std::vector<Mat6>& lower) {
  const int n = int(diag.size());
  L_.resize(n - 1);
  sub_.resize(n - 1);
  W_.clear();
  Mat6 A = diag[0];
  for (int k = 0; k < n; ++k) {
    if (k > 0) {
      A = diag[k];
      A.noalias() -= sub_[k - 1] * sub_[k - 1].transpose();
    }
    Eigen::LLT<Mat6> llt(A);
    if (llt.info() != Eigen::Success) return false;
    if (k == n - 1) {
      last_ = llt.matrixL();
      break;
    }
    L_[k] = llt.matrixL();
    // L[k+1][k] L_kᵀ = S[k+1][k]  ⇔  L_k L[k+1][k]ᵀ = S[k+1][k]ᵀ
    sub_[k] = L_[k].triangularView<Eigen::Lower>().solve(lower[k].transpose()).transpose();
  }
  n_ = n;
  return true;
}

void BlockCyclicCholesky::solve_tridiagonal(Eigen::Ref<Eigen::VectorXd> x) const {
  const int n = n_;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  auto pivot = [&](int k) -> const Mat6& { return k == n - 1 ? last_ : L_[k]; };
  // L y = b
  for (int k = 0; k < n; ++k) {
    Vec6 b = x.segment<6>(6 * k);
    if (k > 0) b.noalias() -= sub_[k - 1] * x.segment<6>(6 * (k - 1));
    pivot(k).triangularView<Eigen::Lower>().solveInPlace(b);
    x.segment<6>(6 * k) = b;
  }
  // Lᵀ x = y
  for (int k = n - 1; k >= 0; --k) {
    Vec6 y = x.segment<6>(6 * k);
    if (k < n - 1) y.noalias() -= sub_[k].transpose() * x.segment<6>(6 * (k + 1));
    pivot(k).triangularView<Eigen::Lower>().transpose().solveInPlace(y);
    x.segment<6>(6 * k) = y;
  }
}

}  // namespace ibrod::integrate
