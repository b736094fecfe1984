#pragma once
// Topology and geometry of a closed rod (MODEL §6). Pure functions, O(n²) where noted: call them
// at output steps only.
#include <span>

#include "core/types.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::diagnostics {

/// Writhe of the closed polygon X_0 … X_{n−1} (X_n = X_0), exact for polygons (the Gauss double
/// integral as a sum of signed solid angles of segment pairs): Wr = (1/2π) Σ_{i<j, not adjacent}
/// Ω_ij. O(n²), OpenMP over rows; the result does not depend on the thread count (its cost:
/// BM_Writhe in docs/performance.md).
double writhe(std::span<const Vec3> X);

/// Twist of the ribbon (X, d1) about the closed polygon X, in turns: the total rotation of d1
/// relative to the polygon's discrete parallel transport, divided by 2π. With this definition
/// twist(X, d1) + writhe(X) equals the linking number of X with X + ε d1 (an integer) for
/// small ε. O(n).
/// Exactly, with t_k the unit tangent of edge X_k → X_{k+1}, P_k(v) = v − (v·t_k) t_k, R_k the
/// minimal rotation taking t_{k−1} to t_k, and ∠_t(p, q) ∈ (−π, π] the right-handed angle about t:
///   2π Tw = Σ_k ∠_{t_k}(P_k d1_k, P_k d1_{k+1}) + ∠_{t_{k+1}}(R_{k+1} P_k d1_{k+1}, P_{k+1}
///   d1_{k+1}).
/// d1 need be neither unit nor ⟂ to the edges (it is projected), but must not lie along one, and
/// its projection must turn by less than π per edge and per vertex. d1.size() ≠ X.size() throws
/// std::invalid_argument.
double twist(std::span<const Vec3> X, std::span<const Vec3> d1);

/// Twist of the ribbon (X, d1) about the open polygon X_0 … X_{n−1} (an open rod), in turns: the
/// same sum as twist() over the n − 1 edges and the n − 2 interior vertices only (no closing edge).
/// Not a topological quantity: an open rod has no link and no writhe that its ends cannot undo,
/// and the total rotation of d1 is what is reported. 0 for n < 2.
double twist_open(std::span<const Vec3> X, std::span<const Vec3> d1);

/// Gauss linking number of two disjoint closed polygons A and B (exact solid-angle sum). O(n·m).
/// Gauss's sign convention, shared with writhe and twist: +1 when B threads A once along A's
/// right-hand normal, and +m for a planar curve and a d1 turning m times right-handedly about
/// its tangent.
double linking_number(std::span<const Vec3> A, std::span<const Vec3> B);

/// min |X_i − X_j| over pairs whose cyclic index distance is at least min_separation, Å. O(n²).
/// +∞ when no pair qualifies (n < 2·min_separation); see closest_pair. closed = false (an open
/// rod): the index distance is |i − j|.
double closest_approach(std::span<const Vec3> X, int min_separation, bool closed = true);

/// mean |X_{k+1} − X_k| over the closed polygon (n edges), or over the open one's n − 1 edges, Å.
/// O(n).
double mean_spacing(std::span<const Vec3> X, bool closed = true);

/// Whether a rod's writhe and linking number are defined: a closed rod's are (topological); an
/// open rod's free ends can undo them, so they are "not defined" (NaN; docs/model.md "Open
/// rods"). For several rods: every rod's (the collection's sums of writhe and link are then
/// defined, and the progress lines and summary.json report them).
bool link_defined(const rod::RodRange& g);
bool link_defined(std::span<const rod::RodRange> rods);

/// One rod's row of the time series (MODEL §6): writhe, twist and link (link = Wr + Tw) where
/// link_defined; else the rod's twist (twist_open), its writhe and link NaN ("not defined"); the
/// closest approach over pairs at least min_separation apart along the rod, the mean spacing and
/// the count of links (rod::links). X, d1: the points and their directors D¹ of the whole
/// collection, of which rod g is X[g.offset] … X[g.offset + g.n − 1].
struct RodTopology {
  double writhe, twist, link, closest, spacing;  ///< spacing: the mean, Å
  int links;
};
RodTopology rod_topology(std::span<const Vec3> X, std::span<const Vec3> d1, const rod::RodRange& g,
                         int min_separation);

// ---- additions (the pieces the functions above are built from; exposed for tests and debugging)

/// The Gauss double integral ∫∫ (dr₁ × dr₂)·(r₁ − r₂)/|r₁ − r₂|³ over the straight segments
/// p1→p2 and p3→p4, evaluated exactly: the signed solid angle (sr, in (−2π, 2π)) that the flat
/// parallelogram {r₂ − r₁} subtends at the origin (Klenin & Langowski 2000, method 1b). Zero for
/// coplanar segments; undefined if the segments touch. writhe = Σ_{i≠j} Ω_ij / 4π,
/// linking_number = Σ_{i,j} Ω_ij / 4π.
double segment_pair_solid_angle(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& p4);

/// A closest non-local pair: distance (Å) and vertex indices i < j.
struct ClosestPair {
  double distance = 0;
  int i = -1;
  int j = -1;
};

/// The pair that closest_approach measures. min_separation < 1 counts as 1 (distinct vertices);
/// with no admissible pair (n < 2·min_separation) returns {+∞, −1, −1}. O(n²).
ClosestPair closest_pair(std::span<const Vec3> X, int min_separation, bool closed = true);

}  // namespace ibrod::diagnostics
