#pragma once
// NumPy .npy writer for the fluid velocity (output.fluid_velocity): DIR/velocity.npy holds the
// velocity at the end of the run, float64, little-endian, C order, shape (3, n, n, n) =
// (component, i, j, k) with grid point (i, j, k) at x = (i, j, k) h, in Å/ns. Read with
// `np.load(DIR + "/velocity.npy")`. Used by python/grid_convergence.py (docs/sweeps.md).
//
// The run driver calls write_velocity_npy(RunDir::velocity(), n, u_x, u_y, u_z) once, after
// the last step, when Config::output_fluid_velocity is set.
#include <filesystem>
#include <vector>

namespace ibrod::io {

/// velocity.npy from three arrays of n³ values each in Å/s (layout GridSpec::index).
void write_velocity_npy(const std::filesystem::path& path, int n, const double* ux,
                        const double* uy, const double* uz);

}  // namespace ibrod::io
