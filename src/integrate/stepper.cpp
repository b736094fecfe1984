#include "integrate/stepper.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <utility>

#include "core/philox.hpp"
#include "integrate/phase_clock.hpp"

namespace ibrod::integrate {

Stepper::Stepper(System& system) : Stepper(nullptr, &system) {}

Stepper::Stepper(const StepperParams& p) : Stepper(std::make_unique<System>(p), nullptr) {}

Stepper::Stepper(std::unique_ptr<System> own, System* shared)
    : own_(std::move(own)),
      sys_(shared ? *shared : *own_),
      p_(sys_.params()),
      fluid_(sys_.serial_or_null()),
      dist_(sys_.distributed_or_null()),
      coupler_(sys_.coupler()),
      plane_coupler_(sys_.plane_coupler()),
      F_(sys_.forces()),
      T_(sys_.torques()) {
  const std::size_t n = std::size_t(sys_.point_count());
  U_.resize(n);
  W_.resize(n);
  if (dist_) rank_sum_.resize(6 * n);
}

Stepper::~Stepper() = default;

double Stepper::advance(rod::RodState& s, double /*max_dt*/) {
  step(s);
  return p_.fluid.dt;
}

double Stepper::power() const {
  return stepped_ ? integrate::power(F_, T_, U_, W_) : std::numeric_limits<double>::quiet_NaN();
}

void Stepper::step(rod::RodState& s, StepPhaseTimes* phases) {
  stepped_ = true;
  sys_.compute_forces(s, phases);
  PhaseClock clock(dist_ ? nullptr : phases);
  if (dist_) {
    // the same step on this rank's x-slab; U, W are partial sums until summed over the ranks
    dist_->begin_step();
    coupler_.spread(s.X, F_, T_, dist_->force());
    dist_->finish_step();
    const fluid::DistributedFluid& fl = *dist_;
    coupler_.interpolate(s.X, fl.velocity(), U_, W_);
    const std::size_t n = U_.size();
    for (std::size_t k = 0; k < n; ++k)
      for (int d = 0; d < 3; ++d) {
        rank_sum_[3 * k + d] = U_[k][d];
        rank_sum_[3 * (n + k) + d] = W_[k][d];
      }
    dist_->sum_over_ranks(rank_sum_.data(), rank_sum_.size());
    for (std::size_t k = 0; k < n; ++k)
      for (int d = 0; d < 3; ++d) {
        U_[k][d] = rank_sum_[3 * k + d];
        W_[k][d] = rank_sum_[3 * (n + k) + d];
      }
    rod::advance(s, U_, W_, p_.fluid.dt);
    return;
  }
  if (p_.thermal_drift && p_.fluid.thermal_kT > 0) {
    drift_step(s, clock);
    return;
  }
  // fⁿ = spread(F, T) is added to r = ρuⁿ/Δt − ρS_h(uⁿ) plane by plane inside the fluid step
  // (MODEL §4), and U, W at Xⁿ are sampled from uⁿ⁺¹ plane by plane: the kernel weights are
  // evaluated once, and no grid-sized pass is spent on either (FluidSolver::step's three passes,
  // called one by one here so that the benchmark can time them)
  plane_coupler_.prepare(s.X, F_, T_);
  clock.mark(2);
  const PlaneCouplerForcing forcing(plane_coupler_);
  const PlaneCouplerSampler sampler(plane_coupler_);
  fluid_->pass_rhs_planes(&forcing);
  clock.mark(3);
  fluid_->pass_pencils();
  clock.mark(4);
  fluid_->pass_inverse_planes(&sampler);
  clock.mark(5);
  plane_coupler_.finish_interpolation(U_, W_);
  clock.mark(6);
  rod::advance(s, U_, W_, p_.fluid.dt);
  clock.mark(7);
}

// The step with the stochastic drift kT ∂_X·M (StepperParams::thermal_drift; docs/thermal.md,
// "The stochastic drift"). With M = J L⁻¹ S, ∂_X·M = J L⁻¹ (∂_X·S) + (∂_X J) : L⁻¹ S:
// the first term by a random finite difference of the spreading, the force pairs ±(kT/δ) W̃_k at
// X_k ± (δ/2) W̃_k (W̃ of mean 0 and unit covariance, keyed by the seed and the noise step like
// the random stress, counter word 1 = 1) spread with the rod's forces; the second by
// interpolating uⁿ⁺¹ at the midpoint X̃ = Xⁿ + (Δt/2) J(Xⁿ) uⁿ⁺¹ (its mean over the noise is
// (Δt²/2) (∂J) : ⟨u uᵀ⟩ J ᵀ = kT Δt (∂J) : L⁻¹ S where the per-step velocity covariance is
// 2kT L⁻¹/Δt, the grid-scale modes that carry the drift).
void Stepper::drift_step(rod::RodState& s, PhaseClock& clock) {
  const std::size_t n = s.X.size();
  const double kT = p_.fluid.thermal_kT, dt = p_.fluid.dt;
  const double delta = 1e-4 * p_.grid.h();  // Å: the RFD's cancellation error ~ 1e-16 h/δ
  const std::uint64_t step = fluid_->noise_step(), seed = p_.fluid.seed;
  const std::uint32_t key0 = std::uint32_t(seed), key1 = std::uint32_t(seed >> 32);
  const std::uint32_t st0 = std::uint32_t(step), st1 = std::uint32_t(step >> 32);
  Xa_.resize(3 * n);
  Fa_.resize(3 * n);
  Ta_.assign(3 * n, Vec3::Zero());
  Ua_.resize(3 * n);
  Wa_.resize(3 * n);
  for (std::size_t k = 0; k < n; ++k) {
    double z[6];
    unit_variance6(philox4x32_10({std::uint32_t(k), 1u, st0, st1}, key0, key1), z);
    const Vec3 w(z[0], z[1], z[2]);
    Xa_[k] = s.X[k];
    Fa_[k] = F_[k];
    Ta_[k] = T_[k];
    Xa_[n + k] = s.X[k] + (0.5 * delta) * w;
    Xa_[2 * n + k] = s.X[k] - (0.5 * delta) * w;
    Fa_[n + k] = (kT / delta) * w;
    Fa_[2 * n + k] = -(kT / delta) * w;
  }
  plane_coupler_.prepare(Xa_, Fa_, Ta_);
  clock.mark(2);
  const PlaneCouplerForcing forcing(plane_coupler_);
  const PlaneCouplerSampler sampler(plane_coupler_, n);  // the force pairs: spread only
  fluid_->pass_rhs_planes(&forcing);
  clock.mark(3);
  fluid_->pass_pencils();
  clock.mark(4);
  fluid_->pass_inverse_planes(&sampler);
  clock.mark(5);
  plane_coupler_.finish_interpolation(std::span<Vec3>(Ua_.data(), n),
                                      std::span<Vec3>(Wa_.data(), n), n);
  for (std::size_t k = 0; k < n; ++k) Xa_[k] = s.X[k] + (0.5 * dt) * Ua_[k];
  // the midpoint interpolation through the plane coupler, as the step's own: the kernel weights
  // once, each x-plane of uⁿ⁺¹ sampled while in cache, the planes' shares added in x-stencil
  // order (the same for any thread count; 5× cheaper at 64³ than ib::Coupler's per-point
  // gathers over the whole grid)
  plane_coupler_.prepare(std::span<const Vec3>(Xa_.data(), n), {}, {});
  const int N = p_.grid.n;
  const std::size_t np = std::size_t(N) * std::size_t(N);
  const std::array<const double*, 3> u{fluid_->velocity(0), fluid_->velocity(1),
                                       fluid_->velocity(2)};
#pragma omp parallel for schedule(static)
  for (int i = 0; i < N; ++i)
    plane_coupler_.sample_plane(i, {u[0] + i * np, u[1] + i * np, u[2] + i * np});
  plane_coupler_.finish_interpolation(U_, W_);
  clock.mark(6);
  rod::advance(s, U_, W_, dt);
  clock.mark(7);
}

}  // namespace ibrod::integrate
