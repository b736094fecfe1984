#pragma once
// Spreading and interpolation one x-plane at a time (MODEL §4), the production path of a time
// step; the same sums as Coupler (ib/coupler.hpp), which it is tested against.
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "core/grid.hpp"
#include "core/types.hpp"
#include "ib/coupler.hpp"

namespace ibrod::ib {

/// Spreading and interpolation one x-plane at a time, for a fluid solver that assembles its
/// right-hand side plane by plane and produces its new velocity plane by plane
/// (FluidSolver::step(forcing, sampler)). The force density lands in a plane that is in cache (no
/// grid-sized force array is zeroed, written and read back), and the velocity is read while its
/// plane is in cache. prepare() evaluates every point's kernel weights once and lists, for each
/// x-plane, the points whose stencil meets it; add_plane() adds exactly the terms Coupler::spread
/// adds to that plane; sample_plane() takes the plane's share of Coupler::interpolate's sums and
/// finish_interpolation() adds the shares of each point in a fixed order. Both are bitwise
/// independent of the thread count; against Coupler they differ by round-off only (sums in
/// another order).
class PlaneCoupler {
 public:
  /// buffers for up to `npoints` points are made here; nothing is allocated after that
  PlaneCoupler(const Coupler& coupler, int npoints);

  const GridSpec& grid() const { return grid_; }

  /// Kernel weights and x-plane lists for points X with forces F and torques T (T may be empty;
  /// F may be empty if only interpolating). Keeps views of F and T: they must stay alive and
  /// unchanged until the last add_plane(). Throws as Coupler::spread.
  void prepare(std::span<const Vec3> X, std::span<const Vec3> F, std::span<const Vec3> T);

  /// Adds (+=) the force density (g Å⁻² s⁻²) of the prepared points to x-plane i: three arrays
  /// (components) of n·n values, layout j·n + k. May be called concurrently for different planes.
  void add_plane(int i, std::array<double*, 3> plane) const;

  /// Takes x-plane i's share of the interpolation sums from the velocity plane (same layout,
  /// Å s⁻¹). Call once for every plane (concurrently for different planes), then
  /// finish_interpolation().
  /// `points` < the prepared count: only the first `points` points are sampled (the others are
  /// spread only: the stochastic drift's force pairs), and finish_interpolation takes U, W of
  /// that many.
  void sample_plane(int i, std::array<const double*, 3> plane,
                    std::size_t points = std::size_t(-1));

  /// U (Å s⁻¹) and, unless W is empty, W (s⁻¹) at the prepared points, as Coupler::interpolate.
  /// With `points` (< the prepared count; as given to sample_plane): U, W of the first `points`.
  void finish_interpolation(std::span<Vec3> U, std::span<Vec3> W,
                            std::size_t points = std::size_t(-1)) const;

 private:
  GridSpec grid_;
  int m_, S_, P_;  ///< kernel width, stencil width 4m + 2, S padded to a multiple of 4
  std::size_t capacity_, npoints_ = 0;
  std::span<const Vec3> F_, T_;
  std::vector<int> first_;          ///< [k][3] first (wrapped) stencil index per dimension
  std::vector<double> phi_, dphi_;  ///< [k][3][P] φ_d (Å⁻¹), dφ_d (Å⁻²) of point k, 0-padded
  std::vector<int> plane_start_;  ///< [n + 2] CSR offsets into entries_ per x-plane
  std::vector<int> entries_;      ///< [2 per entry] (point k, x-stencil entry a), k ascending
  std::vector<int> entry_of_;     ///< [k][a] the entry of point k's x-stencil entry a
  std::vector<double> share_;     ///< [entry][6] Σ u w and Σ u × g over that entry's plane
};

}  // namespace ibrod::ib
