#pragma once
// Implicit rod–fluid coupling with a large time step (issue 14, docs/large_dt.md).
//
// In the Stokes limit (ρh²/(μΔt) ≈ 0.01 at Δt = 0.1 ns and smaller for larger steps) the fluid is
// a linear map from the rod's point forces and torques g = (F_k, T_k) to its velocities and
// angular velocities (U_k, W_k):
//   M g = interpolate ∘ (−μL_h)⁻¹ P ∘ spread g        (one Stokes solve, FluidSolver::solve_stokes)
// and the rod is overdamped: q̇ = M F(q), q = (X_k, θ_k) (positions, lab-frame rotation vectors
// of the triads). Forward Euler in this form is the explicit scheme; its Δt is bounded by the
// stretch/shear/bend/twist stiffness at the kernel scale. With K the elastic stiffness (the
// Gauss–Newton K = Δs Σ Jᵀ C J by default, plus the steric contacts; the pair forces stay
// explicit) and a local mobility M_loc = diag(β m_t I, β m_r I) (m_t, m_r the self mobilities
// of one kernel-spread point), the step is (velocity form, the default and the scheme chosen in
// docs/large_dt.md)
//   u = (I + Δt M_loc K)⁻¹ M F(qⁿ),   δ = Δt u                                         (1)
// one Stokes solve and one sparse (block-cyclic) Cholesky solve of M_loc⁻¹ + Δt K per step; its
// fixed points are the explicit scheme's (M F = 0). Optionally GMRES, right-preconditioned by
// the same system, solves the linearly implicit Euler step (I + Δt M K) u = M F from (1)
// (krylov_max_iter > 0; one Stokes solve per iteration). The force form
//   g = (I + Δt K M_loc)⁻¹ F(qⁿ),  δ = Δt M g                                          (2)
// (velocity_form = false; with GMRES (I + Δt K M) g = F) was measured and not chosen: its fixed
// points move with Δt and it does not decrease the energy. All are first order for any M_loc and
// any approximation of K (they differ from forward Euler by O(Δt²)); stability needs
// M_loc K ≈ M K on the stiff modes (docs/large_dt.md: β ≥ 8).
// Finally X ← X + δ_X, D ← R(δ_θ) D (Rodrigues): the link is conserved as long as the rod does
// not pass through itself, and the triads stay orthonormal.
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <optional>
#include <cstdint>
#include <memory>
#include <vector>

#include "integrate/adaptive_dt.hpp"
#include "integrate/block_cyclic.hpp"
#include "integrate/system.hpp"

namespace ibrod::integrate {

struct ImplicitParams {
  double mobility_scale = 8.0;  ///< β: M_loc = β × the kernel's self mobility (≥ 0; 0: explicit)
  /// GMRES iterations after the local solve's guess, each one Stokes solve (0: none). Order 1:
  /// toward the linearly implicit Euler step (I + Δt M K) u = M F. Order 2: on each ROS2 stage,
  /// whose W is then I + γΔt M K with the Stokes mobility M at qⁿ (docs/large_dt.md §10)
  int krylov_max_iter = 0;
  /// relative residual at which GMRES stops; order 1: a step that does not reach it is
  /// rejected (converged = false); order 2: it stands, judged by its error estimate
  double krylov_tol = 1e-2;
  /// order 2 with GMRES: a stage's GMRES also stops once Δt ‖r‖/√n ≤ this (length, the units
  /// of the positions; ‖·‖ GMRES's mobility-balanced norm of the velocities, over all n points:
  /// the residual's move of the points in RMS). A residual r leaves an error W⁻¹r in the stage
  /// (|W⁻¹| ≤ 1 on the stiff modes); where the ring moves little a relative residual of
  /// krylov_tol asks for far more than the error control can see (docs/large_dt.md §13).
  /// 0: krylov_tol alone
  double krylov_error_budget = 0.0;
  /// trial steps between refreshes of K and of its factorisation (≥ 1; K at qⁿ when refreshed,
  /// and whenever Δt changes). 1: K is a function of the state alone, so a run resumed from any
  /// checkpoint (a signal's too) is bitwise the same. > 1 saves ~1.4 ms per step at the 64³
  /// reference (4: 5.3–5.5 against 7.0–7.1 ms, the same accuracy; docs/large_dt.md), and then
  /// only resumes from the periodic checkpoints are bitwise (Simulation::checkpoint_taken).
  int jacobian_every = 1;
  /// K (and M_loc, and their factorisation) are also refreshed before jacobian_every steps when
  /// a rod point has moved farther than this since the last refresh, Å (0: off). W's error is its
  /// age measured in the geometry it was made for (docs/large_dt.md §6, §8): through a collapse
  /// the points move fast and W is remade every few steps, near rest it is kept for
  /// jacobian_every steps.
  double refresh_displacement = 0;
  bool velocity_form = true;  ///< (I + Δt M_loc K) u = M F (true) or (I + Δt K M_loc) g = F
  /// the length that turns a rotation error (rad) into a displacement of the rod's surface in the
  /// error estimate, Å (the steric radius D/2)
  double rotation_length = 10.0;
  bool gauss_newton = true;  ///< K = Δs Σ Jᵀ C J (positive semi-definite) instead of −∂F/∂q
  bool stiffness_fd = false;  ///< Gauss–Newton K by finite differences (else small-strain
                              ///< analytic strain Jacobian, O(n))
  /// without contacts, solve the local system with BlockCyclicCholesky (else the general sparse
  /// Cholesky; the same solution to round-off)
  bool block_solver = true;
  bool steric_implicit = true;  ///< add the steric contacts' stiffness to K
  /// 1: the linearly implicit IMEX step (1) above; 2: the two-stage Rosenbrock-W step (ROS2,
  /// Verwer et al. 1999) with the same W = I + γΔt M_loc K, γ = 1 + 1/√2:
  ///   W k₁ = M F(qⁿ),  W k₂ = M F(qⁿ + Δt k₁) − 2 k₁,  qⁿ⁺¹ = qⁿ + Δt (3/2 k₁ + 1/2 k₂)
  /// second order for any approximation of the Jacobian (a W-method), two Stokes solves and two
  /// force evaluations per step, with the embedded first-order qⁿ + Δt k₁ for the error
  /// estimate Δt ½ (k₁ + k₂) (docs/large_dt.md "Error control and order"). Velocity form only.
  /// With krylov_max_iter = m > 0 each stage is solved on W = I + γΔt M K instead (M the
  /// Stokes mobility at qⁿ, GMRES right-preconditioned by W_loc: 2m + 4 Stokes solves a step;
  /// converged, ROS2 with the exact M in its Jacobian: L-stable, its stability function
  /// (1 + (1 − 2γ) z)/(1 − γz)²; docs/large_dt.md §10).
  int order = 1;
  /// M_loc: β diag(m_t I, m_r I), the kernel's self mobility on the diagonal (`self`), or
  /// β D O D, the kernel overlap O = 𝒥𝒮 scaled to the same self blocks
  /// (integrate/local_mobility.hpp: it shares the Stokes mobility's near-null space; `overlap`,
  /// solved by sparse LU)
  enum class LocalMobility { self, overlap };
  LocalMobility local_mobility = LocalMobility::self;
  /// overlap: the taper along each rod, in reaches of the kernel along it (4c/Δs points; the
  /// window is the narrowest rod's, clamped to half the shortest rod): pairs farther apart along
  /// a rod than this, and pairs of two rods, are left out of M_loc, so that close strands of a
  /// supercoil do not fill the LU (0: no taper, the default: at 3 reaches the 64³ path runs
  /// ahead, docs/large_dt.md)
  double overlap_window = 0.0;
  /// thermal noise (the System's fluid.thermal_kT > 0; docs/thermal.md "The implicit step with
  /// noise"): the share of the thermal force f_K ~ N(0, kT K) that goes through M_loc, the rest
  /// through the Stokes mobility M in the same Stokes solve (0: candidate D, the default — on
  /// the linearised 100 bp ring never above equipartition; 0.5: G; 1: C, both hot there)
  double thermal_force_local = 0.0;
  /// thermal noise: add the thermal force f_K at all (false: the random stress alone, candidate
  /// A of docs/thermal.md)
  bool thermal_force = true;
  /// thermal noise: the filter's K is the full Hessian −∂(F, T)/∂(X, θ) of the elastic loads
  /// (central finite differences, as gauss_newton = false; the constructor sets gauss_newton
  /// false) instead of the Gauss–Newton K_GN. The thermal stresses give a geometric stiffness
  /// H − K_GN that reaches 10–30× K_GN in directions K_GN holds soft; left out of the filter it
  /// is stepped explicitly and heats the ring from ~1 ns on the 100 bp ring (docs/thermal.md
  /// "The geometric stiffness in the filter"). f_K keeps the covariance kT K_GN.
  bool thermal_hessian = true;
  double fd_dx = 1e-4;      ///< finite-difference step of K in positions, Å
  double fd_dtheta = 1e-5;  ///< ... and in rotation vectors, rad
};

/// What one implicit step did (for the adaptive controller and the logs).
struct ImplicitStepInfo {
  int krylov_iterations = 0;  ///< GMRES iterations (0 for the IMEX scheme; order 2: both stages)
  /// Stokes solves this step (order 1: 1, with GMRES 2 + iterations; order 2: 2, with GMRES
  /// 4 + iterations)
  int fluid_solves = 0;
  /// order 1: residual ≤ krylov_tol (always true with krylov_max_iter = 0); order 2: true
  bool converged = true;
  double residual = 0;  ///< relative residual of (1) at the end (order 2: the larger stage's)
  double max_displacement = 0;  ///< max_k |δX_k|, Å
  double max_rotation = 0;      ///< max_k |δθ_k|, rad
  double energy_before = 0;     ///< potential energy (elastic + electrostatic + steric) at qⁿ,
  double energy_after = 0;      ///<   and at qⁿ⁺¹, g Å² s⁻²
  bool finite = true;           ///< qⁿ⁺¹ is finite
  bool jacobian_refreshed = false;
  /// order 2: the local error estimate max_k max(|e_X,k|, ℓ_θ |e_θ,k|), Å, e = Δt ½ (k₁ + k₂)
  /// (the distance to the embedded first-order solution), ℓ_θ = rotation_length; order 1: 0
  double error = 0;
};

/// Wall time spent in the parts of ImplicitStepper::step, accumulated, s.
struct ImplicitTimings {
  double forces = 0, stiffness = 0, factorize = 0, local_solve = 0, stokes = 0;
  double overlap = 0;        ///< building M_loc = β D O D (in stiffness too)
  double analyze = 0;        ///< the LU's pattern analysis (in factorize too)
  long factorizations = 0;   ///< of the local system (count)
  long moved_refreshes = 0;  ///< refreshes of K made early by refresh_displacement (count)
  long stokes_solves = 0;    ///< Stokes solves of all trial steps (count)
};

class ImplicitStepper {
 public:
  /// Steps through `system` (not owned): its serial fluid (not distributed), coupling and force
  /// terms; the fluid's velocity array becomes the Stokes velocity of the latest solve. Two
  /// Stokes solves here measure the self mobilities. Any collection of rods (system.rods():
  /// closed or open, one or several, per-link moduli): the state is all their points, K and the
  /// local system are block-diagonal over the rods (each rod's band on its own range, block-cyclic
  /// for a closed rod, block-tridiagonal for an open one), the steric contacts couple any two.
  ImplicitStepper(System& system, const ImplicitParams& p);
  ~ImplicitStepper();

  /// With thermal noise (the System's fluid.thermal_kT > 0; issue 28, docs/thermal.md "The
  /// implicit step with noise"): order 1, velocity form, no GMRES, the overlap M_loc with
  /// mobility_scale > 0 (else the constructor throws std::invalid_argument), and the step is
  ///   u = (I + Δt M_loc K)⁻¹ [J(−μL_h)⁻¹P(𝒮(F + (1 − a) f_K) + ξ) + a M_loc f_K]
  /// with ξ the random stress of the same Stokes solve (FluidSolver::solve_stokes, thermal),
  /// f_K ~ N(0, kT K_GN) the thermal force of the Gauss–Newton stiffness (thermal_force) and
  /// a = thermal_force_local; K in the filter is the full Hessian of the elastic loads
  /// (thermal_hessian, the default) or K_GN. The filter (I + Δt M_loc K)⁻¹ is taken at the step's
  /// midpoint q̃ = qⁿ ⊕ (Δt/2) u₀, u₀ the same step with the filter held (the previous step's
  /// midpoint one, or qⁿ's after a refresh): K, M_loc and their LU are made again at q̃ every step
  /// (the refresh by displacement does not apply; docs/thermal.md "Why the implicit step with noise
  /// was hot"). With the System's thermal_drift, the random finite difference of the spreading
  /// joins the same solve and U, W are interpolated at q̃'s positions. The draws are keyed by
  /// the fluid's seed and noise_step() (set per step by the caller), so a step is a function of
  /// (qⁿ, Δt, seed, step) and of the filter held (held_filter(): a checkpoint keeps it and
  /// restore_held_filter() makes it again, so a resume from a checkpoint at any step steps
  /// alike).
  /// One implicit step of size dt (s): rod from qⁿ to qⁿ⁺¹. Returns what it did. The forces at
  /// qⁿ⁺¹ are computed here (for energy_after) and kept for the next step, so a step costs one
  /// force evaluation and 1 + krylov_iterations Stokes solves. The potential energies at qⁿ are
  /// in last_energies().
  ImplicitStepInfo step(rod::RodState& s, double dt);
  /// Puts s back to qⁿ of the latest step (a rejected trial step); at most once per step.
  void undo(rod::RodState& s);
  /// The next step refreshes K (a resumed run and the run it continues then step alike: call it
  /// where a checkpoint is written and after one is read).
  void refresh_jacobian() { steps_since_jacobian_ = 0; }

  /// With thermal noise, what of the past a step depends on besides qⁿ: the state its
  /// predictor's filter was made at (the previous step's midpoint q̃) and the steps since K was
  /// last made at a step's start (p.jacobian_every counts them).
  struct HeldFilter {
    long steps_since_refresh = 0;
    rod::RodState at;
  };
  /// The held filter (thermal noise only; empty without noise, before the first step and when
  /// the next step makes the filter at qⁿ anyway). A checkpoint keeps it, so that a run stopped
  /// at any step (a signal) and resumed steps bitwise as the uninterrupted one.
  std::optional<HeldFilter> held_filter() const;
  /// Makes the held filter again at h.at (K, M_loc and their LU for a step of dt, s) and sets
  /// the count: the next step then takes the bits of the one that followed held_filter().
  void restore_held_filter(const HeldFilter& h, double dt);

  /// (U, W) = M (F, T) at positions X: one Stokes solve (MODEL §4 spreading and interpolation,
  /// ρ dropped). Å s⁻¹, s⁻¹.
  void mobility(std::span<const Vec3> X, std::span<const Vec3> F, std::span<const Vec3> T,
                std::span<Vec3> U, std::span<Vec3> W);
  /// M as a dense [6n × 6n] matrix at X, per point (x, y, z, θx, θy, θz): one Stokes solve per
  /// column (for tests and prototypes: O(n) solves)
  Eigen::MatrixXd mobility_matrix(std::span<const Vec3> X);

  /// The elastic stiffness at s, [6n × 6n] over all rods' points, per point (x, y, z, θx, θy,
  /// θz), each rod's blocks on its own range (no link past an open rod's ends); units g s⁻²,
  /// g Å s⁻², g Å² s⁻²: the Gauss–Newton K = Δs Σ_h J_hᵀ C J_h with the small-strain analytic
  /// strain Jacobian (default), or by central finite differences over a colouring of the rod
  /// (F_k, T_k depend on points k−1..k+1 only): Gauss–Newton (stiffness_fd) or the full
  /// −∂(F, T)/∂(X, θ) (gauss_newton = false). Plus the stiffness of the steric contacts
  /// (positions only; see implicit.cpp).
  Eigen::SparseMatrix<double> stiffness(const rod::RodState& s);

  /// The thermal force f_K = Σ_h J_hᵀ √(kT Δs C_h) η_h at s, [6n] per point (F, T): J_h the
  /// small-strain strain Jacobian of half point h (as the Gauss–Newton K), C_h its moduli, η_h
  /// six unit-variance numbers keyed by (fluid seed; counter: global half-point index, 2, step):
  /// covariance kT K_GN (the steric contacts' stiffness not included). g Å s⁻², g Å² s⁻².
  Eigen::VectorXd thermal_force(const rod::RodState& s, std::uint64_t step) const;
  bool thermal() const { return kT_ > 0; }

  double self_mobility_translation() const { return m_t_; }  ///< Å s⁻¹ per g Å s⁻²
  double self_mobility_rotation() const { return m_r_; }     ///< s⁻¹ per g Å² s⁻²
  const ImplicitParams& params() const { return p_; }
  const StepEnergies& last_energies() const { return last_; }
  const std::vector<Vec3>& velocities() const { return U_; }          ///< [n] δX/Δt, Å s⁻¹
  const std::vector<Vec3>& angular_velocities() const { return W_; }  ///< [n] δθ/Δt, s⁻¹
  /// Σ F·U + T·W of the latest step(): the loads at its start qⁿ and its velocities (Scheme::
  /// power); NaN before a step
  double power() const;
  System& system() { return st_; }
  int contacts() const { return contacts_; }
  const ImplicitTimings& timings() const {
    return timings_;
  }  ///< steric segment contacts in the latest K

 private:
  System& st_;  // the system (the name the overlap block of step() reads)
  ImplicitParams p_;
  std::vector<rod::RodParams> rods_;   // every rod, in the state's order
  std::vector<rod::RodRange> ranges_;  // where each lies in the state
  int n_;                              // points of all rods
  double m_t_ = 0, m_r_ = 0;           // self mobilities
  double scale_t_ = 1;                 // GMRES weight of torques: 1/ℓ, ℓ = √(m_t/m_r)
  Eigen::SparseMatrix<double> K_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu_;        // full K (not symmetric)
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt_;  // Gauss–Newton K
  Eigen::VectorXd mloc_;                                   // diagonal of M_loc
  // GN K blocks over all points: K[k][k], K[k+1][k] (k+1 within k's rod, cyclic if closed;
  // zero at an open rod's last point)
  std::vector<Eigen::Matrix<double, 6, 6>> Kd_, Ko_;
  std::vector<BlockCyclicCholesky> bcc_;  // each rod's local system (no contacts)
  Eigen::SparseMatrix<double> Mov_;       // M_loc (overlap)
  double ov_t_ = 1, ov_r_ = 1;            // D's √c_t, √c_r (overlap)
  std::vector<int> lu_outer_, lu_inner_;  // the pattern lu_ analysed (overlap)
  std::vector<Eigen::Matrix<double, 6, 6>> sdiag_, slower_;  // its blocks (scratch)
  bool use_blocks_ = false, have_K_ = false;
  void gn_blocks(const rod::RodState& s);    // fills Kd_, Ko_
  void overlap_at(std::span<const Vec3> X);  // Mov_ = M_loc = β D O D at X
  rod::RodState mid_;                        // thermal: the midpoint q̃ of the step (scratch)
  // the finite-difference K of rod r (stiffness_fd or gauss_newton = false) into trip
  void fd_stiffness(const rod::RodState& s, std::size_t r,
                    std::vector<Eigen::Triplet<double>>& trip);
  Eigen::VectorXd local_solve(const Eigen::VectorXd& v) const;  // (I + Δt M_loc K)⁻¹ v
  bool pattern_ready_ = false;
  Eigen::Index pattern_nnz_ = 0;
  int contacts_ = 0, pattern_contacts_ = 0;  // steric contacts in K, in the analysed pattern
  double lu_dt_ = -1;                        // dt of the current factorisation (−1: none)
  long steps_since_jacobian_ = 0;
  std::vector<Vec3> X_K_;  // the positions where K (and M_loc) were last made
  StepEnergies last_;
  ImplicitTimings timings_;
  rod::RodWork work_;                            // one rod's (finite-difference K)
  std::vector<double> kept_u_;  // GMRES: the fluid velocity of the last solve of the loads
  std::vector<Vec3> U_, W_, Fa_, Ta_, Fb_, Tb_;  // U_, W_: all points; the others one rod's
  rod::RodState pert_, stage_;
  double kT_ = 0;                   // thermal noise: kT (0: none)
  bool drift_ = false;              // thermal: the stochastic drift
  std::vector<Vec3> Xn_, Fn_, Tn_;  // thermal: the points, forces and torques of the solve
  // forces at the state `cur_` (valid if has_cur_), and at the state before the latest step
  struct Cached {
    rod::RodState q;
    std::vector<Vec3> F, T;
    StepEnergies E;
  };
  Cached cur_, prev_;
  bool has_cur_ = false, has_prev_ = false;
  const Cached& forces_at(const rod::RodState& s);
  void factorize(double dt);
};

/// An accepted step under the controller: tries min(ctl.dt(), cap) (cap: e.g. the time left to
/// the next output, s), undoes and retries rejected trials. Returns the accepted step's info;
/// *dt_taken its Δt, *rejected the trials undone. Throws ibrod::RunError after 60 rejections in
/// a row (the controller's floor normally ends them long before).
ImplicitStepInfo step_adaptive(ImplicitStepper& stepper, rod::RodState& s, AdaptiveDt& ctl,
                               double cap, double* dt_taken, int* rejected = nullptr);

/// The controller's view of a step.
StepOutcome outcome(const ImplicitStepInfo& info);

/// The implicit scheme as a time integrator (`time.scheme = "implicit"`): an ImplicitStepper
/// driven by an AdaptiveDt. Its evolving state, besides the rod, is the controller's next Δt and
/// its count of accepted steps in a row (checkpoint them with state() and put them back with
/// restore(); K is then refreshed at the next step, so call restore() — or refresh() — at the
/// same point of the uninterrupted run as well, e.g. whenever a checkpoint is written).
class ImplicitIntegrator final : public Scheme {
 public:
  struct State {
    double next_dt = 0;  ///< s
    int accepted_in_a_row = 0;
    /// with thermal noise: the filter the next step's predictor uses (ImplicitStepper::
    /// held_filter; empty: made afresh at qⁿ)
    std::optional<ImplicitStepper::HeldFilter> held;
  };
  ImplicitIntegrator(System& system, const ImplicitParams& p, const AdaptiveDtParams& a);

  /// Scheme: one accepted step of at most max_dt (s; e.g. the time left to t_end): returns its
  /// Δt.
  double advance(rod::RodState& s, double max_dt) override;
  /// false with thermal noise: then a fixed Δt = the controller's dt_max, max_dt not taken
  bool adaptive() const override { return !stepper_.thermal(); }
  const ImplicitStepInfo& last_info() const { return info_; }
  int last_rejections() const { return rejected_; }
  long rejections() const { return ctl_.rejections(); }

  State state() const { return {ctl_.dt(), ctl_.accepted_in_a_row(), stepper_.held_filter()}; }
  /// Puts st back: the controller, and with noise the held filter (made again where st says;
  /// without it, or without noise, K is refreshed at the next step).
  void restore(const State& st);
  void refresh() override { stepper_.refresh_jacobian(); }
  /// Without noise K is refreshed where a checkpoint is written (the resumed run refreshes it
  /// too); with noise nothing changes: the checkpoint keeps the held filter (state()).
  void checkpoint_taken() override {
    if (!stepper_.thermal()) refresh();
  }
  double power() const override { return stepper_.power(); }
  ImplicitStepper& stepper() { return stepper_; }
  const ImplicitStepper& stepper() const { return stepper_; }
  const AdaptiveDt& controller() const { return ctl_; }

 private:
  ImplicitStepper stepper_;
  AdaptiveDt ctl_;
  ImplicitStepInfo info_;
  int rejected_ = 0;
};

namespace detail {
/// The steric contacts' stiffness −∂F_steric/∂X as triplets of the 6n × 6n system (implicit_
/// stiffness.cpp) over the segments interactions::Steric sees (p.rods: every rod's own, closed
/// or open; empty: one rod of all points with p.closed); trip = nullptr: count the contacts
/// only. Returns the number of contacts.
int add_steric_stiffness(const interactions::StericParams& p, std::span<const Vec3> X,
                         std::vector<Eigen::Triplet<double>>* trip);
}  // namespace detail

}  // namespace ibrod::integrate
