#pragma once
// Random twist perturbations of the initial circle (MODEL §5: g(s) = Σ_m ε_m sin(m s/r0)), drawn
// reproducibly from a seed, for sampling many perturbations at one (ΔLk, Cs) (MODEL §7).
//
// Distribution: ε_m for m = 1..M is uniform on [−A, A) rad, drawn in order m = 1, 2, …, M from
// std::mt19937_64(seed) as ε_m = A (2u − 1) with u = (x >> 11) · 2⁻⁵³ and x the next 64-bit
// output of the engine. mt19937_64 is fully specified by the C++ standard and the mapping to u is
// written out here (std::uniform_real_distribution is not the same on every standard library),
// so a seed gives the same ε_m on every platform and compiler.
#include <cstdint>
#include <vector>

namespace ibrod::rod {

/// rod.perturbation_random = { modes = M, amplitude = A, seed = S }; M = 0 or A = 0: none.
struct RandomPerturbation {
  int modes = 0;           ///< M, number of modes m = 1..M
  double amplitude = 0.0;  ///< A, rad
  std::uint64_t seed = 0;  ///< S, seed of std::mt19937_64
  bool operator==(const RandomPerturbation&) const = default;
};

/// The M drawn amplitudes ε_1..ε_M, rad (see the file comment for the distribution).
std::vector<double> draw_perturbation(const RandomPerturbation& r);

/// The amplitudes the initial condition uses: the deterministic list plus the drawn one,
/// element by element (the longer of the two sets the length).
std::vector<double> combined_perturbation(const std::vector<double>& deterministic,
                                          const RandomPerturbation& r);

}  // namespace ibrod::rod
