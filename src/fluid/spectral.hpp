#pragma once
// What FluidSolver and DistributedFluid share besides the advection pass (fluid/advection.hpp):
// the checks of their arguments and the per-direction Fourier symbols of the difference
// operators (MODEL §4).
#include <vector>

#include "core/grid.hpp"
#include "fluid/navier_stokes.hpp"

namespace ibrod::fluid::detail {

/// Throws std::invalid_argument, the message starting with `who`, unless n is even and ≥ 4 (the
/// r2c half-spectrum and the Nyquist handling assume it; ±1 and ±2 neighbours are then distinct
/// points), L > 0, ρ > 0, Δt > 0, μ ≥ 0 (which keep the implicit denominator ρ/Δt − μL̂ positive
/// for every k) and threads ≥ 0.
void check_fluid_args(const char* who, const GridSpec& grid, const FluidParams& params,
                      int threads);

/// The symbols per direction for k = 0..n−1 (MODEL §4): grad[k] = sin(2πk/n)/h (Å⁻¹), the
/// central difference G_h, and lap[k] = (4/h²) sin²(πk/n) (Å⁻²) = −L̂ per direction. grad is
/// exactly 0 at k = 0, n/2 and exactly odd, grad[n − k] = −grad[k], so the spectral multiplier
/// is exactly even in k, as the c2r transform assumes of a real field. Resizes both to n.
void make_spectral_symbols(int n, double h, std::vector<double>& grad, std::vector<double>& lap);

}  // namespace ibrod::fluid::detail
