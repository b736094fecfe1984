#pragma once
// Incompressible Navier–Stokes on the periodic grid, first-order semi-implicit step of MODEL §4:
//   ρ[(uⁿ⁺¹ − uⁿ)/Δt + S_h(uⁿ)] = −G_h pⁿ⁺¹ + μ L_h uⁿ⁺¹ + fⁿ,   D_h·uⁿ⁺¹ = 0,
// G_h, D_h central differences, L_h the 7-point Laplacian, S_h(u) = ½[(u·G_h)u + D_h·(uu)].
// In Fourier space (real-to-complex FFTW transforms) this is one projection per wavenumber:
//   ûⁿ⁺¹ = P(k) r̂ / (ρ/Δt − μ L̂(k)),  r = ρuⁿ/Δt − ρS_h(uⁿ) + fⁿ,  P = I − ĝĝᵀ/|ĝ|²,
// ĝ_j = sin(2πk_j/n)/h, L̂ = −(4/h²) Σ_j sin²(πk_j/n); P = I where ĝ = 0 (pressure drops out).
// Knows nothing about rods. Owns its arrays; allocates nothing inside step().
#include <array>
#include <complex>
#include <cstddef>
#include <string>
#include <vector>

#include "core/grid.hpp"

namespace ibrod::fluid {

struct FluidParams {
  double density = 1e-24;    ///< ρ, g Å⁻³
  double viscosity = 1e-10;  ///< μ, g Å⁻¹ s⁻¹
  double dt = 1e-10;         ///< Δt, s
  bool advection = true;     ///< include ρS_h(u); false gives the unsteady Stokes equations
};

class FluidSolver {
 public:
  /// threads: FFTW/OpenMP threads (0 = OpenMP default). plan_measure: FFTW_MEASURE (true) or
  /// FFTW_ESTIMATE (false; fast to plan, for tests). With FFTW_MEASURE, plans already in the
  /// process's wisdom (e.g. a resumed run's own, imported first) are used as they are; otherwise
  /// the wisdom cache (wisdom_cache_path()) is imported, and if it lacks these plans they are
  /// measured and the cache rewritten. An unreadable or unwritable cache is ignored.
  FluidSolver(const GridSpec& grid, const FluidParams& params, int threads = 0,
              bool plan_measure = true);
  ~FluidSolver();
  FluidSolver(const FluidSolver&) = delete;
  FluidSolver& operator=(const FluidSolver&) = delete;

  const GridSpec& grid() const { return grid_; }
  const FluidParams& params() const { return params_; }
  /// threads used by FFTW and the OpenMP loops (resolved: never 0)
  int threads() const { return threads_; }

  /// velocity component c (0, 1, 2), Å s⁻¹, grid().size() values, layout GridSpec::index
  double* velocity(int c) { return u_[c]; }
  const double* velocity(int c) const { return u_[c]; }
  std::array<double*, 3> velocity() { return {u_[0], u_[1], u_[2]}; }
  std::array<const double*, 3> velocity() const { return {u_[0], u_[1], u_[2]}; }

  /// body-force density component c, g Å⁻² s⁻² (force per volume). Callers accumulate (+=) into
  /// it after zero_force(); step() consumes it (its contents are unspecified afterwards).
  double* force(int c) { return f_[c]; }
  std::array<double*, 3> force() { return {f_[0], f_[1], f_[2]}; }
  void zero_force();

  /// Advance u by one step Δt with the current force density (MODEL §4). No allocation.
  void step();

  /// The same step in two halves, for a caller that spreads its forces in between:
  ///   begin_step();  (accumulate (+=) the force density into force());  finish_step();
  /// begin_step() overwrites force() with ρuⁿ/Δt − ρS_h(uⁿ) (no zero_force() needed, and the
  /// force array is read once less than by step()); finish_step() does the FFTs and the solve and
  /// leaves uⁿ⁺¹ in velocity(). Equal to zero_force(); spread; step() up to round-off (fⁿ is
  /// added to the other terms of r in another order). No allocation.
  void begin_step();
  void finish_step();

  /// Fluid kinetic energy ½ρ Σ|u|² h³, g Å² s⁻².
  double kinetic_energy() const;
  /// max over the grid of |D_h·u| (central-difference divergence), s⁻¹.
  double max_divergence() const;

  /// Benchmark aid: executes the forward and the backward plan once on the solver's own buffers
  /// (the 6 real FFTs of one step), clobbering force and velocity. Not part of the physics.
  void run_ffts_only();
  void run_forward_fft_only();   ///< the forward plan alone (benchmark aid, clobbers force)
  void run_backward_fft_only();  ///< the backward plan alone (benchmark aid, clobbers velocity)
  /// Benchmark aid: the spectral pass of finish_step() alone, on whatever the spectral buffer
  /// holds. Not part of the physics.
  void run_spectral_only();

 private:
  GridSpec grid_;
  FluidParams params_;
  std::array<double*, 3> u_{};                 // velocity, real space
  std::array<double*, 3> f_{};                 // force density, then right-hand side r
  std::array<std::complex<double>*, 3> fh_{};  // r̂, then ûⁿ⁺¹
  void* plan_forward_ = nullptr;               // fftw_plan r → r̂ (3 components)
  void* plan_backward_ = nullptr;              // fftw_plan ûⁿ⁺¹ → u (3 components)
  int threads_ = 1;
  std::vector<int> next_, prev_;     // periodic neighbour index i ± 1 (mod n), made once
  std::vector<double> grad_symbol_;  // sin(2πk/n)/h, Å⁻¹, k = 0..n−1; exactly 0 at k = 0, n/2
  std::vector<double> lap_symbol_;   // (4/h²) sin²(πk/n), Å⁻², k = 0..n−1 (= −L̂ per direction)
  void release();                    // frees plans and buffers (destructor, failed constructor)
  void release_plans();
  void spectral_pass();              // r̂ → ûⁿ⁺¹ in place: projection, viscosity, 1/n³
};

/// On-disk FFTW wisdom cache used by FluidSolver when plan_measure is set: $IBROD_FFTW_WISDOM_CACHE
/// if set (empty: no cache), else $XDG_CACHE_HOME/ibrod/fftw-wisdom, else
/// $HOME/.cache/ibrod/fftw-wisdom ("" if none of them is set).
std::string wisdom_cache_path();

}  // namespace ibrod::fluid
