#include "integrate/local_mobility.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
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
  return kernel_overlap(X, grid, m, 0.0, {});
}

Eigen::SparseMatrix<double> kernel_overlap(std::span<const Vec3> X, const GridSpec& grid, int m,
                                           double window, const std::vector<rod::RodRange>& rods) {
  // 2 (4m + 2) ≤ n: two stencils overlap one way round the periodic box at most
  if (m < 1 || m > ib::kMaxKernelWidth || 2 * (4 * m + 2) > grid.n)
    throw std::invalid_argument("kernel_overlap: kernel width " + std::to_string(m) +
                                " not in 1 … " + std::to_string(ib::kMaxKernelWidth) +
                                " or twice its stencil wider than the grid");
  ib::detail::check_positions(X, grid.h());
  const int n = static_cast<int>(X.size());
  // each point's rod and place along it (the taper's distances)
  std::vector<int> rod_of(window > 0 ? n : 0), along(window > 0 ? n : 0);
  if (window > 0) {
    if (rod::total_points(rods) != n)
      throw std::invalid_argument("kernel_overlap: the rods' points are not X's");
    rod::for_each_rod(rods, [&](std::size_t r, const rod::RodRange& g) {
      if (rod::wraps(g) && g.n < 2 * window)
        throw std::invalid_argument("kernel_overlap: a ring of " + std::to_string(g.n) +
                                    " points is shorter than twice the taper's window " +
                                    std::to_string(window));
      for (int k = 0; k < g.n; ++k) {
        rod_of[g.offset + k] = int(r);
        along[g.offset + k] = k;
      }
    });
  }
  const double h = grid.h();
  std::vector<ib::detail::PointStencil> st;
  st.reserve(n);
  for (const Vec3& x : X) st.emplace_back(x, grid, m);
  const int S = 4 * m + 2;
  // offset of k's stencil from j's in dimension d, in (−n/2, n/2]; |o| ≥ S: no overlap
  auto offset = [&](int j, int k, int d) {
    int o = st[k].idx[d][0] - st[j].idx[d][0];
    if (o > grid.n / 2) o -= grid.n;
    if (o <= -grid.n / 2) o += grid.n;
    return o;
  };
  auto taper_of = [&](int j, int k) {
    if (window <= 0) return 1.0;
    if (rod_of[j] != rod_of[k]) return 0.0;  // two rods: dropped
    const rod::RodRange& g = rods[std::size_t(rod_of[j])];
    const int d = rod::arc_separation(g, along[j], along[k]);
    return 1 - d / window;
  };
  // the points by the x index of their stencil (counting sort), so that each point meets only
  // those within 2S − 1 x planes (distinct planes: 2S ≤ grid.n)
  std::vector<int> first(grid.n + 1, 0), by_x(n);
  for (int j = 0; j < n; ++j) ++first[st[j].idx[0][0] + 1];
  for (int i = 0; i < grid.n; ++i) first[i + 1] += first[i];
  {
    std::vector<int> fill(first.begin(), first.end() - 1);
    for (int j = 0; j < n; ++j) by_x[fill[st[j].idx[0][0]]++] = j;
  }
  // each point's overlapping partners (itself included), ascending: the rows of its column block
  std::vector<std::vector<int>> partners(n);
  for (int j = 0; j < n; ++j) {
    for (int dx = -(S - 1); dx <= S - 1; ++dx) {
      const int i = ((st[j].idx[0][0] + dx) % grid.n + grid.n) % grid.n;
      for (int b = first[i]; b < first[i + 1]; ++b) {
        const int k = by_x[b];
        if (std::abs(offset(j, k, 1)) >= S || std::abs(offset(j, k, 2)) >= S) continue;
        if (taper_of(j, k) <= 0) continue;
        partners[j].push_back(k);
      }
    }
    std::sort(partners[j].begin(), partners[j].end());
  }
  // the (j, k) block: 1-D sums (times h) of φ_j φ_k, dφ_j φ_k, φ_j dφ_k, dφ_j dφ_k over the
  // common indices. Block (k, j) is its transpose exactly (the same products, summed in the same
  // order along each dimension).
  auto pair_block = [&](int j, int k, Eigen::Matrix<double, 6, 6>& B) {
    double pp[3], dp[3], pd[3], dd[3];
    for (int d = 0; d < 3; ++d) {
      const int o = offset(j, k, d);
      pp[d] = dp[d] = pd[d] = dd[d] = 0;
      const int q0 = std::max(0, o), q1 = std::min(S, S + o);
      const double* pj = st[j].phi[d];
      const double* dj = st[j].dphi[d];
      const double* pk = st[k].phi[d];
      const double* dk = st[k].dphi[d];
      for (int q = q0; q < q1; ++q) {
        const int r = q - o;
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
    B.topLeftCorner<3, 3>() = w * Eigen::Matrix3d::Identity();
    B.topRightCorner<3, 3>() = 0.5 * cross_matrix(a);
    B.bottomLeftCorner<3, 3>() = -0.5 * cross_matrix(b);
    B.bottomRightCorner<3, 3>() = 0.25 * (G.trace() * Eigen::Matrix3d::Identity() - G.transpose());
    const double t = taper_of(j, k);
    if (t != 1) B *= t;
  };
  Eigen::SparseMatrix<double> O(6 * n, 6 * n);
  std::size_t nnz = 0;
  for (const auto& c : partners) nnz += 36 * c.size();
  O.reserve(Eigen::Index(nnz));
  std::vector<Eigen::Matrix<double, 6, 6>> col;
  for (int k = 0; k < n; ++k) {
    col.resize(partners[k].size());
    for (std::size_t a = 0; a < partners[k].size(); ++a) {
      const int j = partners[k][a];
      // a block below the diagonal is the transpose of the one above: O exactly symmetric
      if (j <= k) {
        pair_block(j, k, col[a]);
      } else {
        Eigen::Matrix<double, 6, 6> B;
        pair_block(k, j, B);
        col[a] = B.transpose();
      }
    }
    for (int c = 0; c < 6; ++c) {
      O.startVec(6 * k + c);
      for (std::size_t a = 0; a < partners[k].size(); ++a) {
        const int j = partners[k][a];
        for (int r = 0; r < 6; ++r) {
          const double v = col[a](r, c);
          if (v != 0) O.insertBack(6 * j + r, 6 * k + c) = v;
        }
      }
    }
  }
  O.finalize();
  return O;
}

}  // namespace ibrod::integrate
