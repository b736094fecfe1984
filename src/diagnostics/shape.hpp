#pragma once
// The shape of a closed rod (issue 15 item 2; criteria in docs/analysis.md "Shapes"): crossings
// in the projection with fewest crossings (and the most frequent count), lobes, two-ply
// (interwound) runs, contacts, and the class (circle, figure-8, plectonemic, toroidal, other). Pure
// functions of the centreline X_0 … X_{n−1} (closed: X_n = X_0), Å, assumed about evenly spaced (a
// rod). O(n²) at most.
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/types.hpp"

namespace ibrod::diagnostics {

/// Thresholds of the shape analysis (all lengths in Å).
struct ShapeOptions {
  double contact_distance_A = 50;  ///< d_c: two stretches closer than this are in contact (the
                                   ///< analysis uses D + 3 λ_D; docs/analysis.md)
  double min_separation_A = 0;     ///< pairs closer along the rod than this are local, never in
                                   ///< contact; 0: 2 d_c (a U-turn of diameter d_c is π d_c / 2)
  double min_interwound_A = 0;     ///< shortest two-ply run that counts; 0: 3 d_c
  int directions = 200;            ///< projection directions (Fibonacci points on a hemisphere)
  double lobe_prominence = 0.25;   ///< a lobe: a maximum of |X − centroid| along the rod that
                                   ///< stands out by this fraction of the largest
};

enum class ShapeClass { circle, figure8, plectonemic, toroidal, other };

/// "circle", "figure-8", "plectonemic", "toroidal", "other".
const char* shape_class_name(ShapeClass c);

struct Shape {
  ShapeClass cls = ShapeClass::other;
  int crossings = 0;        ///< fewest crossings over the projection directions
  Vec3 direction{0, 0, 1};  ///< a direction (unit) that gives them
  int crossings_mode = 0;   ///< the most frequent count over the directions (what a random view
                            ///< most likely shows; the class uses it: the fewest is 0 for a
                            ///< nearly planar figure-8 seen edge-on)
  int lobes = 0;            ///< prominent maxima of |X_k − centroid| along the rod
  int loops = 0;            ///< terminal loops: plectonemic: arcs outside the two-ply runs;
                            ///< figure-8 2; toroidal: lobes; circle 1 (the ring); other: lobes
  double interwound_length_A = 0;  ///< length of the two-ply region (one ply: half the contour
                                   ///< length in accepted two-ply runs)
  int interwound_runs = 0;         ///< accepted two-ply runs (each ply of a region is one run)
  int contact_clusters = 0;        ///< contact_clusters(X, d_c, s_min).size()
};

/// The analysis above with `opt`; needs n ≥ 8 points (std::invalid_argument otherwise).
Shape analyze_shape(std::span<const Vec3> X, const ShapeOptions& opt = {});

// ---- the pieces (exposed for tests and for the contact-based relaxation window)

/// n unit vectors spread evenly over the upper hemisphere (z > 0; Fibonacci lattice): a
/// projection along u and along −u are the same.
std::vector<Vec3> hemisphere_directions(int n);

/// Proper crossings of non-adjacent edges of the closed polygon X projected along `direction`
/// onto the plane normal to it. Sweep over the projected edges sorted by x: O(n log n + pairs
/// whose x-ranges overlap).
int projected_crossings(std::span<const Vec3> X, const Vec3& direction);

/// Distance between the segments p0→p1 and q0→q1 (closest points, clamped to the segments).
double segment_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

/// Contacts: edge pairs (i < j; edge k is X_k → X_{k+1}) whose segment distance is below
/// `distance` and whose separation along the rod, min(j − i, n − j + i) · mean spacing, is at
/// least `min_separation`. Grouped into clusters: two contact pairs are in one cluster when
/// their indices differ by at most 1 in each entry (cyclically). Each cluster is its pairs,
/// sorted. O(n²).
std::vector<std::vector<std::pair<int, int>>> contact_clusters(std::span<const Vec3> X,
                                                               double distance,
                                                               double min_separation);

}  // namespace ibrod::diagnostics
