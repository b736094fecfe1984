#pragma once
// Several rods in one state (`[[rods]]`, docs/model.md "Several rods"): the rods' points and
// triads lie end to end in one RodState (rod 0's first, then rod 1's, …), so the fluid, the
// coupling and the pair forces see one list of points; each rod keeps its own RodParams (its n,
// Δs, moduli, intrinsic strains, closed or open) and its elastic forces are computed on its own
// range. The helpers here cut a rod out of the whole state and place a shape in the box.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <span>
#include <string>
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

// ---- A rod's kind, closed ring or open rod, answered here once: the kernels callers take
// instead of branching on RodRange::closed (ARCHITECTURE.md "How many places a kind of rod or a
// count of rods reaches"). Point indices k are the rod's own, 0 … n − 1 (add g.offset for the
// whole state's).

/// Whether the rod wraps round: a ring, its last point linked back to its first (X_n = X_0), so
/// that every band along it (the implicit scheme's stiffness) is cyclic.
inline bool wraps(const RodRange& g) { return g.closed; }
/// The rod's links (half points k+½, segments X_k → X_{k+1}, k = 0 … links − 1): n of a ring,
/// n − 1 of an open rod (0 for no points).
inline int links(const RodRange& g) { return half_points(g.n, g.closed); }
inline int links(const RodParams& r) { return half_points(r.n, r.closed); }
/// The point o steps along rod g from its point k (o < 0: backwards): round a ring modulo n,
/// −1 past an open rod's ends.
inline int along(const RodRange& g, int k, int o) {
  if (!g.closed) return k + o >= 0 && k + o < g.n ? k + o : -1;
  return ((k + o) % g.n + g.n) % g.n;
}
/// The point before k, after k (along(g, k, ∓1)): −1 past an open rod's ends.
inline int before(const RodRange& g, int k) { return along(g, k, -1); }
inline int after(const RodRange& g, int k) { return along(g, k, 1); }
/// The points of a central difference at k: before / after k, or k itself at an open rod's end
/// (one-sided there): point_before / point_after of the rod's n and kind.
inline int point_before(const RodRange& g, int k) { return point_before(k, g.n, g.closed); }
inline int point_after(const RodRange& g, int k) { return point_after(k, g.n, g.closed); }
/// How far apart along rod g its points (or links) i and j are, in steps: |i − j|, round a ring
/// the shorter way, min(|i − j|, n − |i − j|).
inline int arc_separation(const RodRange& g, int i, int j) {
  const int m = std::abs(i - j);
  return g.closed ? std::min(m, g.n - m) : m;
}
/// The same for two places a, b along rod g given by their arc lengths from its first point, the
/// rod's length (its links' lengths summed) `length`: |a − b|, round a ring the shorter way,
/// min(|a − b|, length − |a − b|).
inline double arc_distance(const RodRange& g, double a, double b, double length) {
  const double d = std::abs(a - b);
  return g.closed ? std::min(d, length - d) : d;
}

// ---- The operations callers outside src/rod take instead of asking how many rods there are
// (ARCHITECTURE.md "How many places a kind of rod or a count of rods reaches"): they loop over the
// collection, and one rod is a collection of one.

/// Calls f(r, range) for each rod r of `rods` laid end to end, in order, without allocating
/// (the ranges ranges_of would return).
template <class F>
void for_each_range(std::span<const RodParams> rods, F&& f) {
  int offset = 0;
  for (std::size_t r = 0; r < rods.size(); ++r) {
    f(r, RodRange{offset, rods[r].n, rods[r].closed, rods[r].ds});
    offset += rods[r].n;
  }
}
/// Calls f(r, range) for each rod r, in order.
template <class F>
void for_each_rod(std::span<const RodRange> rods, F&& f) {
  for (std::size_t r = 0; r < rods.size(); ++r) f(r, rods[r]);
}
/// Calls f(a, b) for each pair of rods a < b, in the order (0,1), (0,2), …, (1,2), … (none for a
/// collection of one): the pair links, the contacts between rods.
template <class F>
void for_each_pair(std::span<const RodRange> rods, F&& f) {
  for (std::size_t a = 0; a < rods.size(); ++a)
    for (std::size_t b = a + 1; b < rods.size(); ++b) f(a, b);
}

/// The rods' points together.
int total_points(std::span<const RodRange> rods);
int total_points(std::span<const RodParams> rods);

/// Whether the files and messages of a run of these rods name each rod: a `rod` column in
/// final_state.csv, the .vtp and the H5MD species, rods.csv (each rod's writhe, twist and link),
/// "rod r: " before what is wrong with rod r, "N rods" in a picture's label. A collection of one
/// names none: its files are those of the one rod runs wrote before there were several (and so
/// stay byte-identical; its per-rod values are the totals). The one place that layout is decided.
bool names_rods(std::span<const RodRange> rods);
bool names_rods(std::span<const RodParams> rods);

/// "rod r: " where names_rods(rods), else "": what heads a message about rod r.
std::string message_prefix(std::span<const RodRange> rods, std::size_t r);
std::string message_prefix(std::span<const RodParams> rods, std::size_t r);

/// "N rod points (rods: K)": the collection in a run's first line.
std::string describe(std::span<const RodRange> rods);
/// "K rods": the collection in a picture's label.
std::string count_label(std::span<const RodRange> rods);

/// Whether the collection is one closed curve: what the shape classes (diagnostics::shape: lobes,
/// two-ply runs; of one ring) and the excess link of `[rod]` describe.
bool one_ring(std::span<const RodRange> rods);

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
