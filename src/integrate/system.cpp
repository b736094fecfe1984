#include "integrate/system.hpp"

#include <omp.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

#include "integrate/phase_clock.hpp"

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
  s.rods = rod::ranges_of(p.rods);
  return s;
}
}  // namespace

int point_count(const StepperParams& p) {
  int n = 0;
  for (const rod::RodParams& r : p.rods) n += r.n;
  return n;
}

System::System(const StepperParams& p)
    : p_((set_threads(p.threads), p)),
      fluid_(make_serial(p)),
      dist_(make_distributed(p)),
      coupler_(p.grid, p.kernel_width, slab_of(p.grid, dist_.get())),
      plane_coupler_(coupler_,
                     p.thermal_drift ? 3 * integrate::point_count(p) : integrate::point_count(p)),
      electro_(p.electro, integrate::point_count(p)),
      steric_(steric_of(p), integrate::point_count(p)) {
  const int n = integrate::point_count(p);
  rods_ = p.rods;
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
  F_.resize(n);
  T_.resize(n);
  const bool external = !p.external_force.isZero(0) || !p.external_torque.isZero(0);
  if (dist_ && external)
    throw std::invalid_argument(
        "System: an external force or torque (external.force_pN, external.torque_pN_nm) runs "
        "on one process only");
  // the reaction of the external force: a uniform body force −F/L³ on the fluid
  if (fluid_) {
    const double vol = p.grid.L * p.grid.L * p.grid.L;
    fluid_->set_mean_force(
        {-p.external_force[0] / vol, -p.external_force[1] / vol, -p.external_force[2] / vol});
  }
}

void System::set_noise_step(std::uint64_t s) {
  if (fluid_) fluid_->set_noise_step(s);
}

System::~System() = default;

const fluid::FluidSolver* System::serial_fluid() const {
  if (!fluid_) throw std::logic_error("System::fluid(): the fluid is distributed over MPI ranks");
  return fluid_.get();
}
fluid::FluidSolver* System::serial_fluid() {
  return const_cast<fluid::FluidSolver*>(std::as_const(*this).serial_fluid());
}

void System::add_external(const std::vector<Vec3>& X) {
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

StepEnergies System::energies(const rod::RodState& s) const {
  StepEnergies e;
  rod::RodState one;
  for (std::size_t r = 0; r < rods_.size(); ++r) {
    rod::extract(s, ranges_[r], one);
    const rod::ElasticEnergy er = rod::elastic_energy(rods_[r], one);
    e.elastic.bend += er.bend;
    e.elastic.twist += er.twist;
    e.elastic.stretch += er.stretch;
  }
  if (p_.electro.enabled) e.electro = electro_.energy(s.X);
  if (p_.steric.enabled) e.steric = steric_.energy(s.X);
  return e;
}

rod::ElasticEnergy System::elastic(const rod::RodState& s) {
  if (s.size() != int(F_.size()))
    throw std::invalid_argument("System: the state has " + std::to_string(s.size()) +
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

StepEnergies System::compute_forces(const rod::RodState& s, StepPhaseTimes* phases) {
  PhaseClock clock(dist_ ? nullptr : phases);
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

double System::fluid_kinetic_energy() const {
  return dist_ ? dist_->kinetic_energy() : fluid_->kinetic_energy();
}

int System::fluid_threads() const { return dist_ ? dist_->threads() : fluid_->threads(); }

std::array<const double*, 3> System::whole_velocity(std::vector<double>& scratch) const {
  if (!dist_) return {fluid_->velocity(0), fluid_->velocity(1), fluid_->velocity(2)};
  dist_->gather_velocity(scratch);
  if (dist_->rank() != 0) return {nullptr, nullptr, nullptr};
  const std::size_t n3 = p_.grid.size();
  return {scratch.data(), scratch.data() + n3, scratch.data() + 2 * n3};
}

void System::set_whole_velocity(std::array<const double*, 3> u) {
  if (dist_) {
    dist_->scatter_velocity(u);
    return;
  }
  const std::size_t n3 = p_.grid.size();
  for (int c = 0; c < 3; ++c) std::copy_n(u[c], n3, fluid_->velocity(c));
}

double power(std::span<const Vec3> F, std::span<const Vec3> T, std::span<const Vec3> U,
             std::span<const Vec3> W) {
  double p = 0;
  for (std::size_t k = 0; k < F.size(); ++k) p += F[k].dot(U[k]) + T[k].dot(W[k]);
  return p;
}

}  // namespace ibrod::integrate
