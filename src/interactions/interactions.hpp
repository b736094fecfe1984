#pragma once
// Non-elastic forces between rod points: Debye–Hückel electrostatics (MODEL (2.19–2.22)) and the
// hard-core steric repulsion (MODEL (2.17–2.18)). Each module accumulates (+=) point forces
// −∂E/∂X_k (g Å s⁻²) into F and returns its energy (g Å² s⁻²), so F = −∂E/∂X can be tested.
// Sign (MODEL §3): these forces act on the massless rod and are passed to the fluid unchanged;
// like charges and overlapping segments push apart.
// Both sums run over the rod's own points in free space (positions unwrapped, no periodic images).
// accumulate() runs OpenMP threads over private force buffers held in the object (no races, no
// allocation after the first call at a given size), reduced in a fixed order, so results are
// reproducible for a fixed thread count.
#include <array>
#include <cmath>
#include <span>
#include <vector>

#include "core/types.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::interactions {

/// Default electrostatic cutoff in Debye lengths: rc = kDefaultCutoffDebye / κ (154 Å at 0.1 M,
/// 486 Å at 0.01 M, 1538 Å at 0.001 M, where it exceeds a 600 bp rod and the direct sum runs).
/// Chosen so that truncation changes the point forces by < 1e-6 relative (max_i |ΔF_i| over
/// max_i |F_i|, against no cutoff), measured in test_electrostatics.cpp (TruncationError...):
///   reference ring (n = 600, r0 = 324.676 Å)   6.3e-8 at 0.1 M, 6.4e-8 at 0.01 M
///   compact 3-D self-avoiding walk (600 × 3.4 Å)  7.9e-9 at 0.1 M, 0 at 0.01 M (rc > extent)
///   collapsed supercoil (plectoneme, 716 Å long)  3.2e-9 at 0.1 M, 7.8e-10 at 0.01 M
/// The ring is the hard case (its point forces nearly cancel, leaving a small net radial force).
/// The error falls like e^{−κ rc}: on the ring 2.9e-6 at 12, 5.0e-7 at 14, 1.8e-7 at 15 Debye
/// lengths; 16 leaves a 15× margin at ~7 % more pairs than 15.
inline constexpr double kDefaultCutoffDebye = 16.0;

/// Default steric stiffness g, g s⁻² (force per Å of overlap) = 0.1 kT/Å² (kT = 414.2 g Å² s⁻²
/// at 300 K).
/// Upper bound (explicit time step), measured in the coupled scheme: a 100-bp ring with ΔLk = 3
/// and 4 collapsing onto itself (16³ grid, h = 12.5 Å, electrostatics off) keeps its total energy
/// non-increasing at Δt = 0.1 ns for g ≤ 0.1 kT/Å², while g = 0.15 and 0.2 kT/Å² chatter at the
/// contacts (the energy rises by up to 0.3 kT when a contact switches on) and g = 0.48 kT/Å²
/// needs Δt ≤ 0.05 ns. The bound scales as g Δt: halve g when doubling Δt.
/// Lower bound (no penetration): the forces pressing segments together in a supercoil are tens of
/// g Å s⁻² at most (the screened repulsion of a straight strand d = 20 Å away is
/// 2(A/Δs) κ K₁(κd) ≈ 5 per point at 0.1 M), and at g = 41 the same collapsing rings keep a
/// closest approach of 19.3–19.5 Å ≥ 0.95 D; passing through takes g D ≈ 800 g Å s⁻² per contact.
/// Test (test_steric.cpp, DefaultStiffness...): overdamped segments pushed together with 10–15
/// g Å s⁻² per end point stay above 0.95 D.
inline constexpr double kDefaultStericStiffness = 0.1 * 414.19;

namespace detail {
/// Scratch of the cell list (src/interactions/cell_list.hpp): the points sorted by cell.
struct CellScratch {
  std::vector<int> start;  ///< [cells + 1] first sorted position of each cell
  std::vector<int> order;  ///< [n] point index at each sorted position
  std::vector<int> cell;   ///< [n] cell of each sorted position
  std::vector<Vec3> x;     ///< [n] positions in sorted order, Å
};
}  // namespace detail

/// Screened Coulomb pair law, MODEL (2.19–2.22): E(d) = A e^{−κd}/d, A = q²/(4π ε0 εw)
/// (g Å³ s⁻²), −(dE/dd)/d = A e^{−κd}/d (1/d + κ)/d. The pair law of every Debye–Hückel sum
/// (Electrostatics: the cell-list loop, the direct oracle, the energy); a small evaluator in the
/// manner of HOOMD's EvaluatorPair, the loops over pairs written elsewhere.
struct DebyeHuckel {
  double A = 0;      ///< q²/(4π ε0 εw), g Å³ s⁻²
  double kappa = 0;  ///< κ, Å⁻¹

  /// One pair at distance d (Å): its energy A e^{−κd}/d and −(dE/dd)/d, so that the force on i
  /// is force_over_d (X_i − X_j). One exponential for both.
  struct Terms {
    double energy;        ///< g Å² s⁻²
    double force_over_d;  ///< g s⁻²
  };
  Terms at(double d) const {
    const double inv = 1.0 / d;
    const double e = A * std::exp(-kappa * d) * inv;  // A e^{−κd}/d
    return {e, e * (inv + kappa) * inv};
  }
  /// the same from the squared distance d² (Å²), as the pair loops have it
  Terms eval(double d2) const { return at(std::sqrt(d2)); }

  /// E(d) = A e^{−κd}/d alone, as the reported energies and the cutoff shift have always been
  /// computed: divided by d where at() multiplies by 1/d (equal to round-off; kept so that the
  /// outputs stay bit for bit what they were).
  double energy(double d) const { return A * std::exp(-kappa * d) / d; }
  /// −(dE/dd)/d: the force on i is force_over_d(d) (X_i − X_j); at(d).force_over_d
  double force_over_d(double d) const { return at(d).force_over_d; }
};

/// The pair law of MODEL (2.19–2.22) from natural parameters: charge per point q (e), dielectric
/// constant εw, salt Cs (mol/L): A = q²/(4π ε0 εw), κ = 0.329 √Cs Å⁻¹ (units::debye_kappa).
DebyeHuckel debye_huckel(double charge_e, double dielectric, double salt_M);

struct ElectroParams {
  bool enabled = true;
  DebyeHuckel law;
  double cutoff = 0;  ///< pairs farther apart than this (Å) are dropped; <= 0: no cutoff
};

/// ElectroParams from the config's natural parameters (config/params.cpp): the law of
/// debye_huckel(charge_e, dielectric, salt_M) and the cutoff rc = cutoff_debye / κ Å, in Debye
/// lengths (kDefaultCutoffDebye by default); no cutoff (0) when κ = 0 (no salt).
ElectroParams electro_params(bool enabled, double charge_e, double dielectric, double salt_M,
                             double cutoff_debye);

/// Electrostatics over all pairs i < j of rod points (adjacent points included, as in the paper).
/// Uses a cell list (cells of edge ≥ rc over the points' bounding box, O(n)) when it has at least
/// 3 cells along some axis (rc ≤ about a third of the rod's extent); otherwise every cell would
/// neighbour every other, and the direct O(n²) sum runs (also for cutoff <= 0).
/// With a cutoff rc > 0 each pair energy is shifted, E(d) − E(rc) for d ≤ rc, so that the energy
/// is continuous and F = −∇E holds everywhere; the forces are the unshifted law. Why: the total
/// energy (potential + kinetic) then cannot jump when pairs cross rc, and the diagnostics' check
/// that it never increases stays exact. The shift is E(rc) = A e^{−κ rc}/rc ≈ 1.2e-9 kT per pair
/// at 0.1 M and the default cutoff; shift plus dropped tail change the ring's energy by 3.5e-5 kT
/// (of 353 kT) and every test configuration's by ≤ 2.1e-4 kT, far below any reported digit.
/// Coincident points (d = 0) are not allowed.
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
  /// whether the latest accumulate() used the cell list (false: the direct sum)
  bool used_cell_list() const { return used_cells_; }

 private:
  ElectroParams p_;
  double e_shift_ = 0;  ///< E(rc) subtracted from each pair energy (0 without cutoff)
  bool used_cells_ = false;
  // scratch, sized on the first call and reused
  detail::CellScratch cells_;
  std::vector<Vec3> thread_F_;    ///< [threads × n] private force buffers
  std::vector<double> thread_E_;  ///< [threads] private energies
};

/// Closest points of the segments P(s) = P0 + s(P1 − P0), Q(t) = Q0 + t(Q1 − Q0), s, t ∈ [0,1].
struct SegmentContact {
  double s = 0, t = 0;  ///< parameters of the closest points
  Vec3 sep;             ///< P(s) − Q(t), Å
  double d = 0;         ///< |sep|, Å
};

/// The exact minimiser of |P(s) − Q(t)| over [0,1]² (a convex quadratic: line solution, clamped,
/// then re-projected; Ericson, Real-Time Collision Detection §5.1.9). The line solution is formed
/// from cross products, (((P1−P0)×(Q1−Q0))×(Q1−Q0))·(P0−Q0)/|(P1−P0)×(Q1−Q0)|², whose relative
/// error grows like ε/θ for a small angle θ instead of ε/θ² for the usual ae − b² form. Parallel
/// segments (sin θ < 1e-10) have a whole set of minimisers: the middle of their overlap is taken,
/// which splits the contact force evenly between the end points.
SegmentContact closest_points(const Vec3& P0, const Vec3& P1, const Vec3& Q0, const Vec3& Q1);

/// One segment pair of MODEL (2.17–2.18): if the closest distance d < D, energy ½ g (D − d)² and
/// the forces −∂E/∂X on P0, P1, Q0, Q1 written (not accumulated) to f: g (D − d) u times
/// (1 − s), s, −(1 − t), −t, u = sep/d. These are the exact gradient (envelope theorem: the
/// closest-point conditions are stationary, or the parameter sits on a fixed bound) except where
/// the minimiser is not unique (exactly parallel overlapping segments). At d = 0 u is taken
/// normal to both segments. Returns the energy; f is zero when d ≥ D.
double steric_pair(double D, double g, const Vec3& P0, const Vec3& P1, const Vec3& Q0,
                   const Vec3& Q1, std::array<Vec3, 4>& f);

struct StericParams {
  bool enabled = true;
  double diameter = 20.0;  ///< D, Å
  double stiffness = 0.0;  ///< g, g s⁻² (force per Å of overlap)
  double ds = 3.4;         ///< Δs of the rod, Å (pairs closer than 2D along the rod are skipped)
  bool closed = true;  ///< closed rod (n segments, cyclic distance) or open (n − 1, |k − l|)
  /// The rods' layouts in the point list (rod::RodRange), in order, covering it; the segments
  /// are each rod's own (its ds and closed), and two segments of different rods always count as
  /// a pair. Empty: one rod of all points with `ds` and `closed` above.
  std::vector<rod::RodRange> rods;
};

/// The rods whose segments the hard core sees in a list of n points: p.rods, or where it is empty
/// one rod of all n points with p.ds and p.closed. Steric and the implicit scheme's contact
/// stiffness (integrate::detail::add_steric_stiffness) both walk these.
std::vector<rod::RodRange> steric_rods(const StericParams& p, int n);

/// Hard-core repulsion between non-neighbouring segments [X_k, X_{k+1}] of the rod (closed: k =
/// 0 … n−1, X_n = X_0; open, StericParams::closed = false: k = 0 … n−2), and with several rods
/// (StericParams::rods) between every two segments of different rods as well:
/// for each pair of segments more than 2D apart along the rod whose closest points are at
/// distance d < D, energy ½ g (D − d)² and the matching forces (−∂E/∂X) distributed to the
/// segments' end points. Accumulates into F; returns the energy.
/// Along-rod separation of segments k, l: min(|k − l|, n − |k − l|) Δs (open: |k − l| Δs); the pair
/// counts when it exceeds 2D. Candidates come from a cell list over segment midpoints with cell
/// edge ≥ D + the longest segment (two segments closer than D have midpoints closer than that);
/// with at most 2 cells per axis, a direct loop with the same midpoint test.
class Steric {
 public:
  Steric(const StericParams& p, int n);
  const StericParams& params() const { return p_; }
  double accumulate(std::span<const Vec3> X, std::span<Vec3> F);
  /// The direct O(n²) sum over segment pairs: the test oracle. Accumulates into F; returns E.
  double accumulate_direct(std::span<const Vec3> X, std::span<Vec3> F) const;
  /// energy alone (direct sum)
  double energy(std::span<const Vec3> X) const;
  /// whether the latest accumulate() used the cell list (false: the direct sum)
  bool used_cell_list() const { return used_cells_; }

 private:
  StericParams p_;
  bool used_cells_ = false;
  /// the segments: end points a → b, rod (chain) and position along it; built for a point list
  /// of seg_built_for_ points (in the constructor, again only if a call brings another size)
  mutable std::vector<int> seg_a_, seg_b_, seg_chain_, seg_pos_;
  mutable std::vector<rod::RodRange> chains_;
  mutable int seg_built_for_ = -1;
  void build_segments(int n) const;
  bool far_along_rod(int k, int l) const;  ///< whether segments k, l form a pair
  double segment_pair(std::span<const Vec3> X, int k, int l, Vec3* F) const;
  // scratch, sized on the first call and reused
  detail::CellScratch cells_;     ///< over the segment midpoints
  std::vector<Vec3> mid_;         ///< [n] segment midpoints, Å
  std::vector<Vec3> thread_F_;    ///< [threads × n] private force buffers
  std::vector<double> thread_E_;  ///< [threads] private energies
};

}  // namespace ibrod::interactions
