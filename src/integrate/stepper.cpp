#include "integrate/stepper.hpp"

#include <omp.h>

#include <algorithm>
#include <array>

namespace ibrod::integrate {

namespace {
// Every OpenMP loop of the step (rod, coupling, pair forces) runs on the configured thread count;
// the fluid passes its own count to FFTW and its loops.
void set_threads(int threads) {
  if (threads > 0) omp_set_num_threads(threads);
}
}  // namespace

Stepper::Stepper(const StepperParams& p)
    : p_((set_threads(p.threads), p)),
      fluid_(std::make_unique<fluid::FluidSolver>(p.grid, p.fluid, p.threads, p.plan_measure)),
      coupler_(p.grid, p.kernel_width),
      plane_coupler_(coupler_, p.rod.n),
      electro_(p.electro, p.rod.n),
      steric_(p.steric, p.rod.n) {
  const int n = p.rod.n;
  work_.resize(n);
  F_.resize(n);
  T_.resize(n);
  U_.resize(n);
  W_.resize(n);
}

StepEnergies Stepper::compute_forces(const rod::RodState& s) {
  std::fill(F_.begin(), F_.end(), Vec3::Zero());
  std::fill(T_.begin(), T_.end(), Vec3::Zero());
  StepEnergies e;
  e.elastic = rod::elastic_forces(p_.rod, s, work_, F_, T_);
  // MODEL §3 sign convention: −∂E/∂X of every non-elastic potential goes to the fluid unchanged.
  if (p_.electro.enabled) e.electro = electro_.accumulate(s.X, F_);
  if (p_.steric.enabled) e.steric = steric_.accumulate(s.X, F_);
  return e;
}

void Stepper::step(rod::RodState& s) {
  last_ = compute_forces(s);
  // fⁿ = spread(F, T) is added to r = ρuⁿ/Δt − ρS_h(uⁿ) plane by plane inside the fluid step
  // (MODEL §4), and U, W at Xⁿ are sampled from uⁿ⁺¹ plane by plane: the kernel weights are
  // evaluated once, and no grid-sized pass is spent on either
  plane_coupler_.prepare(s.X, F_, T_);
  fluid_->step(PlaneCouplerForcing(plane_coupler_), PlaneCouplerSampler(plane_coupler_));
  plane_coupler_.finish_interpolation(U_, W_);
  rod::advance(s, U_, W_, p_.fluid.dt);
}

}  // namespace ibrod::integrate
