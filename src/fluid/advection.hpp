#pragma once
// Internal to src/fluid (the tests use it directly): the real-space half of the fluid step of
// MODEL §4, i.e. the right-hand side r = ρuⁿ/Δt − ρS_h(uⁿ) + fⁿ, assembled in one fused pass.
//
// Skew-symmetric advection, component i (central differences D_j, spacing h):
//   S_h(u)_i = ½ Σ_j [u_j D_j u_i + D_j(u_j u_i)]
//            = (1/4h) Σ_j [(u_j + u_j⁺ʲ) u_i⁺ʲ − (u_j + u_j⁻ʲ) u_i⁻ʲ],
// where u⁺ʲ, u⁻ʲ are u at x ± h e_j. The second (flux) form is what the code evaluates: six face
// fluxes per point, then 6 products per component. Summation by parts on the periodic grid gives
// Σ_x u·S_h(u) = 0 for every u (divergence-free or not): advection does no work.
#include <array>
#include <vector>

#include "core/grid.hpp"

namespace ibrod::fluid::detail {

/// next[i] = (i + 1) mod n, prev[i] = (i − 1) mod n, i = 0..n−1.
inline void make_neighbour_tables(int n, std::vector<int>& next, std::vector<int>& prev) {
  next.resize(n);
  prev.resize(n);
  for (int i = 0; i < n; ++i) {
    next[i] = i + 1 == n ? 0 : i + 1;
    prev[i] = i == 0 ? n - 1 : i - 1;
  }
}

/// One x-plane of the pass below, serial (the building block of the whole-grid passes and of
/// slab-distributed solvers): r_c = a·u_c − b·S_h(u)_c (assign) or r_c += … at the n×n points of
/// one plane, layout j·n + k. uc, uxp, uxm: the three velocity components on this plane and on
/// the planes at x + h and x − h; r: the three output planes (must not overlap u). next/prev:
/// make_neighbour_tables(n) (the y and z neighbours wrap periodically within the plane). h in Å.
void rhs_plane(int n, double h, const int* next, const int* prev, std::array<const double*, 3> uc,
               std::array<const double*, 3> uxp, std::array<const double*, 3> uxm,
               std::array<double*, 3> r, double a, double b, bool assign);

/// At every grid point, r_c += a·u_c − b·S_h(u)_c (c = 0, 1, 2). In the fluid step a = ρ/Δt
/// (g Å⁻³ s⁻¹) and b = ρ (g Å⁻³), u in Å s⁻¹, r in g Å⁻² s⁻². b == 0 skips the advection
/// arithmetic altogether (Stokes). next/prev: tables of make_neighbour_tables(grid.n). u and r
/// must not overlap. One OpenMP-parallel pass over x-planes with `threads` threads; no allocation.
void accumulate_rhs(const GridSpec& grid, const int* next, const int* prev,
                    std::array<const double*, 3> u, std::array<double*, 3> r, double a, double b,
                    int threads);

}  // namespace ibrod::fluid::detail
