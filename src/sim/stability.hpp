#pragma once
// The stability-aware stop ([study]): E_K below time.stop_kinetic_kT is necessary for an
// equilibrium, not sufficient — the twisted circle above the Michell threshold, or a symmetric
// transient, is an unstable equilibrium at which E_K decays as a power law while the unstable
// mode grows from almost nothing. So when the kinetic-energy rule fires, the state is tested by
// integrating two copies of it for a probe time T:
//
//   1. save the rod (X, D), the fluid velocity, the clock and the implicit controller's state;
//      E₀ = E_total of the state
//   2. the continuation: integrate the state as it is for T; E_c = E_total at its end; put the
//      saved state back
//   3. the kicked copy: each rod of the collection in turn (several rods, issue 25: every rod on
//      its own points, about its own centroid and plane; an open rod with one-sided tangents at
//      its ends), move the positions out of the rod's mean plane,
//        δX_k = a n [cos(2φ_k + φ₂) + u₃ cos(3φ_k + φ₃)]
//      (n the normal of the plane of least gyration, φ_k the azimuth of X_k about the centroid
//      in that plane, a the amplitude in Å, u₃ uniform in [−1, 1), φ₂, φ₃ uniform in [0, 2π)),
//      turn each triad by the smallest rotation that takes its old tangent to the new one (a pure
//      bend, no twist), then perturb the twist: D_k ← R(g(s_k) D³_k) D_k,
//      g(s) = A Σ_{m=1..M} u_m sin(m s/r0 + ψ_m) (zero mean: the link is unchanged; A in rad);
//      all drawn from std::mt19937_64(seed + probe index), 53-bit uniforms, rod after rod from
//      the one generator (rod 0 gets the kick a run of it alone gets); integrate for T;
//      E₁ = E_total at its end
//   4. both copies' E_total are sampled at 100 equal divisions of T; unstable if at any sample
//      E₁(τ) < E_c(τ) − tolerance (E_c interpolated to the kicked copy's sample times): the
//      kicked copy found somewhere lower to go than the unperturbed state does. Then the run
//      goes on from the kicked copy's end (its time included). Stable otherwise: the saved
//      state is put back and the run stops as an equilibrium.
//
// Why against the continuation and not against E₀: a state the rule stops at is still settling
// (its energy keeps falling by more than the kick's signal), and near the Michell threshold the
// unstable mode grows slowly (σ ≈ 0.18/µs at ΔLk = 2 for 600 bp), so the kick's energy changes
// by ~1e-4 kT in 2 µs; both copies settle alike, so their difference isolates the kick. A
// stable state's kick relaxes from above (E₁ − E_c = ½ δqᵀHδq > 0, decaying); an unstable one
// crosses below. Why at any time and not only at T: a strongly unstable state (a small ring far
// above the threshold) leaves on its own within T, round-off seeding the mode; the kicked copy
// leaves first and is far below the continuation half-way, but by T both have reached the
// same buckled state and their difference has either sign (measured: docs/study.md). The
// out-of-plane kick seeds the writhing (figure-8, m = 2) mode directly; a twist kick alone reaches
// it only through the twist–writhe coupling (docs/study.md measures both). The test is serial-only
// (a distributed fluid would have to be gathered to be saved); deterministic, so a resumed run
// probes alike.
//
// The Hessian method (time.stability_method = "hessian"). The dynamic test misses a slowly
// unstable state whose stable modes relax slowly too: on the reference ΔLk = 2 circle (600 bp,
// 0.1 M) with dynamics that follow the explicit scheme's, the kicked copy stays +5e-4 kT above the
// continuation after 2 µs and +1e-4 kT after 6 µs, so the unstable circle is called stable
// (docs/study.md). For overdamped dynamics q̇ = −M ∇E, M symmetric positive definite, −M H has as
// many growing modes as H has negative eigenvalues (Sylvester's law of inertia), whatever M is.
// So: H = −∂(F, T)/∂(X, ℓθ) by central differences of System::compute_forces (every term: elastic,
// electrostatic, steric, external; θ the space-frame rotation vector of a triad, ℓ = the first
// rod's Δs puts rotations in Å), symmetrised; the six rigid-body modes and, for each rod with
// isotropic bending, the uniform spin of its triads about their tangents (zero modes of E) are
// projected out (exactly: at a state that is not quite critical an invariance couples to the
// other modes through the gradient, H ξ = −(Dξ)ᵀ∇E, and the unprojected H of a toroid has a
// spurious negative eigenvalue), and so is each uniform closed rod's slithering along its own
// contour (slithering_vector below: a near-invariance of the discrete ring, left out where the
// rigid modes and the spin already span it to within kSlitherResidual, as on a circle); λ₁ is
// its lowest other eigenvalue, v₁ its unit vector. A kick of amplitude a
// along v₁ (scaled so that the largest point's (δX, ℓδθ) has length a) changes the energy by
// ½ λ₁ s², s = a / max_k |v₁,k|: unstable if that is below −tolerance, and then the run goes on
// from the state kicked so (the test takes no simulated time). Cost: 2 × 6n force evaluations
// and a dense eigensolve (~15 s of one core at 600 points), at most kMaxHessianPoints points.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "rod/rod.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::sim {

class Simulation;

struct StabilityProbe {
  /// dynamic: the two copies above. hessian: the lowest eigenvalue of the total energy's Hessian
  /// (the Hessian method above).
  enum class Method { dynamic, hessian };
  static constexpr int kMaxHessianPoints = 1500;  ///< dense: (6n)² doubles, O((6n)³) eigenvalues
  /// time.stability_method = "auto" takes the Hessian up to this many rod points (the 600-point
  /// reference ring: 1–1.5 min a test on one core; the cost grows as n³)
  static constexpr int kAutoHessianPoints = 1000;
  /// a closed uniform rod's slithering is projected out where the part of it that the rigid modes
  /// and the spin leave is longer than this fraction of it (a circle's slithering is a rotation
  /// plus the spin: nothing is left)
  static constexpr double kSlitherResidual = 0.1;
  Method method = Method::dynamic;
  bool enabled = true;
  double amplitude = 0.05;  ///< A, rad (the twist kick)
  double kick = 1.0;        ///< a, Å (the out-of-plane kick of the positions)
  int modes = 4;            ///< M
  double time = 2e-6;       ///< probe time T, s
  double tolerance = 0;     ///< how far below the continuation counts, g Å² s⁻²
  std::uint64_t seed = 1;
};

struct ProbeOutcome {
  bool stable = true;
  std::int64_t step = 0;   ///< the step the probe started at
  double time_us = 0;      ///< its time
  std::int64_t steps = 0;  ///< steps of the kicked copy
  double duration_us = 0;  ///< time the kicked copy integrated (≥ T; adaptive Δt: not steps × Δt)
  std::int64_t continuation_steps = 0;  ///< steps of the unperturbed continuation
  double E_before_kT = 0, E_continuation_kT = 0, E_after_kT = 0;  ///< E₀, E_c, E₁
  double writhe_before = 0, writhe_continuation = 0, writhe_after = 0;
  /// the lowest E₁(τ) − E_c(τ) over the probe (kT; sampled 100 times, E_c interpolated to the
  /// kicked copy's sample times) and when (µs after the kick)
  double min_difference_kT = 0, min_difference_after_us = 0;
  // hessian: min_difference_kT is ½ λ₁ s², the energy a kick of amplitude a along the softest
  // mode changes by (s: its length when its largest point moves by a); steps and durations 0
  bool hessian = false;
  std::vector<double> lowest_eigenvalues;  ///< the lowest of H less the rigid modes, kT/Å²
  int negative_modes = 0;                  ///< eigenvalues whose kick lowers E by > tolerance
  int zero_modes = 0;                      ///< modes projected out: rigid-body, spin, slithering
  int slithering_modes = 0;                ///< of which slithering (per uniform closed rod)
  double gradient_kT_per_A = 0;            ///< |∇E| at the state (rotations per length ℓ)
  double asymmetry = 0;                    ///< ‖H − Hᵀ‖/‖H‖ before symmetrising
};

/// Runs the probe on `sim` (see the file comment); `index` counts the probes of the run (seed +
/// index draws the perturbation). Leaves sim at the saved state if stable, at the probe's end if
/// not.
ProbeOutcome probe_stability(Simulation& sim, const StabilityProbe& p, std::uint64_t index);

/// Whether a closed rod's energy is invariant under the slithering of its material along its own
/// contour, X(s) → X(s + ε), D(s) → D(s + ε): iff it is closed and uniform (the same moduli and
/// intrinsic strains at every link). Exact for the smooth rod; for the discrete ring the shift by
/// one point is the exact symmetry and the slithering below a near one, O(Δs²).
bool slither_invariant(const rod::RodParams& r);

/// The slithering of the closed rod at points [g.offset, g.offset + g.n) of s, in the Hessian's
/// coordinates (δX_k, ℓδθ_k) of all s.size() points (zero outside the rod): δX_k = (X_{k+1} −
/// X_{k−1})/2 and δθ_k the mean of the space-frame rotation vectors taking D_{k−1} to D_k and D_k
/// to D_{k+1} (indices cyclic within the rod).
Eigen::VectorXd slithering_vector(const rod::RodState& s, const rod::RodRange& g, double ell);

/// One line for logs: "stable: kicked − continuation = +3.7e-05 kT …" or "unstable: …".
std::string describe(const ProbeOutcome& o);

}  // namespace ibrod::sim
