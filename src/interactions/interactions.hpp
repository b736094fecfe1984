#pragma once
// Non-elastic forces between rod points: Debye–Hückel electrostatics (MODEL (2.19–2.22)) and the
// hard-core steric repulsion (MODEL (2.17–2.18)). Each module accumulates (+=) point forces
// −∂E/∂X_k (g Å s⁻²) into F and returns its energy (g Å² s⁻²), so F = −∂E/∂X can be tested.
// Sign (MODEL §3): these forces act on the massless rod and are passed to the fluid unchanged;
// like charges and overlapping segments push apart.
#include <span>
#include <vector>

#include "core/types.hpp"

namespace ibrod::interactions {

/// Screened Coulomb pair law: E(d) = A e^{−κd}/d, A = q²/(4π ε0 εw) (g Å³ s⁻²).
struct DebyeHuckel {
  double A = 0;      ///< q²/(4π ε0 εw), g Å³ s⁻²
  double kappa = 0;  ///< κ, Å⁻¹
  double energy(double d) const;
  /// −(dE/dd)/d: the force on i is force_over_d(d) (X_i − X_j)
  double force_over_d(double d) const;
};

struct ElectroParams {
  bool enabled = true;
  DebyeHuckel law;
  double cutoff = 0;  ///< pairs farther apart than this (Å) are dropped; <= 0: no cutoff
};

/// Electrostatics over all pairs i < j of rod points. Uses a cell list (O(n)) when the cutoff is
/// smaller than the rod's extent, the direct O(n²) sum otherwise. Sized once per rod size.
class Electrostatics {
 public:
  Electrostatics(const ElectroParams& p, int n);
  const ElectroParams& params() const { return p_; }
  /// F_i += −∂E/∂X_i; returns E.
  double accumulate(std::span<const Vec3> X, std::span<Vec3> F);
  /// The direct O(n²) pair sum with the same cutoff: the test oracle. F_i += −∂E/∂X_i; returns E.
  double accumulate_direct(std::span<const Vec3> X, std::span<Vec3> F) const;
  /// energy alone (direct sum, same cutoff)
  double energy(std::span<const Vec3> X) const;

 private:
  ElectroParams p_;
  // cell-list scratch (sized once, reused)
  std::vector<int> head_, next_;
};

struct StericParams {
  bool enabled = true;
  double diameter = 20.0;    ///< D, Å
  double stiffness = 0.0;    ///< g, g s⁻² (force per Å of overlap)
  double ds = 3.4;           ///< Δs of the rod, Å (pairs closer than 2D along the rod are skipped)
};

/// Hard-core repulsion between non-neighbouring segments [X_k, X_{k+1}] of the closed rod:
/// for each pair of segments more than 2D apart along the rod whose closest points are at
/// distance d < D, energy ½ g (D − d)² and the matching forces (−∂E/∂X) distributed to the
/// segments' end points. Accumulates into F; returns the energy.
class Steric {
 public:
  Steric(const StericParams& p, int n);
  const StericParams& params() const { return p_; }
  double accumulate(std::span<const Vec3> X, std::span<Vec3> F);
  double energy(std::span<const Vec3> X) const;

 private:
  StericParams p_;
  std::vector<int> head_, next_;
};

}  // namespace ibrod::interactions
