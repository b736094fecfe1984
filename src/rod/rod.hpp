#pragma once
// The special Cosserat rod of MODEL §3 (2.5–2.8, 2.13) discretised as in MODEL §4: a closed rod of
// n points X_k with orthonormal triads D_k = [D¹ D² D³] (columns), spacing Δs along the rod.
// Closed (the default: half points k+½ for k = 0 … n−1, indices cyclic) or open (RodParams::closed
// = false: half points k+½ for k = 0 … n−2 only; the ends X_0, X_{n−1} have one neighbour, no
// half point beyond them, so F_{−½} = F_{n−½} = 0 and N likewise: free, force- and torque-free
// ends; docs/model.md "Open rods").
// Internal force F and moment N live at half points k+½ with the half-point triad
// D_{k+½} = √A D_k, A = D_{k+1} D_kᵀ (principal square root: half the angle about the same axis).
#include <span>
#include <vector>

#include "core/types.hpp"

namespace ibrod::rod {

struct RodParams {
  int n = 600;                   ///< number of rod points (= base pairs)
  double ds = 3.4;               ///< Δs, Å (rise per base pair)
  Vec3 a{1.3e5, 1.3e5, 1.82e5};  ///< a1, a2 (bending), a3 (twist), g Å³ s⁻²
  Vec3 b{5e3, 5e3, 5e3};         ///< b1, b2 (shear), b3 (stretch), g Å s⁻²
  Vec3 omega0{0.0, 0.0, 0.0};  ///< intrinsic curvatures Ω¹₀, Ω²₀ and twist Ω³₀, Å⁻¹
  /// Per link: omega0_k[k] replaces omega0 at half point k+½ (link k → k+1) when not empty; size
  /// n (an open rod uses the first n − 1). rod.intrinsic_file (docs/config.md).
  std::vector<Vec3> omega0_k;
  /// Per link: a_k[k], b_k[k] replace a, b at half point k+½ (link k → k+1) when not empty; size
  /// n each (an open rod uses the first n − 1); given together or not at all. rod.moduli_file
  /// (docs/config.md), which also sets a, b to the per-link means (the twisted circle's tilt).
  std::vector<Vec3> a_k;
  std::vector<Vec3> b_k;
  bool closed = true;  ///< closed ring (X_n = X_0) or open rod with two free ends
};

/// Number of half points (links k → k+1) of a rod of n points: n closed, n − 1 open.
inline int half_points(int n, bool closed) { return closed ? n : (n > 0 ? n - 1 : 0); }
/// The point before k along a rod of n points (closed: n − 1 before 0; open: the first point is
/// its own, so that a central difference becomes one-sided at a free end).
inline int point_before(int k, int n, bool closed) { return k > 0 ? k - 1 : closed ? n - 1 : 0; }
/// The point after k (closed: 0 after n − 1; open: the last point is its own).
inline int point_after(int k, int n, bool closed) { return k + 1 < n ? k + 1 : closed ? 0 : n - 1; }

struct RodState {
  std::vector<Vec3> X;  ///< [n] axis positions, Å (unwrapped: never folded into the box)
  std::vector<Mat3> D;  ///< [n] triads, columns D¹, D², D³ (orthonormal, right-handed)
  int size() const { return int(X.size()); }
};

/// Elastic energy split as the diagnostics report it, g Å² s⁻² (sums over the half points k+½;
/// aᵢ, bᵢ and Ωᵢ₀ are those of link k when a_k, b_k, omega0_k are given).
struct ElasticEnergy {
  double bend = 0;     ///< (Δs/2) Σ a1 (Ω¹−Ω¹₀)² + a2 (Ω²−Ω²₀)²
  double twist = 0;    ///< (Δs/2) Σ a3 (Ω³−Ω³₀)²
  double stretch = 0;  ///< (Δs/2) Σ b1 Γ₁² + b2 Γ₂² + b3 Γ₃²  (shear and stretch)
  double total() const { return bend + twist + stretch; }
};

/// Scratch for elastic_forces (half-point quantities), sized once; reused every step.
struct RodWork {
  std::vector<Mat3> Dh;  ///< [n] half-point triads D_{k+½}
  std::vector<Vec3> Fh;  ///< [n] internal force F_{k+½}, lab frame, g Å s⁻²
  std::vector<Vec3> Nh;  ///< [n] internal moment N_{k+½}, lab frame, g Å² s⁻²
  std::vector<Vec3> Xp;  ///< [n] X′_{k+½} = (X_{k+1} − X_k)/Δs
  std::vector<Vec3> Eh;  ///< [n] (bend, twist, stretch) energy of half point k+½, g Å² s⁻²
  void resize(int n) {
    Dh.resize(n);
    Fh.resize(n);
    Nh.resize(n);
    Xp.resize(n);
    Eh.resize(n);
  }
};

/// Half-point triad √(D_{k+1} D_kᵀ) D_k (principal square root). Exposed for tests.
Mat3 half_point_triad(const Mat3& Dk, const Mat3& Dk1);

/// Elastic point forces and torques that the rod applies to the fluid (MODEL §4 step 4):
///   F_k += Δs f_k = F_{k+½} − F_{k−½}              (g Å s⁻²)
///   T_k += Δs n_k = N_{k+½} − N_{k−½} + (Δs/2)[X′_{k+½}×F_{k+½} + X′_{k−½}×F_{k−½}]  (g Å² s⁻²)
/// Accumulates (+=) into F and T ([n] each). Returns the elastic energy E_h (summed in index order,
/// so it does not depend on the thread count and equals elastic_energy() exactly).
/// Resizes w if its size is not n (allocation only then). Throws std::invalid_argument if the
/// sizes of s.D, F or T differ from n.
/// F is exactly −∂E_h/∂X_k; T matches the negative rotation gradient of E_h to O(Δs²) relative.
ElasticEnergy elastic_forces(const RodParams& p, const RodState& s, RodWork& w, std::span<Vec3> F,
                             std::span<Vec3> T);

/// The discrete elastic energy E_h alone (MODEL §4), g Å² s⁻².
ElasticEnergy elastic_energy(const RodParams& p, const RodState& s);

/// Explicit rod update of MODEL §4: X_k += dt U_k; D_k ← R(dt W_k) D_k (Rodrigues).
void advance(RodState& s, std::span<const Vec3> U, std::span<const Vec3> W, double dt);

/// Initial condition of MODEL §5: the twisted circle of radius r0 = n Δs / 2π in the z = 0 plane,
/// centred at `center`, excess link ΔLk, twist perturbation g(s) = Σ_m eps[m−1] sin(m s / r0).
/// sin β = −a3 ΔLk / (b1 r0² + a3 − a1). Uses p.n, p.ds and the scalars a1, a3, b1 (never a_k,
/// b_k: with per-link moduli to_params sets the scalars to their means); an equilibrium (to
/// O(Δs²)) only for ε = 0, a1 = a2, b1 = b2 = b3, uniform moduli and zero intrinsic strains. Throws
/// ConfigError for n < 3, ds ≤ 0 or |sin β| > 1.
struct CircleParams {
  int excess_link = 6;
  std::vector<double> perturbation{1.0};  ///< ε_m for m = 1, 2, … (radians)
  Vec3 center{0.0, 0.0, 0.0};             ///< Å
};
RodState twisted_circle(const RodParams& p, const CircleParams& c);

/// Initial condition of an open rod (rod.closed = false): a straight rod along x, centred at
/// `center`, points Δs apart, triads D¹ = ŷ, D² = ẑ, D³ = x̂ turned about x by the same twist
/// perturbation as the circle's, ψ_k = Σ_m eps[m−1] sin(2π m k / n) (none when eps is empty).
/// A stress-free state when p.omega0 = 0 and eps is empty. Throws ConfigError for n < 2 or
/// ds ≤ 0.
RodState straight_rod(const RodParams& p, const std::vector<double>& eps, const Vec3& center);

/// A rod's built-in initial shape: the twisted circle of `c` (p.closed) or the straight rod
/// (open: c's perturbation and centre).
RodState initial_shape(const RodParams& p, const CircleParams& c);

/// Radius of the circle of n points Δs apart (Å): r0 = n Δs / 2π (MODEL §5).
double circle_radius(int n, double ds);

/// sin β of the twisted circle (MODEL §5), the tilt of D³ out of the circle's plane that balances
/// twist against shear: −a3 ΔLk / (b1 r0² + a3 − a1); a1 bend and a3 twist modulus (g Å³ s⁻²),
/// b1 shear modulus (g Å s⁻²), r0 the radius (Å). The circle exists only for |sin β| ≤ 1.
double circle_tilt_sin_beta(double a1, double a3, double b1, double r0, double excess_link);

}  // namespace ibrod::rod
