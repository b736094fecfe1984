#pragma once
// The fluid step of FluidSolver (MODEL §4, same physics, same Δt) on one grid split over the
// ranks of MPI_COMM_WORLD in slabs of x-planes, with FFTW's MPI transforms (`mpirun -np K
// ibrod run`, issue 7). Rank r owns the planes x ∈ [x_begin(), x_begin() + x_count()),
// x_count() = n/K; K must divide n.
//
// One step (begin_step(); spread into force(); finish_step()):
//   1. r = ρuⁿ/Δt − ρS_h(uⁿ) on the own planes (detail::rhs_plane), reading one halo plane of u
//      on each side, received from the neighbouring ranks (periodic) after the previous step;
//   2. the caller adds fⁿ into force() (local planes only);
//   3. r is copied into FFTW's padded, component-interleaved real layout (howmany = 3) and
//      transformed in place by one r2c plan with FFTW_MPI_TRANSPOSED_OUT: the spectrum is held
//      as n/K y-rows × n x × (n/2+1) z (y distributed), so no transpose back is needed;
//   4. the per-wavenumber projection, implicit viscosity and 1/n³ (the formula of
//      FluidSolver::spectral_pass, same symbols, same DBL_MIN trick) on that transposed layout;
//   5. c2r with FFTW_MPI_TRANSPOSED_IN, copy into the own planes of u, halo exchange.
// The result equals FluidSolver's to round-off (other FFT algorithms and summation orders).
//
// Every collective (constructor, finish_step, kinetic_energy, max_divergence, gather_velocity,
// scatter_velocity, sum_over_ranks) must be called by every rank in the same order.
// Compiled with IBROD_MPI only (the class is declared always; without MPI the constructor
// throws).
#include <array>
#include <cstddef>
#include <vector>

#include "core/grid.hpp"
#include "fluid/navier_stokes.hpp"

namespace ibrod::fluid {

/// true if this build has the distributed solver (built with MPI and FFTW MPI)
bool distributed_available();

class DistributedFluid {
 public:
  /// Collective over MPI_COMM_WORLD (MPI must be initialised). threads: OpenMP/FFTW threads per
  /// rank (0 = OpenMP default). plan_measure: FFTW_MEASURE (rank 0's wisdom, e.g. the cache of
  /// wisdom_cache_path() or a resumed run's own, is broadcast first and all ranks' wisdom
  /// gathered to rank 0 afterwards) or FFTW_ESTIMATE. Throws std::invalid_argument (on every
  /// rank alike) for a bad grid or parameters, or if the rank count does not divide n.
  DistributedFluid(const GridSpec& grid, const FluidParams& params, int threads = 0,
                   bool plan_measure = true);
  ~DistributedFluid();
  DistributedFluid(const DistributedFluid&) = delete;
  DistributedFluid& operator=(const DistributedFluid&) = delete;

  const GridSpec& grid() const { return grid_; }
  const FluidParams& params() const { return params_; }
  int threads() const { return threads_; }
  int rank() const { return rank_; }
  int ranks() const { return ranks_; }
  int x_begin() const { return x0_; }  ///< first own x-plane
  int x_count() const { return nx_; }  ///< own x-planes (n / ranks())

  /// Own velocity planes of component c, Å s⁻¹: x_count() n² values, global point (i, j, k) at
  /// ((i − x_begin()) n + j) n + k. After writing into them call exchange_halos().
  double* velocity(int c) { return u_[c] + plane_; }
  const double* velocity(int c) const { return u_[c] + plane_; }
  std::array<double*, 3> velocity() { return {velocity(0), velocity(1), velocity(2)}; }
  std::array<const double*, 3> velocity() const { return {velocity(0), velocity(1), velocity(2)}; }

  /// Own force-density planes (layout as velocity()); begin_step() overwrites them with
  /// ρuⁿ/Δt − ρS_h(uⁿ), the caller adds (+=) fⁿ, finish_step() consumes them.
  double* force(int c) { return f_[c]; }
  std::array<double*, 3> force() { return {f_[0], f_[1], f_[2]}; }

  void begin_step();
  /// Collective: FFTs, solve, uⁿ⁺¹ in velocity(), halos exchanged.
  void finish_step();
  /// Collective: receives the halo planes x_begin() − 1 and x_begin() + x_count() of u.
  void exchange_halos();

  /// Collective: ½ρ Σ|u|² h³ over the whole grid, g Å² s⁻²; bitwise the same on every rank
  /// (the ranks' partial sums are added in rank order).
  double kinetic_energy() const;
  /// Collective: max over the whole grid of |D_h·u|, s⁻¹.
  double max_divergence() const;

  /// Collective: the whole velocity on rank 0, 3 n³ values (u_x, u_y, u_z blocks, each in
  /// GridSpec::index order); `full` is left untouched on the other ranks.
  void gather_velocity(std::vector<double>& full) const;
  /// Collective: every rank passes the whole velocity (3 arrays of n³ values); each copies its
  /// own planes and the halos are exchanged.
  void scatter_velocity(std::array<const double*, 3> full);

  /// Collective: data[i] ← Σ_ranks data[i], added in rank order on every rank (MPI_Allgather,
  /// then the same additions everywhere), so the result is bitwise identical on all ranks
  /// whatever MPI's reduction algorithms. Allocates only when count grows.
  void sum_over_ranks(double* data, std::size_t count);

 private:
  GridSpec grid_;
  FluidParams params_;
  int threads_ = 1;
  int rank_ = 0, ranks_ = 1;
  int x0_ = 0, nx_ = 0;            // own x-planes (real space)
  int y0_ = 0, ny_ = 0;            // own y-rows of the transposed spectrum
  std::size_t plane_ = 0;          // n², values per plane
  std::array<double*, 3> u_{};     // (nx + 2) planes: halo x0 − 1, own planes, halo x0 + nx
  std::array<double*, 3> f_{};     // nx planes
  double* buf_ = nullptr;          // FFTW's padded interleaved real array / spectrum, in place
  void* plan_forward_ = nullptr;   // fftw_plan
  void* plan_backward_ = nullptr;  // fftw_plan
  std::vector<int> next_, prev_;
  std::vector<double> grad_symbol_, lap_symbol_;  // as FluidSolver's
  std::vector<double> gathered_;                  // sum_over_ranks scratch
  void release();
  void spectral_pass();
};

}  // namespace ibrod::fluid
