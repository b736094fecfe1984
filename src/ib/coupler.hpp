#pragma once
// Generalized immersed-boundary coupling (MODEL §3 (2.9–2.16), §4): spreading of point forces and
// torques to the grid and interpolation of velocity and angular velocity back to the points,
// with the smoothed delta δ_c(x) = c⁻³ φ(x₁/c) φ(x₂/c) φ(x₃/c), Peskin's 4-point φ, c = m·h.
// Knows the grid and a list of points only (no rods).
//
// Spreading, for point forces F_k (g Å s⁻²) and point torques T_k (g Å² s⁻²) at X_k:
//   f(x) += Σ_k F_k δ_c(x − X_k) + ½ curl_h[Σ_k T_k δ_c(x − X_k)]
// Interpolation, from velocity u on the grid:
//   U_k = Σ_x u(x) δ_c(x − X_k) h³,   W_k = ½ Σ_x (curl_h u)(x) δ_c(x − X_k) h³
// curl_h is the central-difference curl, which is symmetric on the periodic grid, so the two are
// exactly adjoint: Σ_x f·u h³ = Σ_k (F_k·U_k + T_k·W_k). Points may lie anywhere (positions are
// kept unwrapped; the grid index is wrapped periodically).
//
// Coupler is the reference implementation, one point at a time over the whole grid (or an
// x-slab of it); PlaneCoupler (ib/plane_coupler.hpp) does the same one x-plane at a time.
#include <array>
#include <span>
#include <vector>

#include "core/grid.hpp"
#include "core/types.hpp"
#include "ib/kernel.hpp"

namespace ibrod::ib {

/// A range of x-planes [begin, begin + count) of the periodic grid (0 ≤ begin < n, 1 ≤ count ≤ n).
/// A Coupler restricted to it reads and writes arrays that hold these planes only, global point
/// (i, j, k) at ((i − begin) n + j) n + k: the slab of one MPI rank (fluid::DistributedFluid).
struct XSlab {
  int begin = 0;
  int count = 0;
};

/// Spreading and interpolation for one grid and kernel width. Copyable and without mutable
/// state, so its const member functions may be called concurrently. Neither spread() nor
/// interpolate() allocates. Both run OpenMP-parallel (see spread() for how it avoids races) and
/// give bitwise the same result for any number of threads.
class Coupler {
 public:
  /// largest kernel width m accepted (fixed-size stencil arrays: 4m + 2 ≤ 34 points)
  /// largest kernel width m accepted (ib::kMaxKernelWidth)
  static constexpr int kMaxKernelWidth = ib::kMaxKernelWidth;

  /// kernel_width m: c = m·h, a positive integer. Throws std::invalid_argument for m < 1,
  /// m > kMaxKernelWidth, 4m + 2 > grid.n (the stencil would overlap its own periodic image) or
  /// a grid with L ≤ 0.
  Coupler(const GridSpec& grid, int kernel_width);
  /// Restricted to the x-planes of `slab` (see XSlab): spread() adds only the contributions that
  /// fall on these planes, interpolate() sums only over them (partial U, W; the sum over slabs
  /// that tile the grid is the whole-grid result up to round-off). No halo is needed: W uses
  /// u × ∇_h δ at the stencil points only. Also throws std::invalid_argument for a bad slab. A
  /// slab of all n planes from 0 is the whole grid (the same code and bits as the constructor
  /// above).
  Coupler(const GridSpec& grid, int kernel_width, XSlab slab);

  const GridSpec& grid() const { return grid_; }
  int kernel_width() const { return m_; }
  double c() const { return m_ * grid_.h(); }
  /// grid points per dimension that one point touches when spreading (support of φ plus the
  /// one-point halo of the curl): 4m + 2
  int stencil() const { return 4 * m_ + 2; }
  /// the x-planes the arrays hold ({0, n}: the whole grid)
  XSlab slab() const { return slab_; }

  /// Accumulates (+=) the force density of point forces F and torques T at X into f
  /// (g Å⁻² s⁻²). T may be empty (no torques). f: three distinct, non-overlapping arrays of
  /// grid().size() values, layout GridSpec::index (slab(): only its planes, see XSlab). Throws
  /// std::invalid_argument if F (or a non-empty T) differs in size from X, ibrod::RunError if a
  /// position is not finite or absurdly far out (|X_d| > 2⁴⁰ h). Race-free in parallel: the x axis
  /// is cut into an even number of slabs at least 4m + 2 wide, so a point's stencil touches only
  /// its own slab and the next; even slabs are done in parallel, then odd ones. Each grid value
  /// thus receives its contributions in a fixed order.
  void spread(std::span<const Vec3> X, std::span<const Vec3> F, std::span<const Vec3> T,
              std::array<double*, 3> f) const;

  /// Overwrites U (Å s⁻¹) and W (s⁻¹) with the interpolated velocity and angular velocity at X.
  /// W may be empty (not computed). u: three arrays of grid().size() values (slab(): its
  /// planes). Throws as spread()
  /// (U, and W unless empty, must have X's size).
  void interpolate(std::span<const Vec3> X, std::array<const double*, 3> u, std::span<Vec3> U,
                   std::span<Vec3> W) const;

 private:
  GridSpec grid_;
  int m_;
  int nslabs_;                ///< x slabs for race-free parallel spreading (1 or even)
  std::vector<int> slab_of_;  ///< [n] slab of each x index
  XSlab slab_;                ///< the x-planes of the arrays
  bool whole_ = true;         ///< slab_ is the whole grid
  /// true if the stencil of a point whose first wrapped x index is `first` meets slab_
  bool touches_slab(int first) const;
};

}  // namespace ibrod::ib
