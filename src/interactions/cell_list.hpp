#pragma once
// Internal to src/interactions: a free-space cell list over the bounding box of a point set
// (points sorted by cell, so that each cell is a contiguous range), and the OpenMP plumbing
// shared by the electrostatic and steric sums.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "interactions/interactions.hpp"

namespace ibrod::interactions::detail {

/// Cells of edge ≥ min_edge tiling the points' bounding box; no periodic wrap.
struct CellGrid {
  Vec3 lo = Vec3::Zero();
  std::array<double, 3> inv_edge{0, 0, 0};  ///< 1/edge, Å⁻¹ (0 when one cell spans the axis)
  std::array<int, 3> nc{1, 1, 1};           ///< cells per axis

  int size() const { return nc[0] * nc[1] * nc[2]; }
  /// Every cell is a neighbour of every other: the list cannot prune any pair.
  bool trivial() const { return nc[0] <= 2 && nc[1] <= 2 && nc[2] <= 2; }
  std::array<int, 3> coords(const Vec3& x) const {
    std::array<int, 3> c;
    for (int a = 0; a < 3; ++a) c[a] = std::min(nc[a] - 1, int((x[a] - lo[a]) * inv_edge[a]));
    return c;
  }
  int index(const std::array<int, 3>& c) const { return (c[2] * nc[1] + c[1]) * nc[0] + c[0]; }
};

/// Grid over the bounding box of pts with every cell edge ≥ min_edge, so that two points at most
/// min_edge apart lie in the same or adjacent cells. The edge is padded by 1e-9 relative so that
/// rounding in the cell index cannot separate such a pair by two cells. At most max_cells cells
/// (coarsening keeps the edge ≥ min_edge, hence correctness).
inline CellGrid make_grid(std::span<const Vec3> pts, double min_edge, int max_cells) {
  Vec3 lo = Vec3::Constant(HUGE_VAL), hi = Vec3::Constant(-HUGE_VAL);
  bool finite = true;  // checked per point: min/max would silently drop a NaN
  for (const Vec3& x : pts) {
    finite = finite && x.allFinite();
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  if (!finite || !lo.allFinite() || !hi.allFinite())
    throw RunError(
        "interactions: a rod position became non-finite (NaN/Inf): the simulation blew "
        "up, most likely because time.dt_ns is too large for the stretch/shear or steric "
        "stiffness");
  CellGrid g;
  g.lo = lo;
  const double edge = min_edge * (1.0 + 1e-9);
  for (int a = 0; a < 3; ++a) {
    const double ext = hi[a] - lo[a];
    // per-axis cap first, so that the product below cannot overflow (a blown-up rod has a huge
    // extent); coarsening keeps every edge ≥ min_edge
    g.nc[a] = int(std::clamp(std::floor(ext / edge), 1.0, double(std::min(max_cells, 1024))));
  }
  while (g.size() > max_cells) {  // coarsen the finest axis
    int a = int(std::max_element(g.nc.begin(), g.nc.end()) - g.nc.begin());
    g.nc[a] = std::max(1, g.nc[a] / 2);
  }
  for (int a = 0; a < 3; ++a) g.inv_edge[a] = g.nc[a] > 1 ? g.nc[a] / (hi[a] - lo[a]) : 0.0;
  return g;
}

/// Bins the points by counting sort: sorted position a holds point order[a], at x[a] (a copy, so
/// that the pair loops read positions contiguously), in cell cell[a]; cell c holds the sorted
/// positions start[c] .. start[c+1]−1, in increasing point index. assign()/resize() reuse
/// capacity: no allocation once the sizes were seen.
inline void bin(const CellGrid& g, std::span<const Vec3> pts, CellScratch& s) {
  const int n = int(pts.size()), nc = g.size();
  s.start.assign(nc + 1, 0);
  s.order.resize(n);
  s.cell.resize(n);
  s.x.resize(n);
  for (int i = 0; i < n; ++i) {
    s.cell[i] = g.index(g.coords(pts[i]));  // cell of point i (reordered below)
    ++s.start[s.cell[i] + 1];
  }
  for (int c = 0; c < nc; ++c) s.start[c + 1] += s.start[c];
  for (int i = 0; i < n; ++i) s.order[s.start[s.cell[i]]++] = i;  // start[c] → end of c
  for (int c = nc; c > 0; --c) s.start[c] = s.start[c - 1];
  s.start[0] = 0;
  for (int a = 0; a < n; ++a) {
    s.x[a] = pts[s.order[a]];
    s.cell[a] = g.index(g.coords(s.x[a]));
  }
}

/// Calls fn(b) for every sorted position b paired with a: b in a cell adjacent to (or equal to)
/// a's cell with a cell index ≥ a's, and b > a within a's own cell. Each pair of points in
/// adjacent cells is visited exactly once over all a, with no visit wasted on the other half.
template <class Fn>
inline void for_each_partner(const CellGrid& g, const CellScratch& s, int a, Fn&& fn) {
  const int c = s.cell[a];
  const int cx = c % g.nc[0], cy = (c / g.nc[0]) % g.nc[1], cz = c / (g.nc[0] * g.nc[1]);
  for (int z = std::max(0, cz - 1); z <= std::min(g.nc[2] - 1, cz + 1); ++z)
    for (int y = std::max(0, cy - 1); y <= std::min(g.nc[1] - 1, cy + 1); ++y)
      for (int x = std::max(0, cx - 1); x <= std::min(g.nc[0] - 1, cx + 1); ++x) {
        const int c2 = (z * g.nc[1] + y) * g.nc[0] + x;
        if (c2 < c) continue;
        const int end = s.start[c2 + 1];
        for (int b = c2 == c ? a + 1 : s.start[c2]; b < end; ++b) fn(b);
      }
}

/// Runs body(i, Fbuf, E) for i = 0..n−1 on OpenMP threads, each thread adding forces into its own
/// buffer Fbuf ([n], zeroed here) and energy into its own E; then adds the buffers into F and
/// returns ΣE, both in thread order (reproducible for a fixed thread count). Interleaved chunks
/// balance the triangular loops (j > i). Buffers grow only when n or the thread count grows.
/// Two barriers per call (after the pair loop, at the end); small n runs on one thread.
template <class Body>
inline double parallel_pairs(int n, std::span<Vec3> F, std::vector<Vec3>& thread_F,
                             std::vector<double>& thread_E, Body&& body) {
  const int nt = std::max(1, omp_get_max_threads());
  if (thread_F.size() < size_t(nt) * size_t(n)) thread_F.resize(size_t(nt) * size_t(n));
  if (thread_E.size() < size_t(nt)) thread_E.resize(nt);
  int used = 1;
#pragma omp parallel num_threads(nt) if (n >= 64)
  {
    const int t = omp_get_thread_num(), nth = omp_get_num_threads();
    if (t == 0) used = nth;  // read after the region
    Vec3* Ft = thread_F.data() + size_t(t) * size_t(n);
    for (int k = 0; k < n; ++k) Ft[k].setZero();
    double E = 0;
#pragma omp for schedule(static, 8)
    for (int i = 0; i < n; ++i) body(i, Ft, E);
    thread_E[t] = E;
#pragma omp for schedule(static) nowait
    for (int k = 0; k < n; ++k) {
      Vec3 s = Vec3::Zero();
      for (int u = 0; u < nth; ++u) s += thread_F[size_t(u) * size_t(n) + k];
      F[k] += s;
    }
  }
  double E = 0;
  for (int u = 0; u < used; ++u) E += thread_E[u];
  return E;
}

}  // namespace ibrod::interactions::detail
