#pragma once
// The sanity check of the rod after every step: what the blow-up guard of a run reports.
#include <string>

#include "rod/rod.hpp"

namespace ibrod::sim {

/// Empty if the rod is sane; otherwise what is wrong, naming the point: a non-finite position or
/// triad, an adjacent spacing off Δs by more than 50 %, a triad off orthonormal by more than 1e-3.
std::string rod_problem(const rod::RodState& s, double ds);

}  // namespace ibrod::sim
