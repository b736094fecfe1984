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
#include <cstdint>
#include <string>
#include <vector>

#include "core/grid.hpp"

namespace ibrod::fluid {

struct FluidParams {
  double density = 1e-24;    ///< ρ, g Å⁻³
  double viscosity = 1e-10;  ///< μ, g Å⁻¹ s⁻¹
  double dt = 1e-10;         ///< Δt, s
  bool advection = true;     ///< include ρS_h(u); false gives the unsteady Stokes equations
  /// Thermal fluctuations (docs/thermal.md): kT of the random stress, g Å² s⁻² (0: none, the
  /// deterministic equations). Its divergence is drawn per Fourier mode k in the solve,
  ///   ξ̂(k) with ⟨ξ̂ ξ̂ᴴ⟩ = n³ · 2 kT μ λ(k) / (h³ Δt) · I,  λ = −L̂ ≥ 0,
  /// Hermitian in the k_z = 0, n/2 planes, by Philox4x32-10 keyed by (seed, noise step, mode).
  double thermal_kT = 0;
  std::uint64_t seed = 0;  ///< key of the random stress
};

/// A body force supplied one x-plane at a time (FluidSolver::step(forcing, sampler)), e.g. an
/// immersed boundary's spreading: add_plane(i, plane) adds (+=) the force density (g Å⁻² s⁻²) of
/// x-plane i to three arrays (components) of n·n values, layout j·n + k. It is called once per
/// plane per step, concurrently for different planes.
class PlaneForcing {
 public:
  virtual void add_plane(int i, std::array<double*, 3> plane) const = 0;

 protected:
  ~PlaneForcing() = default;
};

/// Reads the new velocity one x-plane at a time (FluidSolver::step(forcing, sampler)), e.g. an
/// immersed boundary's interpolation: sample_plane(i, plane) is called once per plane per step,
/// as soon as the plane of uⁿ⁺¹ (three arrays of n·n values, layout j·n + k, Å s⁻¹) is final,
/// concurrently for different planes.
class PlaneSampler {
 public:
  virtual void sample_plane(int i, std::array<const double*, 3> plane) const = 0;

 protected:
  ~PlaneSampler() = default;
};

class FluidSolver {
 public:
  /// threads: FFTW/OpenMP threads (0 = OpenMP default). plan_measure: FFTW_MEASURE (true) or
  /// FFTW_ESTIMATE (false; fast to plan, for tests). With FFTW_MEASURE, plans already in the
  /// process's wisdom (e.g. a resumed run's own, imported first) are used as they are; otherwise
  /// the wisdom cache (fluid/fftw_wisdom.hpp: wisdom_cache_path()) is imported, and if it lacks
  /// these plans they are measured and the cache rewritten. An unreadable or unwritable cache is
  /// ignored.
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
  /// it after zero_force() (or begin_step()); step() and finish_step() consume it and leave it
  /// zero. The non-const accessors mark it as written.
  double* force(int c) {
    force_zero_ = false;
    return f_[c];
  }
  std::array<double*, 3> force() {
    force_zero_ = false;
    return {f_[0], f_[1], f_[2]};
  }
  void zero_force();

  /// A uniform body-force density (g Å⁻² s⁻²) added to every step's force, in the k = 0 mode of
  /// the solve (no grid pass): e.g. −F/L³ balancing a net force F spread by a caller, so that
  /// the fluid's mean momentum stays constant. Zero by default.
  void set_mean_force(const std::array<double, 3>& f) { mean_force_ = f; }
  const std::array<double, 3>& mean_force() const { return mean_force_; }

  /// The counter of the thermal noise (FluidParams::thermal_kT > 0): the random stress of a
  /// step is keyed by (seed, this counter, mode index) and the counter advances by one with
  /// every step (Navier–Stokes, not solve_stokes). A caller that restores a state sets it (the
  /// simulation: the step number), so that a resumed run draws the same numbers.
  void set_noise_step(std::uint64_t s) { noise_step_ = s; }
  /// Δt of the following steps and thermal Stokes solves, s (> 0; read at each solve, nothing
  /// cached: the implicit scheme sets it before each thermal solve, whose noise variance is
  /// ∝ 1/Δt). Throws std::invalid_argument otherwise.
  void set_dt(double dt);
  std::uint64_t noise_step() const { return noise_step_; }

  /// Advance u by one step Δt with the current force density (MODEL §4). No allocation.
  void step();
  /// The same with the force density of `forcing` added (to force(), if that was written), plane
  /// by plane while the right-hand side is assembled, and with `sampler` reading each plane of
  /// uⁿ⁺¹ while it is in cache: the fast path, no grid-sized force pass.
  void step(const PlaneForcing& forcing, const PlaneSampler& sampler);

  /// The same step in two halves, for a caller that spreads its forces in between:
  ///   begin_step();  (accumulate (+=) the force density into force());  finish_step();
  /// begin_step() makes sure force() is zero (it normally already is: finish_step() zeroes the
  /// force array as it consumes it, so no separate zeroing pass runs). finish_step() = step().
  void begin_step();
  void finish_step();

  /// finish_step() is three OpenMP passes over the grid, public for the benchmark (each alone is
  /// not a meaningful operation; called in order they are the step):
  ///  1. x-planes: r = ρuⁿ/Δt − ρS_h(uⁿ) + fⁿ into a per-thread plane buffer (fⁿ from force(),
  ///     zeroed behind, if it was written, and from `forcing` if given), and the 2-D (y, z)
  ///     real-to-complex FFTs of the plane;
  ///  2. y-slices of the half spectrum: the 1-D x FFTs, the per-wavenumber solve, the inverse
  ///     x FFTs, all while the slice is in cache;
  ///  3. x-planes: the 2-D complex-to-real inverse FFTs into velocity().
  void pass_rhs_planes(const PlaneForcing* forcing = nullptr);
  void pass_pencils();
  void pass_inverse_planes(const PlaneSampler* sampler = nullptr);

  /// Stokes limit (issue 14, the implicit scheme's mobility): overwrites velocity() with the
  /// zero-mean solution of 0 = −G_h p + μ L_h u + f, D_h·u = 0, f the force density of
  /// `forcing` alone (ρ, Δt, advection and the previous velocity play no part):
  ///   û = P(k) f̂ / (−μ L̂(k)) for k ≠ 0,  û(0) = 0.
  /// force() must be zero (it is after every step). The same fused plane and slice passes as
  /// step(), with `sampler` (if given) reading each plane of u as it is made. No allocation.
  /// `thermal` (issue 28; needs FluidParams::thermal_kT > 0): the random stress of
  /// add_noise_slice, keyed by (seed, noise_step(), mode) as in step(), is added to f̂ in the same
  /// solve, so that u = (−μL_h)⁻¹P(f + ξ): its Brownian part has the covariance
  /// (2kT/Δt) G, G the Stokes response to a unit point force, and an interpolated J u the
  /// covariance (2kT/Δt) M — the Stokes-limit increment √(2kTΔt) M^{1/2} W per step Δt =
  /// FluidParams::dt, at no extra solve (docs/thermal.md, "Noise in the implicit scheme"). The
  /// counter is not advanced: the caller sets it (set_noise_step) for each step's draw.
  void solve_stokes(const PlaneForcing& forcing, const PlaneSampler* sampler = nullptr,
                    bool thermal = false);

  /// Fluid kinetic energy ½ρ Σ|u|² h³, g Å² s⁻².
  double kinetic_energy() const;
  /// max over the grid of |D_h·u| (central-difference divergence), s⁻¹.
  double max_divergence() const;

  /// Benchmark aid: FFTW's own threaded 3-D transforms of the same size (three r2c and three c2r
  /// 64³ transforms at 64³, planned with the solver's flags on its own buffers: the "six FFTs of
  /// one step" a textbook code would run), planned on first use. Clobbers force and velocity;
  /// not part of the physics.
  void run_ffts_only();
  /// Benchmark aid: the same six transforms as the step does them (2-D plane FFTs, 1-D x FFTs
  /// per y-slice, inverse 2-D plane FFTs, threaded over planes and slices) with nothing else:
  /// the step's own FFT time. Clobbers force and velocity; not part of the physics.
  void run_split_ffts_only();
  /// Benchmark aid: the thermal noise of one step alone (add_noise_slice over all y-slices,
  /// threaded like the step) into the spectrum buffer, which it clobbers; the noise counter is
  /// left as it was. Nothing without FluidParams::thermal_kT > 0.
  void run_noise_only();

 private:
  GridSpec grid_;
  FluidParams params_;
  std::array<double*, 3> u_{};                 // velocity, real space
  std::array<double*, 3> f_{};                 // force density, then right-hand side r
  std::array<std::complex<double>*, 3> fh_{};  // r̂, then ûⁿ⁺¹, layout [x][y][k_z], x-stride
                                               //   plane_c_ ≥ n(n/2+1) (padded, see constructor)
  std::size_t plane_c_ = 0;
  std::size_t comp_r_ = 0;       // component stride of u_ and f_, doubles (n³ + padding)
  std::size_t comp_p_ = 0;       // component stride in a thread's plane buffer (n² + padding)
  double* plane_buf_ = nullptr;  // per thread: 3 real n×n planes of r
  bool force_zero_ = true;       // f_ known to be all zero
  bool plan_measure_ = true;
  std::array<double, 3> mean_force_{};  // uniform body force, added to the k = 0 mode
  std::uint64_t noise_step_ = 0;        // counter of the thermal noise
  void* plan_plane_r2c_ = nullptr;      // 3 × 2-D (y, z) r2c: plane buffer → r̂ plane
  void* plan_plane_c2r_ = nullptr;      // 3 × 2-D (y, z) c2r: û plane → u plane
  void* plan_x_fwd_[2] = {};            // 1-D x FFTs of one y-slice (k_z × 3 components), for the
  void* plan_x_bwd_[2] = {};            //   two alignments of a slice start (even, odd y)
  void* plan_forward_ = nullptr;        // benchmark only: threaded 3-D r2c, 3 components
  void* plan_backward_ = nullptr;       // benchmark only: threaded 3-D c2r, 3 components
  void* plan_split_r2c_ = nullptr;      // benchmark only: plan_plane_r2c_ reading the force array
  int threads_ = 1;
  std::vector<int> next_, prev_;     // periodic neighbour index i ± 1 (mod n), made once
  std::vector<double> grad_symbol_;  // sin(2πk/n)/h, Å⁻¹, k = 0..n−1; exactly 0 at k = 0, n/2
  std::vector<double> lap_symbol_;  // (4/h²) sin²(πk/n), Å⁻², k = 0..n−1 (= −L̂ per direction)
  std::vector<double> grad_symbol2_, lap_symbol2_;  // k = 0..n/2, each twice (re, im)
  void release();  // frees plans and buffers (destructor, failed constructor)
  void release_plans();
  void solve_slice(int j);         // r̂ → ûⁿ⁺¹ in place on the y-slice j: projection,
                                   // implicit viscosity, 1/n³
  void solve_slice_stokes(int j);  // f̂ → û of the Stokes limit in place on the y-slice j
  void add_noise_slice(int j);     // r̂ += ξ̂ (the thermal random stress) on the y-slice j
};

}  // namespace ibrod::fluid
