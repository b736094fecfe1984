#pragma once
// The rod's shape from a file (`rod.initial_shape`): a run's final_state.csv, or one frame of an
// H5MD trajectory (trajectory.h5md), so that a run can start where another one ended.
#include <string>

#include "rod/rod.hpp"

namespace ibrod::io {

/// Reads positions (Å) and triads from `spec`:
///   "PATH"          a CSV file with the columns of final_state.csv (x_A,y_A,z_A,d1x,…,d3z);
///                   a PATH ending in ".h5" is read as "PATH@-1"
///   "PATH@FRAME"    frame FRAME of the H5MD file PATH (/particles/rod/position, d1, d2, d3);
///                   FRAME counts from 0, a negative FRAME from the end (−1: the last frame)
/// The numbers are returned exactly as stored (no re-orthonormalisation); the caller checks them
/// (sim::Simulation::set_rod_state). Throws ConfigError naming `key`, the file and the reason.
/// A final_state.csv of several rods (a first column `rod`) gives the rows of rod `rod_index`;
/// such a file read with rod_index < 0 is refused unless it holds one rod only.
rod::RodState read_rod_shape(const std::string& spec, const std::string& key, int rod_index = -1);

}  // namespace ibrod::io
