#pragma once
// FFTW wisdom: the plans that FFTW_MEASURE chose, saved as text. FFTW_MEASURE times candidate
// algorithms, so two processes may pick different plans for the same grid, and different plans
// round differently. A process that imports the wisdom of another before it constructs its
// FluidSolver makes the same plans, hence bit-for-bit the same velocities (the run driver keeps
// the wisdom of each run in its output directory for `ibrod run --resume`).
#include <string>

namespace ibrod::fluid {

/// Adds the wisdom in `path` to this process's planner (before any FluidSolver is made).
/// Returns false if the file cannot be read or is not FFTW wisdom.
bool import_wisdom(const std::string& path);

/// Writes all wisdom this process has accumulated to `path`. Returns false on failure.
bool export_wisdom(const std::string& path);

}  // namespace ibrod::fluid
