#include "fluid/navier_stokes.hpp"

#include <fftw3.h>
#include <omp.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <new>
#include <stdexcept>
#include <string>

#include "core/philox.hpp"
#include "core/target_clones.hpp"
#include "fluid/advection.hpp"
#include "fluid/fftw_wisdom.hpp"
#include "fluid/spectral.hpp"

namespace ibrod::fluid {
namespace {

fftw_plan as_plan(void* p) { return static_cast<fftw_plan>(p); }

// doubles between the components of u, f and the plane buffer (constructor): 1088 bytes, a
// multiple of 32 (FFTW's alignment) that puts the components' rows in different cache sets
constexpr std::size_t kCompPad = 136;

}  // namespace

FluidSolver::FluidSolver(const GridSpec& grid, const FluidParams& params, int threads,
                         bool plan_measure)
    : grid_(grid), params_(params) {
  detail::check_fluid_args("FluidSolver", grid, params, threads);
  threads_ = threads > 0 ? threads : std::max(1, omp_get_max_threads());

  const int n = grid_.n;
  const double h = grid_.h();
  detail::make_neighbour_tables(n, next_, prev_);
  detail::make_spectral_symbols(n, h, grad_symbol_, lap_symbol_);

  // the k_z symbols once per double of the interleaved half spectrum (solve_row)
  grad_symbol2_.resize(2 * std::size_t(n / 2 + 1));
  lap_symbol2_.resize(2 * std::size_t(n / 2 + 1));
  for (int k = 0; k <= n / 2; ++k) {
    grad_symbol2_[2 * k] = grad_symbol2_[2 * k + 1] = grad_symbol_[k];
    lap_symbol2_[2 * k] = lap_symbol2_[2 * k + 1] = lap_symbol_[k];
  }

  init_fftw_threads();
  const std::size_t nr = grid_.size();
  const int nzh = n / 2 + 1;
  // x-stride of the half spectrum: n(n/2+1) complex values padded to an odd number of 64-byte
  // cache lines (and an even number of complex values, which keeps every plane 32-byte aligned).
  // Unpadded, the rows of a y-slice, which the x transforms and the solve walk, lie a multiple of
  // 4 KiB apart at 256³ (and 1–2 KiB at 64³–128³) and fall into the same few cache sets: the x
  // pass then took 0.98 of 1.3 s per step at 256³ (FFTW_ESTIMATE).
  plane_c_ = std::size_t(n) * nzh;
  while (plane_c_ % 8 != 4) plane_c_ += 2;  // 16-byte values: 4 mod 8 = an odd number of lines
  const std::size_t nc = std::size_t(n) * plane_c_;  // component stride, complex values
  const std::size_t np = std::size_t(n) * n;         // points of one real x-plane
  plan_measure_ = plan_measure;
  // The three components of u and f (and of the plane buffer) lie apart by their size plus
  // kCompPad doubles: unpadded, they are a multiple of 4 KiB apart, and the rows that the
  // advection pass reads of the three components of three x-planes (nine streams) all fall into
  // the same sets of an 8-way first-level cache.
  comp_r_ = nr + kCompPad;
  comp_p_ = np + kCompPad;
  double* u = fftw_alloc_real(3 * comp_r_);
  double* f = fftw_alloc_real(3 * comp_r_);
  fftw_complex* fh = fftw_alloc_complex(3 * nc);
  plane_buf_ = fftw_alloc_real(3 * comp_p_ * std::size_t(threads_));
  // Components are consecutive blocks of one allocation (howmany = 3 plans need a fixed
  // stride); n even makes every block start 32-byte aligned, like the base.
  for (int c = 0; c < 3; ++c) {
    u_[c] = u ? u + c * comp_r_ : nullptr;
    f_[c] = f ? f + c * comp_r_ : nullptr;
    fh_[c] = fh ? reinterpret_cast<std::complex<double>*>(fh + c * nc) : nullptr;
  }
  if (!u || !f || !fh || !plane_buf_) {
    // u_[0] etc. point at the allocation bases, so release() frees exactly what was allocated
    release();
    throw std::bad_alloc();
  }

  // The step's transforms are single-threaded FFTW plans that the OpenMP passes execute on
  // their own planes and slices (fftw_execute_dft_* on new arrays is thread-safe). A new array
  // must have the alignment the plan was made for: x-planes start at multiples of n·n reals or
  // plane_c_ complex values (32-byte multiples for even n), y-slices at multiples of n/2+1
  // complex values, which alternate between two alignments when n/2+1 is odd: one x plan each.
  // FFTW_DESTROY_INPUT: the plane buffer and r̂ are scratch.
  const int plane_dims[2] = {n, n};
  fftw_iodim xdim{n, int(plane_c_), int(plane_c_)};           // the x axis of the half spectrum
  fftw_iodim many[2] = {{nzh, 1, 1}, {3, int(nc), int(nc)}};  // k_z, then the component
  auto make_plans = [&](unsigned fl) {
    fftw_plan_with_nthreads(1);
    plan_plane_r2c_ = fftw_plan_many_dft_r2c(2, plane_dims, 3, plane_buf_, nullptr, 1, int(comp_p_),
                                             fh, nullptr, 1, int(nc), fl);
    plan_plane_c2r_ = fftw_plan_many_dft_c2r(2, plane_dims, 3, fh, nullptr, 1, int(nc), u, nullptr,
                                             1, int(comp_r_), fl);
    bool ok = plan_plane_r2c_ && plan_plane_c2r_;
    for (int par = 0; par < 2; ++par) {
      fftw_complex* slice = fh + par * nzh;
      plan_x_fwd_[par] = fftw_plan_guru_dft(1, &xdim, 2, many, slice, slice, FFTW_FORWARD, fl);
      plan_x_bwd_[par] = fftw_plan_guru_dft(1, &xdim, 2, many, slice, slice, FFTW_BACKWARD, fl);
      ok = ok && plan_x_fwd_[par] && plan_x_bwd_[par];
    }
    if (ok) return true;
    release_plans();
    return false;
  };
  plan_with_wisdom(plan_measure, FFTW_DESTROY_INPUT, make_plans);
  if (!plan_plane_r2c_) {
    release();
    throw std::runtime_error("FluidSolver: FFTW planning failed");
  }
  // FFTW_MEASURE scribbles on the buffers while planning: start from rest only afterwards.
  std::fill(u, u + 3 * comp_r_, 0.0);
  std::fill(f, f + 3 * comp_r_, 0.0);
  force_zero_ = true;
}

FluidSolver::~FluidSolver() { release(); }

void FluidSolver::release_plans() {
  for (void** p :
       {&plan_plane_r2c_, &plan_plane_c2r_, &plan_x_fwd_[0], &plan_x_fwd_[1], &plan_x_bwd_[0],
        &plan_x_bwd_[1], &plan_forward_, &plan_backward_, &plan_split_r2c_}) {
    if (*p) fftw_destroy_plan(as_plan(*p));
    *p = nullptr;
  }
}

void FluidSolver::release() {
  release_plans();
  fftw_free(u_[0]);  // fftw_free(nullptr) is a no-op
  fftw_free(f_[0]);
  fftw_free(fh_[0]);
  fftw_free(plane_buf_);
  u_ = {};
  f_ = {};
  fh_ = {};
  plane_buf_ = nullptr;
}

void FluidSolver::zero_force() {
  const std::ptrdiff_t total = std::ptrdiff_t(3 * comp_r_);  // the pads too: they stay zero
  double* f = f_[0];
#pragma omp parallel for simd num_threads(threads_) schedule(static)
  for (std::ptrdiff_t i = 0; i < total; ++i) f[i] = 0.0;
  force_zero_ = true;
}

void FluidSolver::begin_step() {
  if (!force_zero_) zero_force();
}

void FluidSolver::step() { finish_step(); }

void FluidSolver::step(const PlaneForcing& forcing, const PlaneSampler& sampler) {
  pass_rhs_planes(&forcing);
  pass_pencils();
  pass_inverse_planes(&sampler);
}

void FluidSolver::finish_step() {
  pass_rhs_planes();
  pass_pencils();
  pass_inverse_planes();
}

void FluidSolver::pass_rhs_planes(const PlaneForcing* forcing) {
  const int n = grid_.n;
  const std::size_t np = std::size_t(n) * n;
  const double h = grid_.h();
  const double a = params_.density / params_.dt;               // ρ/Δt
  const double b = params_.advection ? params_.density : 0.0;  // ρ, or 0 for Stokes
  const int* next = next_.data();
  const int* prev = prev_.data();
  fftw_plan plan = as_plan(plan_plane_r2c_);
  auto at = [np](const std::array<double*, 3>& v, int i) {
    return std::array<const double*, 3>{v[0] + i * np, v[1] + i * np, v[2] + i * np};
  };
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int i = 0; i < n; ++i) {
    double* buf = plane_buf_ + 3 * comp_p_ * std::size_t(omp_get_thread_num());
    const std::array<double*, 3> r{buf, buf + comp_p_, buf + 2 * comp_p_};
    // r = ρuⁿ/Δt − ρS_h(uⁿ) + fⁿ (MODEL §4): fⁿ from the force array if it was written (the
    // plane zeroed behind), plus the forcing's
    const bool with_array = !force_zero_;
    if (with_array) {
      for (int c = 0; c < 3; ++c) {
        double* f = f_[c] + i * np;
        std::copy_n(f, np, r[c]);
        std::fill_n(f, np, 0.0);
      }
    }
    detail::rhs_plane(n, h, next, prev, at(u_, i), at(u_, next[i]), at(u_, prev[i]), r, a, b,
                      !with_array);
    if (forcing) forcing->add_plane(i, r);
    // r̂ of this plane in y and z, into its place in the half spectrum
    fftw_execute_dft_r2c(plan, buf, reinterpret_cast<fftw_complex*>(fh_[0]) + i * plane_c_);
  }
  force_zero_ = true;
}

void FluidSolver::pass_pencils() {
  const int n = grid_.n;
  const int nzh = n / 2 + 1;
  fftw_complex* base = reinterpret_cast<fftw_complex*>(fh_[0]);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int j = 0; j < n; ++j) {
    // the slice of wavenumber index j in y: x × k_z × 3 components, ~100 KB at 64³
    const int par = (j * nzh) % 2;
    fftw_complex* slice = base + std::size_t(j) * nzh;
    fftw_execute_dft(as_plan(plan_x_fwd_[par]), slice, slice);
    if (params_.thermal_kT > 0) add_noise_slice(j);
    solve_slice(j);
    fftw_execute_dft(as_plan(plan_x_bwd_[par]), slice, slice);
  }
  ++noise_step_;
}

void FluidSolver::pass_inverse_planes(const PlaneSampler* sampler) {
  const int n = grid_.n;
  const std::size_t np = std::size_t(n) * n;
  fftw_plan plan = as_plan(plan_plane_c2r_);
  fftw_complex* in = reinterpret_cast<fftw_complex*>(fh_[0]);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int i = 0; i < n; ++i) {
    fftw_execute_dft_c2r(plan, in + i * plane_c_, u_[0] + i * np);
    if (sampler) sampler->sample_plane(i, {u_[0] + i * np, u_[1] + i * np, u_[2] + i * np});
  }
}

void FluidSolver::run_split_ffts_only() {
  const int n = grid_.n;
  const int nzh = n / 2 + 1;
  const std::size_t np = std::size_t(n) * n;
  fftw_complex* fh = reinterpret_cast<fftw_complex*>(fh_[0]);
  if (!plan_split_r2c_) {
    // the step's plane r2c reads its three components comp_p_ apart (the plane buffer); here
    // they are comp_r_ apart (the force array): the same transform with another input stride
    const int dims[2] = {n, n};
    auto make = [&](unsigned fl) {
      fftw_plan_with_nthreads(1);
      plan_split_r2c_ = fftw_plan_many_dft_r2c(2, dims, 3, f_[0], nullptr, 1, int(comp_r_), fh,
                                               nullptr, 1, int(n * plane_c_), fl);
      return plan_split_r2c_ != nullptr;
    };
    if (!plan_with_wisdom(plan_measure_, FFTW_DESTROY_INPUT, make))
      throw std::runtime_error("FluidSolver: FFTW planning failed");
  }
  force_zero_ = false;
  // f's planes are aligned like the force array (n·n reals apart, n even)
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int i = 0; i < n; ++i)
    fftw_execute_dft_r2c(as_plan(plan_split_r2c_), f_[0] + i * np, fh + i * plane_c_);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int j = 0; j < n; ++j) {
    const int par = (j * nzh) % 2;
    fftw_complex* slice = fh + std::size_t(j) * nzh;
    fftw_execute_dft(as_plan(plan_x_fwd_[par]), slice, slice);
    fftw_execute_dft(as_plan(plan_x_bwd_[par]), slice, slice);
  }
  pass_inverse_planes();
}

namespace {

// One x-row (fixed wavenumbers k_x, k_y) of the per-wavenumber solve, MODEL §4:
//   ûⁿ⁺¹ = P(k) r̂ / (ρ/Δt − μL̂(k)) / n³ = (r̂ − ĝ (ĝ·r̂)/|ĝ|²) · norm / (ρ/Δt) / den',
//   den' = 1 + (μ Δt/ρ)(−L̂) ≥ 1, dimensionless.
// The row is walked as 2(n/2+1) doubles (re, im interleaved) with the k_z symbols duplicated per
// double (gz2, lz2), so the loop is contiguous and vectorises fully. One division per double:
// q = 1/((|ĝ|² + ε) den') gives 1/|ĝ|² = den' q and 1/den' = (|ĝ|² + ε) q. Where ĝ = 0 (k_j ∈
// {0, n/2} for all j) D_h and G_h vanish: no pressure, P = I; then ĝ·r̂ = 0 exactly and any finite
// 1/|ĝ|² will do: ε = DBL_MIN keeps q finite (den' ≥ 1) without a branch, and leaves every nonzero
// |ĝ|² (≥ sin²(2π/n)/h², Å⁻²) bit-for-bit unchanged.
IBROD_TARGET_CLONES void solve_row(int len, double gx, double gy, double gxy2, double lxy,
                                   const double* gz2, const double* lz2, double visc_per_inertia,
                                   double out_scale, double* r0, double* r1, double* r2) {
#pragma omp simd
  for (int t = 0; t < len; ++t) {
    const double gz = gz2[t];
    const double g2 = gxy2 + gz * gz + DBL_MIN;                  // |ĝ|² + ε, Å⁻²
    const double den = 1.0 + visc_per_inertia * (lxy + lz2[t]);  // den'
    const double q = 1.0 / (g2 * den);
    const double ig2 = den * q;                 // 1/|ĝ|²
    const double scale = out_scale * (g2 * q);  // norm/(ρ/Δt)/den'
    const double a0 = r0[t], a1 = r1[t], a2 = r2[t];
    const double p = (gx * a0 + gy * a1 + gz * a2) * ig2;  // ĝ·r̂ / |ĝ|²
    r0[t] = scale * (a0 - gx * p);
    r1[t] = scale * (a1 - gy * p);
    r2[t] = scale * (a2 - gz * p);
  }
}

}  // namespace

namespace {

// One x-row of the thermal noise (add_noise_slice) for k_z in [kz0, kz1), where k and −k are both
// stored (0 < k_z < n/2): r̂_c(k) += √(cλ) (z_c + i z_{c+3}), z the six unit-variance numbers of
// the Philox output for the counter (mode0 + k_z, 0, step). Branch-free: vectorises.
IBROD_TARGET_CLONES void noise_row(int kz0, int kz1, std::uint32_t mode0, double lxy,
                                   const double* lz, double c, std::uint32_t st0, std::uint32_t st1,
                                   std::uint32_t key0, std::uint32_t key1, double* r0, double* r1,
                                   double* r2) {
#pragma omp simd
  for (int kz = kz0; kz < kz1; ++kz) {
    const Philox4x32 w = philox4x32_10({mode0 + std::uint32_t(kz), 0u, st0, st1}, key0, key1);
    double z[6];
    unit_variance6(w, z);
    const double a = std::sqrt(c * (lxy + lz[kz]));
    r0[2 * kz] += a * z[0];
    r1[2 * kz] += a * z[1];
    r2[2 * kz] += a * z[2];
    r0[2 * kz + 1] += a * z[3];
    r1[2 * kz + 1] += a * z[4];
    r2[2 * kz + 1] += a * z[5];
  }
}

}  // namespace

// The thermal random stress of docs/thermal.md, drawn in Fourier space: r̂(k) += ξ̂(k) with
//   ⟨ξ̂_c(k) ξ̂_c(k)*⟩ = n³ σ²(k),  σ²(k) = 2 kT μ λ(k) / (h³ Δt),  λ = −L̂ = (4/h²) Σ_j sin²(πk_j/n),
// independent components c and modes, i.e. the unnormalised DFT of a real field whose divergence
// part is the discrete divergence of a random stress (the projection in the solve removes the
// rest). Each k takes six unit-variance numbers (real and imaginary parts of three components)
// from one Philox4x32-10 output keyed by the seed, with the counter (mode index, 0, step): the
// same numbers for any thread count and order. In the k_z = 0 and n/2 planes the half spectrum
// holds k and −k: k draws with the index of whichever of the two comes first and takes the
// complex conjugate otherwise (a Hermitian spectrum, i.e. a real field), and a k equal to −k gets
// a real value of the full variance. k = 0 (λ = 0) gets none: momentum is conserved.
void FluidSolver::add_noise_slice(int j) {
  const int n = grid_.n;
  const int nzh = n / 2 + 1;
  const double h = grid_.h();
  // variance of each real and imaginary part: n³ σ²/2 = c λ
  const double c =
      params_.thermal_kT * params_.viscosity * double(grid_.size()) / (h * h * h * params_.dt);
  const double* ls = lap_symbol_.data();
  const std::uint32_t key0 = std::uint32_t(params_.seed), key1 = std::uint32_t(params_.seed >> 32);
  const std::uint32_t st0 = std::uint32_t(noise_step_), st1 = std::uint32_t(noise_step_ >> 32);
  double* r[3] = {reinterpret_cast<double*>(fh_[0]), reinterpret_cast<double*>(fh_[1]),
                  reinterpret_cast<double*>(fh_[2])};
  const int nj = (n - j) % n;
  for (int i = 0; i < n; ++i) {
    const int ni = (n - i) % n;
    const double lxy = ls[i] + ls[j];
    const std::size_t o = 2 * (std::size_t(i) * plane_c_ + std::size_t(j) * nzh);
    const std::uint32_t row = std::uint32_t((std::size_t(i) * n + j) * nzh);
    noise_row(1, n / 2, row, lxy, ls, c, st0, st1, key0, key1, r[0] + o, r[1] + o, r[2] + o);
    for (const int kz : {0, n / 2}) {  // the Hermitian planes
      const double lam = lxy + ls[kz];
      if (lam == 0.0) continue;  // k = 0
      // which of k, −k draws, and whether k is its own conjugate (a real value)
      std::uint32_t mode = row + std::uint32_t(kz);
      double sign = 1.0;
      const bool real_only = ni == i && nj == j;
      if (!real_only && std::size_t(ni) * n + nj < std::size_t(i) * n + j) {
        mode = std::uint32_t((std::size_t(ni) * n + nj) * nzh + kz);
        sign = -1.0;
      }
      double z[6];
      unit_variance6(philox4x32_10({mode, 0u, st0, st1}, key0, key1), z);
      const std::size_t t = o + 2 * std::size_t(kz);
      const double a = std::sqrt((real_only ? 2.0 : 1.0) * c * lam);
      for (int d = 0; d < 3; ++d) {
        r[d][t] += a * z[d];
        if (!real_only) r[d][t + 1] += sign * a * z[d + 3];
      }
    }
  }
}

void FluidSolver::run_noise_only() {
  if (!(params_.thermal_kT > 0)) return;
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int j = 0; j < grid_.n; ++j) add_noise_slice(j);
}

void FluidSolver::solve_slice(int j) {
  const int n = grid_.n;
  const double inertia = params_.density / params_.dt;          // ρ/Δt, g Å⁻³ s⁻¹
  const double visc_per_inertia = params_.viscosity / inertia;  // μΔt/ρ, Å²
  // the unnormalised FFTW round trip multiplies by n³
  const double out_scale = 1.0 / double(grid_.size()) / inertia;
  const int nzh = n / 2 + 1;
  const double* gs = grad_symbol_.data();
  const double* ls = lap_symbol_.data();
  double* r0 = reinterpret_cast<double*>(fh_[0]);  // interleaved (re, im)
  double* r1 = reinterpret_cast<double*>(fh_[1]);
  double* r2 = reinterpret_cast<double*>(fh_[2]);
  const double gy = gs[j];
  if (j == 0)  // the uniform body force: the k = 0 entry of the unnormalised DFT is n³ f
    for (int c = 0; c < 3; ++c)
      (c == 0 ? r0 : c == 1 ? r1 : r2)[0] += double(grid_.size()) * mean_force_[c];
  for (int i = 0; i < n; ++i) {
    const double gx = gs[i];
    const std::size_t o = 2 * (std::size_t(i) * plane_c_ + std::size_t(j) * nzh);
    solve_row(2 * nzh, gx, gy, gx * gx + gy * gy, ls[i] + ls[j], grad_symbol2_.data(),
              lap_symbol2_.data(), visc_per_inertia, out_scale, r0 + o, r1 + o, r2 + o);
  }
}

void FluidSolver::run_ffts_only() {
  if (!plan_forward_) {
    // planned on first use, threaded like a textbook solver's, with the step's planner flags
    const int n = grid_.n;
    const int nr = int(comp_r_);  // component stride
    const int nc = n * n * (n / 2 + 1);
    const int dims[3] = {n, n, n};
    auto* fh = reinterpret_cast<fftw_complex*>(fh_[0]);
    auto make = [&](unsigned fl) {
      fftw_plan_with_nthreads(threads_);
      plan_forward_ =
          fftw_plan_many_dft_r2c(3, dims, 3, f_[0], nullptr, 1, nr, fh, nullptr, 1, nc, fl);
      plan_backward_ =
          fftw_plan_many_dft_c2r(3, dims, 3, fh, nullptr, 1, nc, u_[0], nullptr, 1, nr, fl);
      fftw_plan_with_nthreads(1);
      if (plan_forward_ && plan_backward_) return true;
      for (void** p : {&plan_forward_, &plan_backward_}) {
        if (*p) fftw_destroy_plan(as_plan(*p));
        *p = nullptr;
      }
      return false;
    };
    if (!plan_with_wisdom(plan_measure_, FFTW_DESTROY_INPUT, make))
      throw std::runtime_error("FluidSolver: FFTW planning failed");
  }
  force_zero_ = false;
  fftw_execute(as_plan(plan_forward_));
  fftw_execute(as_plan(plan_backward_));
}

double FluidSolver::kinetic_energy() const {
  // Partial sums over a fixed number of blocks, added in block order: bit-for-bit the same for
  // any thread count and any thread timing. (An OpenMP reduction(+) adds the threads' partial
  // sums in the order the threads finish, which changes the last bits from run to run with more
  // than two threads; a resumed run must reproduce every bit of the uninterrupted one.)
  constexpr int kPerComp = 22, kBlocks = 3 * kPerComp;
  const std::ptrdiff_t total = std::ptrdiff_t(grid_.size());  // per component
  double part[kBlocks];
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int b = 0; b < kBlocks; ++b) {
    const double* u = u_[b / kPerComp];
    const int bc = b % kPerComp;
    const std::ptrdiff_t lo = total * bc / kPerComp, hi = total * (bc + 1) / kPerComp;
    double s = 0.0;
#pragma omp simd reduction(+ : s)
    for (std::ptrdiff_t i = lo; i < hi; ++i) s += u[i] * u[i];
    part[b] = s;
  }
  double sum = 0.0;
  for (int b = 0; b < kBlocks; ++b) sum += part[b];
  const double h = grid_.h();
  return 0.5 * params_.density * sum * h * h * h;  // ½ρ Σ|u|² h³, g Å² s⁻²
}

double FluidSolver::max_divergence() const {
  const int n = grid_.n;
  const std::size_t nz = std::size_t(n);
  const double inv2h = 0.5 / grid_.h();
  const int* next = next_.data();
  const int* prev = prev_.data();
  const double* ux = u_[0];
  const double* uy = u_[1];
  const double* uz = u_[2];
  double dmax = 0.0;
#pragma omp parallel for num_threads(threads_) schedule(static) reduction(max : dmax)
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const std::size_t oc = (std::size_t(i) * n + j) * nz;
      const std::size_t oxp = (std::size_t(next[i]) * n + j) * nz;
      const std::size_t oxm = (std::size_t(prev[i]) * n + j) * nz;
      const std::size_t oyp = (std::size_t(i) * n + next[j]) * nz;
      const std::size_t oym = (std::size_t(i) * n + prev[j]) * nz;
      for (int k = 0; k < n; ++k) {
        // D_h·u, MODEL §4 central differences
        const double d = (ux[oxp + k] - ux[oxm + k]) + (uy[oyp + k] - uy[oym + k]) +
                         (uz[oc + next[k]] - uz[oc + prev[k]]);
        dmax = std::max(dmax, std::abs(d) * inv2h);
      }
    }
  }
  return dmax;
}

}  // namespace ibrod::fluid

// ---------------------------------------------------------------------------------------------
// Stokes limit (issue 14): the implicit rod–fluid scheme applies the IB mobility
// M = interpolate ∘ (−μL_h)⁻¹P ∘ spread once per Krylov iteration, with ρ/Δt dropped.
namespace ibrod::fluid {
namespace {

// One x-row of û = P f̂ / (−μL̂) / n³ (cf. solve_row): lap = −L̂ ≥ 0, zero only at k = 0, whose
// entries the caller overwrites. kEps keeps the quotient finite there and where ĝ = 0 without a
// branch (DBL_MIN would underflow in the product), and leaves every nonzero |ĝ|², −L̂
// (≥ ~1e-6 Å⁻²) bit-for-bit unchanged.
IBROD_TARGET_CLONES void solve_row_stokes(int len, double gx, double gy, double gxy2, double lxy,
                                          const double* gz2, const double* lz2, double out_scale,
                                          double* r0, double* r1, double* r2) {
#pragma omp simd
  for (int t = 0; t < len; ++t) {
    const double gz = gz2[t];
    constexpr double kEps = 1e-150;
    const double g2 = gxy2 + gz * gz + kEps;  // |ĝ|² + ε, Å⁻²
    const double lap = lxy + lz2[t] + kEps;   // −L̂ + ε, Å⁻²
    const double q = 1.0 / (g2 * lap);
    const double ig2 = lap * q;                 // 1/|ĝ|²
    const double scale = out_scale * (g2 * q);  // 1/(n³ μ (−L̂))
    const double a0 = r0[t], a1 = r1[t], a2 = r2[t];
    const double p = (gx * a0 + gy * a1 + gz * a2) * ig2;
    r0[t] = scale * (a0 - gx * p);
    r1[t] = scale * (a1 - gy * p);
    r2[t] = scale * (a2 - gz * p);
  }
}

}  // namespace

void FluidSolver::solve_slice_stokes(int j) {
  const int n = grid_.n;
  const double out_scale = 1.0 / double(grid_.size()) / params_.viscosity;
  const int nzh = n / 2 + 1;
  const double* gs = grad_symbol_.data();
  const double* ls = lap_symbol_.data();
  double* r0 = reinterpret_cast<double*>(fh_[0]);
  double* r1 = reinterpret_cast<double*>(fh_[1]);
  double* r2 = reinterpret_cast<double*>(fh_[2]);
  const double gy = gs[j];
  for (int i = 0; i < n; ++i) {
    const double gx = gs[i];
    const std::size_t o = 2 * (std::size_t(i) * plane_c_ + std::size_t(j) * nzh);
    solve_row_stokes(2 * nzh, gx, gy, gx * gx + gy * gy, ls[i] + ls[j], grad_symbol2_.data(),
                     lap_symbol2_.data(), out_scale, r0 + o, r1 + o, r2 + o);
    if (i == 0 && j == 0)  // the mean: a net force has no periodic Stokes solution; u's mean = 0
      for (double* r : {r0, r1, r2}) r[o] = r[o + 1] = 0.0;
  }
}

void FluidSolver::set_dt(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw std::invalid_argument("FluidSolver::set_dt: dt must be positive and finite");
  params_.dt = dt;
}

void FluidSolver::solve_stokes(const PlaneForcing& forcing, const PlaneSampler* sampler,
                               bool thermal) {
  if (!(params_.viscosity > 0.0))
    throw std::logic_error("FluidSolver::solve_stokes: needs a viscosity > 0");
  if (thermal && !(params_.thermal_kT > 0.0 && params_.dt > 0.0))
    throw std::logic_error("FluidSolver::solve_stokes: thermal needs thermal_kT > 0 and dt > 0");
  if (!force_zero_)
    throw std::logic_error("FluidSolver::solve_stokes: force() must be zero (it was written)");
  const int n = grid_.n;
  const int nzh = n / 2 + 1;
  const std::size_t np = std::size_t(n) * n;
  fftw_plan plan = as_plan(plan_plane_r2c_);
  fftw_complex* base = reinterpret_cast<fftw_complex*>(fh_[0]);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int i = 0; i < n; ++i) {
    double* buf = plane_buf_ + 3 * comp_p_ * std::size_t(omp_get_thread_num());
    const std::array<double*, 3> r{buf, buf + comp_p_, buf + 2 * comp_p_};
    for (int c = 0; c < 3; ++c) std::fill_n(r[c], np, 0.0);
    forcing.add_plane(i, r);
    fftw_execute_dft_r2c(plan, buf, base + i * plane_c_);
  }
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int j = 0; j < n; ++j) {
    const int par = (j * nzh) % 2;
    fftw_complex* slice = base + std::size_t(j) * nzh;
    fftw_execute_dft(as_plan(plan_x_fwd_[par]), slice, slice);
    if (thermal) add_noise_slice(j);  // the random stress, as in step(): ξ̂ on this slice
    solve_slice_stokes(j);
    fftw_execute_dft(as_plan(plan_x_bwd_[par]), slice, slice);
  }
  pass_inverse_planes(sampler);
}

}  // namespace ibrod::fluid
