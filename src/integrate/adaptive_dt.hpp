#pragma once
// Adaptive time step for the implicit scheme (issue 14, docs/large_dt.md): a pure controller that
// judges each trial step from what it measured, so that the collapse takes small steps and the
// long relaxation large ones. A trial step is rejected (the caller restores the state and tries
// again with the new, smaller dt()) if
//   - its Krylov solve did not converge, or the state is not finite;
//   - some rod point moved more than max_displacement (a fraction of min(1/κ, D): the pair
//     forces, which stay explicit, must see a small step), or some triad turned by more than
//     max_rotation;
//   - the potential energy rose by more than energy_tolerance (the overdamped rod–Stokes
//     dynamics is a gradient flow: E never increases; a rise means the step was too large).
// Rejection multiplies Δt by `shrink` (and by less if the displacement says so); after
// `grow_after` accepted steps in a row Δt grows by `grow`, never above dt_max. Units: s, Å, rad,
// g Å² s⁻² (any consistent set).
// With error_tolerance > 0 (error control, issue 24) a step is also rejected when its local
// error estimate exceeds the tolerance, and Δt follows the estimate instead of the fixed growth.
namespace ibrod::integrate {

struct AdaptiveDtParams {
  double dt_max = 1e-9;           ///< largest step (and the first), s
  double dt_min = 1e-12;          ///< a step below this is accepted regardless (see judge())
  double max_displacement = 1.0;  ///< largest |δX_k| per step, Å
  double max_rotation = 0.2;      ///< largest |δθ_k| per step, rad
  double energy_tolerance = 0.0;  ///< allowed rise of the potential energy per step
  /// largest local error estimate per step (StepOutcome::error, Å); 0: no error control. With
  /// it, Δt follows the estimate (error ∝ Δt² for the embedded first-order estimate):
  /// Δt ← Δt · clamp(0.9 √(tol/err), 0.2, grow_max), rejecting steps with err > tol
  double error_tolerance = 0.0;
  double grow_max = 2.0;  ///< largest growth factor of one step under error control
  double shrink = 0.5;    ///< Δt factor on rejection
  double grow = 1.25;     ///< Δt factor after grow_after accepted steps
  int grow_after = 4;
};

/// What a trial step measured (ImplicitStepInfo plus the energies).
struct StepOutcome {
  double max_displacement = 0;  ///< Å
  double max_rotation = 0;      ///< rad
  double energy_change = 0;     ///< E(qⁿ⁺¹) − E(qⁿ)
  double error = 0;             ///< local error estimate, Å (0: none)
  double dt = 0;                ///< the trial's Δt (0: dt(); less when the caller capped it)
  bool converged = true;
  bool finite = true;
};

class AdaptiveDt {
 public:
  /// Starts at dt_max. Throws std::invalid_argument for inconsistent parameters.
  explicit AdaptiveDt(const AdaptiveDtParams& p);
  /// Restores a controller's state (resume): its current dt and accepted-in-a-row count.
  AdaptiveDt(const AdaptiveDtParams& p, double dt, int accepted_in_a_row);

  double dt() const { return dt_; }  ///< the step to try next, s
  int accepted_in_a_row() const { return run_; }
  long rejections() const { return rejections_; }
  const AdaptiveDtParams& params() const { return p_; }

  /// Judges the trial step just taken with dt(): true = accept (dt() may grow for the next
  /// step), false = reject (dt() has shrunk; the caller undoes the step and retries). A step at
  /// dt_min or below is always accepted if it is finite (the run goes on, or the caller fails
  /// on a non-finite state).
  bool judge(const StepOutcome& o);

 private:
  AdaptiveDtParams p_;
  double dt_;
  int run_ = 0;
  long rejections_ = 0;
};

}  // namespace ibrod::integrate
