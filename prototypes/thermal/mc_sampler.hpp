#pragma once
// Issue 16, the equilibrium check (docs/thermal.md, "Writhe and shape against Monte Carlo"): a
// Metropolis sampler of exp(−E/kT) over the closed rod's points X_k and triads D_k, with E
// exactly the energy the IB run integrates — rod::elastic_energy + Electrostatics::energy +
// Steric::energy with the run's own parameters (config::to_params) — so that the distribution
// of writhe and shape from a long thermal IB run can be compared with an independent sample.
//
// Moves (each a symmetric proposal that preserves Lebesgue measure on X and Haar measure on D,
// so plain Metropolis acceptance min(1, e^{−ΔE/kT}) gives detailed balance):
//   crankshaft  an arc of m = 1 … n/2 points between two fixed points X_i, X_j rotated rigidly,
//               points and triads, by θ ∈ U(−δ_c, δ_c) about the chord X_i → X_j (the elastic
//               energy changes at the two hinges only; electrostatics and steric everywhere);
//   twist       one triad turned by φ ∈ U(−δ_t, δ_t) about its own D³ (D³ unchanged);
//   tilt        one triad turned by φ ∈ U(−δ_r, δ_r) about a uniformly random axis (shear of D³
//               against the tangent, and the bend/twist strains it carries);
//   shift       one point displaced by U(−δ_x, δ_x)³ (stretch and shear);
//   spin        the triads of an arc of m = 1 … n/2 points each turned by the same φ ∈ U(−δ_s, δ_s)
//               about its own D³ (moves twist between the arc's ends in one step: single twist
//               moves alone relax the ring's twist profile diffusively, slowly);
//   dilate      all points scaled about their centroid by e^u, u ∈ U(−δ_u, δ_u), triads kept
//               (the ring's size: single shifts relax it slowly); Metropolis–Hastings with the
//               Jacobian e^{(3n−3)u} of the map, min(1, e^{−ΔE/kT + (3n−3)u}).
// A sweep is n attempts of each of the first four kinds and n/10 of the last two.
// The step sizes adapt during burn-in only (towards 40 % acceptance) and are frozen afterwards.
// Linking number: a move that changes Lk is rejected. Lk = Tw + Wr (O(n²)) is recomputed for a
// position move only when it could have passed the rod through itself: when a non-local segment
// pair is closer than the hard core D after the move (steric energy > 0), or when some point
// moved along a path of length ≥ D. Otherwise no crossing of segments more than 2D apart along
// the rod is possible (their distance is 1-Lipschitz in the motion and ends ≥ D); crossings of
// segments closer than 2D along the rod would need a hairpin of radius < D and are not checked.
#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "interactions/interactions.hpp"
#include "rod/rod.hpp"

namespace ibrod::mc {

/// The energy of the IB run, in kT (all of it a function of the rod's state only).
struct RingEnergy {
  rod::RodParams rod;
  interactions::Electrostatics electro;
  interactions::Steric steric;
  double kT;  ///< g Å² s⁻²
  RingEnergy(const rod::RodParams& r, const interactions::ElectroParams& e,
             const interactions::StericParams& s, double kT_)
      : rod(r), electro(e, r.n), steric(s, r.n), kT(kT_) {}
  double elastic(const rod::RodState& s) const { return rod::elastic_energy(rod, s).total() / kT; }
  /// Electrostatics and steric by their direct sums (energy(): the same energies as the run's
  /// cell-list sums to round-off).
  double pairs(const std::vector<Vec3>& X) const {
    return (electro.energy(X) + steric.energy(X)) / kT;
  }
  double steric_only(const std::vector<Vec3>& X) const { return steric.energy(X) / kT; }
  /// pairs(Xnew) − pairs(Xold) (kT) when only the points in `moved` (ascending, distinct) differ:
  /// the core's pair laws (DebyeHuckel::energy with the cutoff shift, steric_pair with the
  /// along-rod rule of Steric) summed over the pairs that involve a moved point or a segment with
  /// a moved end. Pairs of two moved points are skipped when `rigid` (a rigid motion of the moved
  /// set keeps their distances). RingMC checks the running sum against pairs() every sweep.
  /// Returns {Δ electrostatic, Δ steric}.
  std::array<double, 2> pairs_delta(const std::vector<Vec3>& Xold, const std::vector<Vec3>& Xnew,
                                    const std::vector<int>& moved, bool rigid) const;
  /// Σ_k X_k · ∂E/∂X_k (kT) with the code's exact point forces (−∂E/∂X): the virial. Its mean is
  /// (3n − 3) kT for any E that is translation invariant (generalized equipartition over the 3n − 3
  /// relative coordinates), whatever the temperature and the anharmonicity.
  double virial(const rod::RodState& s);
  /// Configurational temperature of the triads: Σ_{k,a} (L_{k,a} E)² and Σ_{k,a} L²_{k,a} E, with
  /// L_{k,a} the derivative along D_k ← exp(ε ê_a) D_k (central differences, ε = 1e-4 rad).
  /// Haar measure is invariant under these flows, so ⟨Σ (LE)²⟩ = ⟨Σ L²E⟩ in kT units exactly.
  std::array<double, 2> rotation_temperature_terms(rod::RodState& s) const;
  /// Configurational temperature of the positions: Σ |∂E/∂X|² and Σ ∂²E/∂X² (kT units), the first
  /// from the code's exact point forces, the second by central differences of those forces
  /// (ε = 1e-4 Å). ⟨Σ |∂E/∂X|²⟩ = ⟨Σ ∂²E/∂X²⟩ exactly (a far smaller variance than the virial's).
  std::array<double, 2> position_temperature_terms(rod::RodState& s);

 private:
  void forces(const rod::RodState& s, std::vector<Vec3>& F);
  rod::RodWork work_;
  std::vector<Vec3> Fp_, Fm_;
  std::vector<Vec3> F_, T_;
};

struct McSteps {
  double crank = 0.2;    ///< δ_c, rad
  double twist = 0.3;    ///< δ_t, rad
  double tilt = 0.05;    ///< δ_r, rad
  double shift = 0.3;    ///< δ_x, Å
  double spin = 0.1;     ///< δ_s, rad
  double dilate = 0.01;  ///< δ_u
};

struct McCounts {
  std::array<std::int64_t, 6> tried{}, accepted{};  ///< crank, twist, tilt, shift, spin, dilate
  std::int64_t lk_checks = 0;                       ///< exact Lk evaluations
  std::int64_t lk_rejects = 0;                      ///< moves rejected for changing Lk
};

/// One sample of the statistics the comparison uses (lengths in Å, energies in kT).
struct RingSample {
  double writhe = 0, twist = 0, link = 0;
  double rg2 = 0;  ///< radius of gyration², Å²
  std::array<double, 5>
      power{};  ///< P_m = |X̂_m|², m = 0 … 4 (X̂_m = (1/n) Σ X_k e^{−2πimk/n}; P_0 unused)
  double E_bend = 0, E_twist = 0, E_stretch = 0, E_pairs = 0;
};

/// The statistics of a state (O(n²): the writhe).
RingSample measure(const RingEnergy& E, const rod::RodState& s);

class RingMC {
 public:
  RingMC(RingEnergy& energy, rod::RodState start, std::uint64_t seed, McSteps steps = {});
  /// One sweep: n moves of each kind, in random order of kind. adapt: retune the step sizes
  /// from this sweep's acceptance (burn-in only).
  void sweep(bool adapt = false);
  const rod::RodState& state() const { return s_; }
  const McCounts& counts() const { return counts_; }
  const McSteps& steps() const { return steps_; }
  double link0() const { return lk0_; }
  void reset_counts() { counts_ = {}; }
  bool debug_ = false;  ///< check the running energies against full sums after every move
  /// largest discrepancy seen between the incrementally updated pair energy and the full sum
  double max_pair_drift() const { return max_pair_drift_; }
  /// largest max |DᵀD − I| of a triad at a sweep's end (before it is re-orthonormalised)
  double max_triad_drift() const { return max_triad_drift_; }

 private:
  bool accept(double dE);
  bool crank();
  bool twist_move();
  bool tilt_move();
  bool shift_move();
  bool spin_move();
  bool dilate_move();
  /// whether the position move just made may have changed Lk, and if it has (restores nothing)
  bool link_changed(double max_path, double e_steric);

  RingEnergy& E_;
  rod::RodState s_, trial_;
  std::mt19937_64 rng_;
  McSteps steps_;
  McCounts counts_;
  std::vector<int> moved_;
  std::vector<char> is_moved_;
  double max_pair_drift_ = 0;
  double max_triad_drift_ = 0;  ///< largest |running pair energy − pairs()| at a sweep's end, kT
  double e_el_ = 0, e_pair_ = 0;  ///< current elastic and pair energies, kT
  double e_steric_ = 0;           ///< its steric part, kT (contacts closer than D: > 0)
  double lk0_ = 0;
};

}  // namespace ibrod::mc
