#include "integrate/local_mobility.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

#include "ib/kernel.hpp"

namespace ibrod::integrate {

namespace {

Eigen::Matrix3d cross_matrix(const Vec3& a) {
  Eigen::Matrix3d c;
  c << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return c;
}

}  // namespace

Eigen::SparseMatrix<double> kernel_overlap(std::span<const Vec3> X, const GridSpec& grid, int m) {
  return kernel_overlap(X, grid, m, 0.0, false);
}

Eigen::SparseMatrix<double> kernel_overlap(std::span<const Vec3> X, const GridSpec& grid, int m,
                                           double window, bool closed) {
  // 2 (4m + 2) ≤ n: two stencils overlap one way round the periodic box at most
  if (m < 1 || m > ib::kMaxKernelWidth || 2 * (4 * m + 2) > grid.n)
    throw std::invalid_argument("kernel_overlap: kernel width " + std::to_string(m) +
                                " not in 1 … " + std::to_string(ib::kMaxKernelWidth) +
                                " or twice its stencil wider than the grid");
  ib::detail::check_positions(X, grid.h());
  if (closed && window > 0 && X.size() < 2 * window)
    throw std::invalid_argument("kernel_overlap: a closed chain of " + std::to_string(X.size()) +
                                " points is shorter than twice the taper's window " +
                                std::to_string(window));
  const int n = static_cast<int>(X.size());
  const double h = grid.h();
  std::vector<ib::detail::PointStencil> st;
  st.reserve(n);
  for (const Vec3& x : X) st.emplace_back(x, grid, m);
  const int S = 4 * m + 2;
  // the blocks of each overlapping pair j ≤ k, then the columns in order
  struct Block {
    int j, k;
    Eigen::Matrix<double, 6, 6> B;
  };
  std::vector<Block> blocks;
  blocks.reserve(std::size_t(n) * 16);
  // offset of k's stencil from j's in dimension d, in (−n/2, n/2]; |o| ≥ S: no overlap
  auto offset = [&](int j, int k, int d) {
    int o = st[k].idx[d][0] - st[j].idx[d][0];
    if (o > grid.n / 2) o -= grid.n;
    if (o <= -grid.n / 2) o += grid.n;
    return o;
  };
  for (int j = 0; j < n; ++j) {
    for (int k = j; k < n; ++k) {
      int o[3];
      bool overlap = true;
      for (int d = 0; d < 3 && overlap; ++d) {
        o[d] = offset(j, k, d);
        overlap = o[d] > -S && o[d] < S;
      }
      if (!overlap) continue;
      double taper = 1;
      if (window > 0) {
        const int d = closed ? std::min(k - j, n - (k - j)) : k - j;
        taper = 1 - d / window;
        if (taper <= 0) continue;
      }
      // 1-D sums (times h) of φ_j φ_k, dφ_j φ_k, φ_j dφ_k, dφ_j dφ_k over the common indices
      double pp[3], dp[3], pd[3], dd[3];
      for (int d = 0; d < 3; ++d) {
        pp[d] = dp[d] = pd[d] = dd[d] = 0;
        const int q0 = std::max(0, o[d]), q1 = std::min(S, S + o[d]);
        const double* pj = st[j].phi[d];
        const double* dj = st[j].dphi[d];
        const double* pk = st[k].phi[d];
        const double* dk = st[k].dphi[d];
        for (int q = q0; q < q1; ++q) {
          const int r = q - o[d];
          pp[d] += pj[q] * pk[r];
          dp[d] += dj[q] * pk[r];
          pd[d] += pj[q] * dk[r];
          dd[d] += dj[q] * dk[r];
        }
        pp[d] *= h;
        dp[d] *= h;
        pd[d] *= h;
        dd[d] *= h;
      }
      const double w = pp[0] * pp[1] * pp[2];
      auto other = [](int a, int b) { return 3 - a - b; };
      Eigen::Matrix3d G;  // h³ Σ g_j,a g_k,b
      Vec3 a, b;          // h³ Σ w_j g_k, h³ Σ w_k g_j
      for (int p = 0; p < 3; ++p) {
        const int q = (p + 1) % 3, r = (p + 2) % 3;
        a[p] = pd[p] * pp[q] * pp[r];
        b[p] = dp[p] * pp[q] * pp[r];
        G(p, p) = dd[p] * pp[q] * pp[r];
        for (int c = 0; c < 3; ++c)
          if (c != p) G(p, c) = dp[p] * pd[c] * pp[other(p, c)];
      }
      Eigen::Matrix<double, 6, 6> B;
      B.topLeftCorner<3, 3>() = w * Eigen::Matrix3d::Identity();
      B.topRightCorner<3, 3>() = 0.5 * cross_matrix(a);
      B.bottomLeftCorner<3, 3>() = -0.5 * cross_matrix(b);
      B.bottomRightCorner<3, 3>() =
          0.25 * (G.trace() * Eigen::Matrix3d::Identity() - G.transpose());
      if (taper != 1) B *= taper;
      blocks.push_back({j, k, B});
    }
  }
  // column block k holds B(j, k) for j ≤ k and B(k, j)ᵀ for j > k; rows ascending
  std::vector<std::vector<std::pair<int, int>>> col(n);  // (row point, block index, ± transposed)
  for (int b = 0; b < int(blocks.size()); ++b) {
    col[blocks[b].k].emplace_back(blocks[b].j, b);
    if (blocks[b].j != blocks[b].k) col[blocks[b].j].emplace_back(blocks[b].k, ~b);
  }
  Eigen::SparseMatrix<double> O(6 * n, 6 * n);
  std::size_t nnz = 0;
  for (const auto& c : col) nnz += 36 * c.size();
  O.reserve(Eigen::Index(nnz));
  for (int k = 0; k < n; ++k) {
    std::sort(col[k].begin(), col[k].end());
    for (int c = 0; c < 6; ++c) {
      O.startVec(6 * k + c);
      for (const auto& [j, b] : col[k]) {
        const bool transposed = b < 0;
        const Eigen::Matrix<double, 6, 6>& B = blocks[transposed ? ~b : b].B;
        for (int r = 0; r < 6; ++r) {
          const double v = transposed ? B(c, r) : B(r, c);
          if (v != 0) O.insertBack(6 * j + r, 6 * k + c) = v;
        }
      }
    }
  }
  O.finalize();
  return O;
}

}  // namespace ibrod::integrate
