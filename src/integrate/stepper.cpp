#include "integrate/stepper.hpp"

#include <algorithm>
#include <chrono>

#include "core/philox.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <utility>

namespace ibrod::integrate {

namespace {
// Every OpenMP loop of the step (rod, coupling, pair forces) runs on the configured thread count;
// the fluid passes its own count to FFTW and its loops.
void set_threads(int threads) {
  if (threads > 0) omp_set_num_threads(threads);
}

std::unique_ptr<fluid::FluidSolver> make_serial(const StepperParams& p) {
  if (p.distributed) return nullptr;
  return std::make_unique<fluid::FluidSolver>(p.grid, p.fluid, p.threads, p.plan_measure);
}

std::unique_ptr<fluid::DistributedFluid> make_distributed(const StepperParams& p) {
  if (!p.distributed) return nullptr;
  return std::make_unique<fluid::DistributedFluid>(p.grid, p.fluid, p.threads, p.plan_measure);
}

ib::XSlab slab_of(const GridSpec& grid, const fluid::DistributedFluid* d) {
  return d ? ib::XSlab{d->x_begin(), d->x_count()} : ib::XSlab{0, grid.n};
}

// the hard core follows the rods: each its own segments, closed (cyclic) or open
interactions::StericParams steric_of(const StepperParams& p) {
  interactions::StericParams s = p.steric;
  s.closed = p.rod.closed;
  s.rods = rod::ranges_of(all_rods(p));
  return s;
}
}  // namespace

std::vector<rod::RodParams> all_rods(const StepperParams& p) {
  std::vector<rod::RodParams> r{p.rod};
  r.insert(r.end(), p.more_rods.begin(), p.more_rods.end());
  return r;
}

int point_count(const StepperParams& p) {
  int n = p.rod.n;
  for (const rod::RodParams& r : p.more_rods) n += r.n;
  return n;
}

Stepper::Stepper(const StepperParams& p)
    : p_((set_threads(p.threads), p)),
      fluid_(make_serial(p)),
      dist_(make_distributed(p)),
      coupler_(p.grid, p.kernel_width, slab_of(p.grid, dist_.get())),
      plane_coupler_(coupler_, p.thermal_drift ? 3 * point_count(p) : point_count(p)),
      electro_(p.electro, point_count(p)),
      steric_(steric_of(p), point_count(p)) {
  const int n = point_count(p);
  if (p.more_rods.empty()) {
    work_.resize(n);
  } else {
    rods_ = all_rods(p);
    ranges_ = rod::ranges_of(rods_);
    const std::size_t R = rods_.size();
    rod_state_.resize(R);
    rod_work_.resize(R);
    rod_F_.resize(R);
    rod_T_.resize(R);
    for (std::size_t r = 0; r < R; ++r) {
      rod_state_[r].X.resize(rods_[r].n);
      rod_state_[r].D.resize(rods_[r].n);
      rod_work_[r].resize(rods_[r].n);
      rod_F_[r].resize(rods_[r].n);
      rod_T_[r].resize(rods_[r].n);
    }
  }
  F_.resize(n);
  T_.resize(n);
  U_.resize(n);
  W_.resize(n);
  if (dist_) rank_sum_.resize(6 * std::size_t(n));
  const bool external = !p.external_force.isZero(0) || !p.external_torque.isZero(0);
  if (dist_ && external)
    throw std::invalid_argument(
        "Stepper: an external force or torque (external.force_pN, external.torque_pN_nm) runs "
        "on one process only");
  // the reaction of the external force: a uniform body force −F/L³ on the fluid
  if (fluid_) {
    const double vol = p.grid.L * p.grid.L * p.grid.L;
    fluid_->set_mean_force(
        {-p.external_force[0] / vol, -p.external_force[1] / vol, -p.external_force[2] / vol});
  }
}

void Stepper::set_noise_step(std::uint64_t s) {
  if (fluid_) fluid_->set_noise_step(s);
}

Stepper::~Stepper() = default;

const fluid::FluidSolver* Stepper::serial_fluid() const {
  if (!fluid_) throw std::logic_error("Stepper::fluid(): the fluid is distributed over MPI ranks");
  return fluid_.get();
}
fluid::FluidSolver* Stepper::serial_fluid() {
  return const_cast<fluid::FluidSolver*>(std::as_const(*this).serial_fluid());
}

// Adds the time since the previous mark to phase k (nothing without a StepPhaseTimes).
class PhaseClock {
 public:
  explicit PhaseClock(StepPhaseTimes* t) : t_(t) {
    if (t_) last_ = std::chrono::steady_clock::now();
  }
  void mark(int k) {
    if (!t_) return;
    const auto now = std::chrono::steady_clock::now();
    t_->ms[k] += std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
  }

 private:
  StepPhaseTimes* t_;
  std::chrono::steady_clock::time_point last_;
};

void Stepper::add_external(const std::vector<Vec3>& X) {
  const std::size_t n = X.size();
  if (n == 0) return;
  if (!p_.external_force.isZero(0)) {
    const Vec3 f = p_.external_force / double(n);
    for (Vec3& F : F_) F += f;
  }
  if (!p_.external_torque.isZero(0)) {
    // ω = I⁻¹ τ with I = Σ (|r|² 1 − r rᵀ), r = X_k − X̄: the rigid rotation's force pattern
    // f_k = ω × r_k has Σ f_k = ω × Σ r_k = 0 and Σ r_k × f_k = I ω = τ
    Vec3 c = Vec3::Zero();
    for (const Vec3& x : X) c += x;
    c /= double(n);
    Mat3 I = Mat3::Zero();
    for (const Vec3& x : X) {
      const Vec3 r = x - c;
      I += r.squaredNorm() * Mat3::Identity() - r * r.transpose();
    }
    const Vec3 w = I.completeOrthogonalDecomposition().solve(p_.external_torque);
    for (std::size_t k = 0; k < n; ++k) F_[k] += w.cross(X[k] - c);
  }
}

StepEnergies Stepper::compute_forces(const rod::RodState& s) {
  PhaseClock none(nullptr);
  return forces(s, none);
}

StepEnergies Stepper::energies(const rod::RodState& s) const {
  StepEnergies e;
  if (rods_.empty()) {
    e.elastic = rod::elastic_energy(p_.rod, s);
  } else {
    rod::RodState one;
    for (std::size_t r = 0; r < rods_.size(); ++r) {
      rod::extract(s, ranges_[r], one);
      const rod::ElasticEnergy er = rod::elastic_energy(rods_[r], one);
      e.elastic.bend += er.bend;
      e.elastic.twist += er.twist;
      e.elastic.stretch += er.stretch;
    }
  }
  if (p_.electro.enabled) e.electro = electro_.energy(s.X);
  if (p_.steric.enabled) e.steric = steric_.energy(s.X);
  return e;
}

rod::ElasticEnergy Stepper::elastic(const rod::RodState& s) {
  if (rods_.empty()) return rod::elastic_forces(p_.rod, s, work_, F_, T_);
  if (s.size() != int(F_.size()))
    throw std::invalid_argument("Stepper: the state has " + std::to_string(s.size()) +
                                " points, the rods " + std::to_string(F_.size()));
  // each rod on its own points: a copy of its range, its forces added back at its offset
  rod::ElasticEnergy e;
  for (std::size_t r = 0; r < rods_.size(); ++r) {
    const rod::RodRange& g = ranges_[r];
    rod::extract(s, g, rod_state_[r]);
    std::fill(rod_F_[r].begin(), rod_F_[r].end(), Vec3::Zero());
    std::fill(rod_T_[r].begin(), rod_T_[r].end(), Vec3::Zero());
    const rod::ElasticEnergy er =
        rod::elastic_forces(rods_[r], rod_state_[r], rod_work_[r], rod_F_[r], rod_T_[r]);
    for (int k = 0; k < g.n; ++k) {
      F_[g.offset + k] += rod_F_[r][k];
      T_[g.offset + k] += rod_T_[r][k];
    }
    e.bend += er.bend;
    e.twist += er.twist;
    e.stretch += er.stretch;
  }
  return e;
}

StepEnergies Stepper::forces(const rod::RodState& s, PhaseClock& clock) {
  std::fill(F_.begin(), F_.end(), Vec3::Zero());
  std::fill(T_.begin(), T_.end(), Vec3::Zero());
  StepEnergies e;
  e.elastic = elastic(s);
  clock.mark(0);
  // MODEL §3 sign convention: −∂E/∂X of every non-elastic potential goes to the fluid unchanged.
  if (p_.electro.enabled) e.electro = electro_.accumulate(s.X, F_);
  if (p_.steric.enabled) e.steric = steric_.accumulate(s.X, F_);
  add_external(s.X);
  clock.mark(1);
  return e;
}

void Stepper::step(rod::RodState& s, StepPhaseTimes* phases) {
  PhaseClock clock(dist_ ? nullptr : phases);
  forces(s, clock);
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

double Stepper::fluid_kinetic_energy() const {
  return dist_ ? dist_->kinetic_energy() : fluid_->kinetic_energy();
}

int Stepper::fluid_threads() const { return dist_ ? dist_->threads() : fluid_->threads(); }

std::array<const double*, 3> Stepper::whole_velocity(std::vector<double>& scratch) const {
  if (!dist_) return {fluid_->velocity(0), fluid_->velocity(1), fluid_->velocity(2)};
  dist_->gather_velocity(scratch);
  if (dist_->rank() != 0) return {nullptr, nullptr, nullptr};
  const std::size_t n3 = p_.grid.size();
  return {scratch.data(), scratch.data() + n3, scratch.data() + 2 * n3};
}

void Stepper::set_whole_velocity(std::array<const double*, 3> u) {
  if (dist_) {
    dist_->scatter_velocity(u);
    return;
  }
  const std::size_t n3 = p_.grid.size();
  for (int c = 0; c < 3; ++c) std::copy_n(u[c], n3, fluid_->velocity(c));
}

}  // namespace ibrod::integrate
