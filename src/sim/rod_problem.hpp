#pragma once
// The sanity check of the rod after every step: what the blow-up guard of a run reports.
#include <span>
#include <string>

#include "rod/rod.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::sim {

/// Empty if the ring `s` (all its points, Δs = ds apart) is sane; otherwise what is wrong, naming
/// the point: a non-finite position or triad, the spacing of a link off Δs by more than
/// `tolerance` (relative; 50 % by default; never below 0.05 Δs), a triad off orthonormal by more
/// than 1e-3.
std::string rod_problem(const rod::RodState& s, double ds, double tolerance = 0.5);
/// The same for rod g (its Δs and links: an open rod has none between its last point and its
/// first) of the points X and triads D of a state of one or several rods; points are numbered
/// within the rod.
std::string rod_problem(std::span<const Vec3> X, std::span<const Mat3> D, const rod::RodRange& g,
                        double tolerance);

/// The spacing tolerance of rod_problem for a run: 0.5, or with thermal noise (docs/thermal.md)
/// seven standard deviations of the thermal stretch or shear of one segment,
/// 7 √(kT Δs / min(b1, b3)) / Δs (the softest link's with rod.moduli_file), if that is larger (0.94
/// · 7/6 for the reference parameters: a 50 % stretch is a 3σ event there, not a blow-up).
double spacing_tolerance(const rod::RodParams& rod, double thermal_kT);

/// Empty if `s` may be the rod laid out as g (g.n points, g.ds apart, its kind; g.offset is not
/// read: s holds that rod alone; an initial shape, a state set from Python); otherwise what is
/// wrong: a count of positions or triads other than g.n, what rod_problem finds, a left-handed
/// triad (det D < 0: D³ must be D¹ × D²), or a D³ more than 60° off the tangent X[k+1] − X[k−1]
/// (one-sided at an open rod's ends).
std::string state_problem(const rod::RodState& s, const rod::RodRange& g);
/// The same for a ring of n points Δs = ds apart.
std::string state_problem(const rod::RodState& s, int n, double ds);

/// The same for the rods of a state of one or several rods laid end to end (rod::RodRange): each
/// rod checked in place on its own points with its own Δs, end condition and spacing tolerance
/// (`tolerances`, one per rod: spacing_tolerance(rod, thermal_kT), computed once per run); with
/// several rods (rod::names_rods) "rod r: " heads what is wrong and point numbers count within
/// that rod; one rod: what rod_problem / state_problem find. A state whose size is not the rods'
/// total is a problem too. O(n), no allocation: the blow-up guard after every step.
std::string rods_problem(std::span<const rod::RodParams> rods, const rod::RodState& s,
                         std::span<const double> tolerances);
/// box > 0: the edge of the periodic box (internal units); two rods overlap if any of their points
/// are closer than half a rise across the box's faces too (the nearest periodic image).
std::string rods_state_problem(std::span<const rod::RodParams> rods, const rod::RodState& s,
                               double box = 0);

/// The smallest cosine between a triad's D³ and the rod's tangent that state_problem accepts
/// (60°: far beyond any shear a run reaches, far below a triad with rows and columns swapped).
inline constexpr double kMinTangentCosine = 0.5;

}  // namespace ibrod::sim
