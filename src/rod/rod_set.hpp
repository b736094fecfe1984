#pragma once
// Several rods in one state (`[[rods]]`, docs/model.md "Several rods"): the rods' points and
// triads lie end to end in one RodState (rod 0's first, then rod 1's, …), so the fluid, the
// coupling and the pair forces see one list of points; each rod keeps its own RodParams (its n,
// Δs, moduli, intrinsic strains, closed or open) and its elastic forces are computed on its own
// range. The helpers here cut a rod out of the whole state and place a shape in the box.
#include <span>
#include <vector>

#include "rod/rod.hpp"

namespace ibrod::rod {

/// The layout of one rod of a collection: where its points lie in the whole state (points
/// offset … offset + n − 1), closed or open, and its spacing Δs (Å). The one layout type of the
/// code: the stepper's and the implicit scheme's per-rod loops, the steric segments
/// (interactions::StericParams::rods), the outputs and the pictures all take it.
struct RodRange {
  int offset = 0;
  int n = 0;
  bool closed = true;
  double ds = 3.4;  ///< Å
};

/// The ranges of rods laid end to end, in order (each rod's n, closed and Δs).
std::vector<RodRange> ranges_of(std::span<const RodParams> rods);

/// Copies rod r's positions and triads out of the whole state into `out` (resized only when its
/// size differs, so a reused `out` allocates nothing).
void extract(const RodState& all, const RodRange& r, RodState& out);

/// Copies `one` (r.n points) back into rod r's range of the whole state.
void insert(RodState& all, const RodRange& r, const RodState& one);

/// Appends a rod's state to the whole state.
void append(RodState& all, const RodState& one);

/// The rotation of `angles_deg` = (α, β, γ) degrees about the fixed x, then y, then z axes:
/// R = R_z(γ) R_y(β) R_x(α).
Mat3 rotation_xyz_deg(const Vec3& angles_deg);

/// Turns a shape rigidly about the centroid of its points by R and then moves the centroid by
/// `shift` (Å): positions X_k → c + shift + R (X_k − c), triads D_k → R D_k.
void place(RodState& s, const Mat3& R, const Vec3& shift);

}  // namespace ibrod::rod
