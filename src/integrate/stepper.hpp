#pragma once
// The explicit scheme: one time step of the generalized IB method (MODEL §4) through the System
// (integrate/system.hpp: the fluid, the IB coupling and the force terms):
//   1. rod forces at Xⁿ, Dⁿ: elastic F, T (point force/torque), + electrostatic + steric F
//   2. PlaneCoupler::prepare: kernel weights of every point, points listed by x-plane
//   3. FluidSolver::step(forcing, sampler): per x-plane r = ρuⁿ/Δt − ρS_h(uⁿ) + fⁿ, fⁿ = spread
//      F, T (force + ½ curl of torque) added to the plane in cache; FFTs and the solve give
//      uⁿ⁺¹, and each x-plane of it is sampled for the interpolation as soon as it is made
//   4. interpolate U, W at Xⁿ from uⁿ⁺¹: the planes' shares added in a fixed order
//   5. move: X += Δt U, D ← R(Δt W) D
// Buffers are sized once; step() allocates nothing.
//
// With StepperParams::distributed (`mpirun -np K ibrod run`, built with MPI) the fluid is a
// fluid::DistributedFluid split in x-slabs over the K ranks and the rod work is replicated: every
// rank computes all rod forces, spreads every point into its own planes only and interpolates
// from its own planes only (ib::XSlab); the partial U, W are then summed over the ranks in rank
// order on every rank (DistributedFluid::sum_over_ranks: MPI_Allgather + the same additions
// everywhere), so every rank holds bitwise the same rod state after each step. (The distributed
// step uses the whole-grid Coupler restricted to the rank's slab, not the PlaneCoupler.)
#include <memory>
#include <vector>

#include "integrate/system.hpp"

namespace ibrod::integrate {

class PhaseClock;

/// The explicit scheme (time.scheme = "explicit"): a fixed Δt (StepperParams::fluid.dt).
class Stepper final : public Scheme {
 public:
  /// The explicit scheme on `system` (not owned; it must outlive the Stepper).
  explicit Stepper(System& system);
  /// The explicit scheme on a System of its own, built from p.
  explicit Stepper(const StepperParams& p);
  ~Stepper() override;

  /// Advance rod and fluid by one Δt. phases (serial fluid only): add each phase's wall time.
  void step(rod::RodState& s, StepPhaseTimes* phases = nullptr);
  /// Scheme: step(s); returns the fixed Δt (max_dt is not honoured: the explicit Δt is fixed).
  double advance(rod::RodState& s, double max_dt) override;
  bool adaptive() const override { return false; }
  double power() const override;

  System& system() { return sys_; }
  const System& system() const { return sys_; }
  const StepperParams& params() const { return p_; }
  /// velocities U (Å s⁻¹) of the latest step()
  const std::vector<Vec3>& velocities() const { return U_; }

 private:
  Stepper(std::unique_ptr<System> own, System* shared);
  std::unique_ptr<System> own_;  // the System when the Stepper was built from params
  System& sys_;
  // the system's parts the step reads, under the names the step has always used
  const StepperParams& p_;
  fluid::FluidSolver* fluid_;      // serial, or
  fluid::DistributedFluid* dist_;  // distributed
  ib::Coupler& coupler_;
  ib::PlaneCoupler& plane_coupler_;
  const std::vector<Vec3>& F_;  // the system's point forces and torques
  const std::vector<Vec3>& T_;
  // [n] velocities U (Å s⁻¹), angular velocities W (s⁻¹)
  std::vector<Vec3> U_, W_;
  bool stepped_ = false;                      // a step() taken: U_, W_ are its velocities (power())
  std::vector<Vec3> Xa_, Fa_, Ta_, Ua_, Wa_;  // thermal_drift: the points with the RFD pairs
  void drift_step(rod::RodState& s, PhaseClock& clock);
  std::vector<double> rank_sum_;  // distributed: [6n] U then W, packed for sum_over_ranks
};

}  // namespace ibrod::integrate
