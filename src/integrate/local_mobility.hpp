#pragma once
// The kernel overlap of the IB coupling, the local mobility with the kernel's near-null space
// (issue 24, docs/large_dt.md "A local mobility with the kernel's null space").
//
// The Stokes mobility of the rod's points is M = 𝒥 G 𝒮: spreading 𝒮 of the point forces and
// torques (F_k, T_k) to the grid, the Stokes solve G = (−μL_h)⁻¹P, interpolation 𝒥 = 𝒮ᵀ of the
// velocity and angular velocity (ib/coupler.hpp). Dropping the fluid solve leaves the overlap
//   O = 𝒥 𝒮,   O (F, T) = interpolate(spread(F, T))
// a sparse, symmetric positive semi-definite 6n × 6n matrix whose (j, k) block is non-zero only
// where the two points' kernels overlap (|X_j,d − X_k,d| < 4c in each dimension: along the rod and
// across close strands). It shares M's near-null space: a displacement pattern that the kernel
// averages away (wavelength along the rod below ~3h) has 𝒮 g ≈ 0, so both O g and M g vanish,
// whereas the diagonal self mobility moves every pattern alike. With D = diag(√c_t I, √c_r I)
// per point, c_t, c_r fixing the self blocks to the self mobilities m_t, m_r,
//   M_loc = β D O D
// is within a factor 0.2–1.8 of M on every Fourier mode of a straight line of points at the
// reference spacing (prototypes/large_dt/mobility_spectrum.py), where β m_t I ranges over 0.008–2.
//
// The blocks, with w_j = δ_c(x − X_j), g_j = ∇_h w_j (the central-difference gradient of the
// kernel, ib/kernel.hpp) and sums over grid points times h³:
//   FF: Σ w_j w_k I        FT (U_j from T_k): ½ [Σ w_j g_k]×
//   TF: −½ [Σ w_k g_j]×    TT (W_j from T_k): ¼ (Σ g_j·g_k I − Σ g_k g_jᵀ)
// Each sum factorises over the three dimensions into 1-D sums of φ and dφ.
#include <Eigen/Sparse>
#include <span>
#include <vector>

#include "core/grid.hpp"
#include "core/types.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::integrate {

/// O = 𝒥 𝒮 at positions X for kernel width m (c = m h), 6n × 6n, per point (x, y, z, θx, θy, θz);
/// units Å⁻³ (FF), Å⁻⁴ (FT, TF), Å⁻⁵ (TT). The overlapping pairs are found among the points whose
/// stencils start within 4m + 1 x planes of each other (a counting sort by x plane, then integer
/// comparisons of the y and z indices, periodically); the sums are O(m) per overlapping pair.
/// Throws std::invalid_argument for m < 1, m > ib::kMaxKernelWidth or 2 (4m + 2) > grid.n.
Eigen::SparseMatrix<double> kernel_overlap(std::span<const Vec3> X, const GridSpec& grid, int m);

/// The overlap of the points of rods laid end to end (rod::RodRange, covering X), tapered along
/// each rod with the distance d along it (rod::arc_separation: |j − k|, round a ring the shorter
/// way): block (j, k) of two points of one rod times max(0, 1 − d/window); of two rods, 0 (as far
/// apart along a rod as can be). The taper is a positive semi-definite matrix on each rod (its
/// spectrum is a Fejér kernel; closed rods need n ≥ 2·window), zero between them, so the Schur
/// product stays positive semi-definite (Schur's product theorem). With a window wider than the
/// kernel's reach along the rod (4c / spacing points) it keeps each rod's own overlap nearly whole
/// and drops that of strands far apart along the rod but close in space, which would make the local
/// system's factorisation no longer banded. window ≤ 0: no taper (the rods are then not read).
Eigen::SparseMatrix<double> kernel_overlap(std::span<const Vec3> X, const GridSpec& grid, int m,
                                           double window, const std::vector<rod::RodRange>& rods);

}  // namespace ibrod::integrate
