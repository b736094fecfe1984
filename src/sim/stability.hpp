#pragma once
// The stability-aware stop ([study]): E_K below time.stop_kinetic_kT is necessary for an
// equilibrium, not sufficient — the twisted circle above the Michell threshold, or a symmetric
// transient, is an unstable equilibrium at which E_K decays as a power law while the unstable
// mode grows from almost nothing. So when the kinetic-energy rule fires, a copy of the state is
// perturbed and integrated for a probe time:
//
//   1. save the rod (X, D), the fluid velocity, the step and the time; E₀ = E_total of the state
//   2. perturb the twist: D_k ← R(g(s_k) D³_k) D_k, g(s) = A Σ_{m=1..M} u_m sin(m s/r0 + φ_m),
//      u_m uniform in [−1, 1) and φ_m uniform in [0, 2π) from std::mt19937_64(seed + probe
//      index) (as rod/perturbation.hpp draws: 53-bit uniforms) — g is periodic with zero mean, so
//      the link is unchanged; A is the amplitude (rad)
//   3. integrate the probe time (the same Simulation::step); E₁ = E_total at its end
//   4. unstable if E₁ < E₀ − tolerance (the state has somewhere lower to go); then the run goes
//      on from the probe's end (its time included). Stable otherwise: the saved state is put
//      back and the run stops as an equilibrium.
//
// A stable state's kick relaxes back from above E₀ (E₁ ≥ E₀ up to dissipation of what was left
// of the approach); an unstable one falls below it. The test is serial-only (a distributed fluid
// would have to be gathered to be saved); deterministic, so a resumed run probes alike.
#include <cstdint>
#include <string>

namespace ibrod::sim {

class Simulation;

struct StabilityProbe {
  bool enabled = true;
  double amplitude = 0.05;  ///< A, rad
  int modes = 4;            ///< M
  double time = 0.5e-6;     ///< probe time, s
  double tolerance = 0;     ///< energy drop that counts, g Å² s⁻²
  std::uint64_t seed = 1;
};

struct ProbeOutcome {
  bool stable = true;
  std::int64_t step = 0;   ///< the step the probe started at
  double time_us = 0;      ///< its time
  std::int64_t steps = 0;  ///< steps integrated
  double duration_us = 0;  ///< time integrated (≥ the probe time; adaptive Δt: not steps × Δt)
  double E_before_kT = 0, E_after_kT = 0;
  double writhe_before = 0, writhe_after = 0;
};

/// Runs the probe on `sim` (see the file comment); `index` counts the probes of the run (seed +
/// index draws the perturbation). Leaves sim at the saved state if stable, at the probe's end if
/// not.
ProbeOutcome probe_stability(Simulation& sim, const StabilityProbe& p, std::uint64_t index);

/// One line for logs: "stable: E 1.23 → 1.25 kT over 0.5 µs" or "unstable: …".
std::string describe(const ProbeOutcome& o);

}  // namespace ibrod::sim
