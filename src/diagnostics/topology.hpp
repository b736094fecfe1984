#pragma once
// Topology and geometry of a closed rod (MODEL §6). Pure functions, O(n²) where noted: call them
// at output steps only.
#include <span>

#include "core/types.hpp"

namespace ibrod::diag {

/// Writhe of the closed polygon X_0 … X_{n−1} (X_n = X_0), exact for polygons (the Gauss double
/// integral as a sum of signed solid angles of segment pairs). O(n²).
double writhe(std::span<const Vec3> X);

/// Twist of the ribbon (X, d1) about the closed polygon X, in turns: the total rotation of d1
/// relative to the polygon's discrete parallel transport, divided by 2π. With this definition
/// twist(X, d1) + writhe(X) equals the linking number of X with X + ε d1 (an integer) for
/// small ε. O(n).
double twist(std::span<const Vec3> X, std::span<const Vec3> d1);

/// Gauss linking number of two disjoint closed polygons A and B (exact solid-angle sum). O(n·m).
double linking_number(std::span<const Vec3> A, std::span<const Vec3> B);

/// min |X_i − X_j| over pairs whose cyclic index distance is at least min_separation, Å. O(n²).
double closest_approach(std::span<const Vec3> X, int min_separation);

/// mean |X_{k+1} − X_k| over the closed polygon, Å. O(n).
double mean_spacing(std::span<const Vec3> X);

}  // namespace ibrod::diag
