#include "fluid/navier_stokes.hpp"

#include <fftw3.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <new>
#include <numbers>
#include <stdexcept>
#include <string>

#include "fluid/advection.hpp"
#include "fluid/fftw_wisdom.hpp"

namespace ibrod::fluid {
namespace {

// fftw_init_threads must run once per process, before any threaded plan is made.
void init_fftw_threads() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (fftw_init_threads() == 0) throw std::runtime_error("FluidSolver: fftw_init_threads failed");
  });
}

fftw_plan as_plan(void* p) { return static_cast<fftw_plan>(p); }

// Best effort throughout: a cache that cannot be read or written only costs planning time.
void save_wisdom_cache(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  // write then rename: concurrent processes never see a half-written file
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  if (export_wisdom(tmp)) fs::rename(tmp, path, ec);
  if (ec || fs::exists(tmp, ec)) fs::remove(tmp, ec);
}

}  // namespace

std::string wisdom_cache_path() {
  if (const char* p = std::getenv("IBROD_FFTW_WISDOM_CACHE")) return p;  // "" disables
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
    return std::string(x) + "/ibrod/fftw-wisdom";
  if (const char* h = std::getenv("HOME"); h && *h)
    return std::string(h) + "/.cache/ibrod/fftw-wisdom";
  return {};
}

FluidSolver::FluidSolver(const GridSpec& grid, const FluidParams& params, int threads,
                         bool plan_measure)
    : grid_(grid), params_(params) {
  // Even n: the r2c half-spectrum and the Nyquist handling assume it; n ≥ 4 so that ±1 and ±2
  // neighbours are distinct points.
  if (grid.n < 4 || grid.n % 2 != 0)
    throw std::invalid_argument("FluidSolver: grid n must be even and >= 4, got " +
                                std::to_string(grid.n));
  if (!(grid.L > 0.0)) throw std::invalid_argument("FluidSolver: box edge L must be > 0");
  // ρ/Δt > 0 and μ ≥ 0 keep the implicit denominator ρ/Δt − μL̂ positive for every k.
  if (!(params.density > 0.0)) throw std::invalid_argument("FluidSolver: density must be > 0");
  if (!(params.dt > 0.0)) throw std::invalid_argument("FluidSolver: dt must be > 0");
  if (!(params.viscosity >= 0.0))
    throw std::invalid_argument("FluidSolver: viscosity must be >= 0");
  if (threads < 0) throw std::invalid_argument("FluidSolver: threads must be >= 0");
  threads_ = threads > 0 ? threads : std::max(1, omp_get_max_threads());

  const int n = grid_.n;
  const double h = grid_.h();
  detail::make_neighbour_tables(n, next_, prev_);
  grad_symbol_.assign(n, 0.0);
  lap_symbol_.assign(n, 0.0);
  for (int k = 0; k <= n / 2; ++k) {
    // Exact zeros at k = 0, n/2 and exact oddness sin(2π(n−k)/n) = −sin(2πk/n): the spectral
    // multiplier is then exactly even in k, as the c2r transform assumes of a real field.
    const double g = (k == 0 || k == n / 2) ? 0.0 : std::sin(2.0 * std::numbers::pi * k / n) / h;
    const double s = std::sin(std::numbers::pi * k / n);
    grad_symbol_[k] = g;
    lap_symbol_[k] = 4.0 / (h * h) * s * s;
    if (k > 0 && k < n / 2) {
      grad_symbol_[n - k] = -g;
      lap_symbol_[n - k] = lap_symbol_[k];
    }
  }

  init_fftw_threads();
  const std::size_t nr = grid_.size();
  const std::size_t nc = std::size_t(n) * n * (n / 2 + 1);
  double* u = fftw_alloc_real(3 * nr);
  double* f = fftw_alloc_real(3 * nr);
  fftw_complex* fh = fftw_alloc_complex(3 * nc);
  // Components are consecutive blocks of one allocation (howmany = 3 plans need a fixed
  // stride); n even makes every block start 16-byte aligned, like the base.
  for (int c = 0; c < 3; ++c) {
    u_[c] = u ? u + c * nr : nullptr;
    f_[c] = f ? f + c * nr : nullptr;
    fh_[c] = fh ? reinterpret_cast<std::complex<double>*>(fh + c * nc) : nullptr;
  }
  if (!u || !f || !fh) {
    // u_[0] etc. point at the allocation bases, so release() frees exactly what was allocated
    release();
    throw std::bad_alloc();
  }

  const int dims[3] = {n, n, n};
  // FFTW_DESTROY_INPUT: step() owns both inputs as scratch (force is consumed, r̂ is rebuilt).
  const unsigned flags = (plan_measure ? FFTW_MEASURE : FFTW_ESTIMATE) | FFTW_DESTROY_INPUT;
  fftw_plan_with_nthreads(threads_);
  auto make_plans = [&](unsigned fl) {
    plan_forward_ =
        fftw_plan_many_dft_r2c(3, dims, 3, f, nullptr, 1, int(nr), fh, nullptr, 1, int(nc), fl);
    plan_backward_ =
        fftw_plan_many_dft_c2r(3, dims, 3, fh, nullptr, 1, int(nc), u, nullptr, 1, int(nr), fl);
    if (plan_forward_ && plan_backward_) return true;
    release_plans();
    return false;
  };
  if (!plan_measure) {
    make_plans(flags);
  } else if (!make_plans(flags | FFTW_WISDOM_ONLY)) {
    // Wisdom already in the process (a resumed run imports its own first) wins; otherwise the
    // on-disk cache, and only if that lacks these plans too, FFTW_MEASURE, saved for next time.
    const std::string cache = wisdom_cache_path();
    if (!cache.empty()) import_wisdom(cache);
    if (!make_plans(flags | FFTW_WISDOM_ONLY) && make_plans(flags) && !cache.empty())
      save_wisdom_cache(cache);
  }
  if (!plan_forward_ || !plan_backward_) {
    release();
    throw std::runtime_error("FluidSolver: FFTW planning failed");
  }
  // FFTW_MEASURE scribbles on the buffers while planning: start from rest only afterwards.
  std::fill(u, u + 3 * nr, 0.0);
  std::fill(f, f + 3 * nr, 0.0);
}

FluidSolver::~FluidSolver() { release(); }

void FluidSolver::release_plans() {
  if (plan_forward_) fftw_destroy_plan(as_plan(plan_forward_));
  if (plan_backward_) fftw_destroy_plan(as_plan(plan_backward_));
  plan_forward_ = plan_backward_ = nullptr;
}

void FluidSolver::release() {
  release_plans();
  fftw_free(u_[0]);  // fftw_free(nullptr) is a no-op
  fftw_free(f_[0]);
  fftw_free(fh_[0]);
  u_ = {};
  f_ = {};
  fh_ = {};
}

void FluidSolver::zero_force() {
  const std::ptrdiff_t total = std::ptrdiff_t(3 * grid_.size());
  double* f = f_[0];
#pragma omp parallel for simd num_threads(threads_) schedule(static)
  for (std::ptrdiff_t i = 0; i < total; ++i) f[i] = 0.0;
}

void FluidSolver::step() {
  // 1. r = ρuⁿ/Δt − ρS_h(uⁿ) + fⁿ, in place over the force (MODEL §4)
  detail::accumulate_rhs(grid_, next_.data(), prev_.data(), {u_[0], u_[1], u_[2]}, f_,
                         params_.density / params_.dt, params_.advection ? params_.density : 0.0,
                         threads_);
  finish_step();
}

void FluidSolver::begin_step() {
  // r = ρuⁿ/Δt − ρS_h(uⁿ) over the force array; the caller adds fⁿ (MODEL §4)
  detail::assign_rhs(grid_, next_.data(), prev_.data(), {u_[0], u_[1], u_[2]}, f_,
                     params_.density / params_.dt, params_.advection ? params_.density : 0.0,
                     threads_);
}

void FluidSolver::finish_step() {
  // 2. r̂ for all three components in one plan
  fftw_execute(as_plan(plan_forward_));
  // 3. projection, implicit viscosity and the 1/n³ of the FFT round trip, one pass
  spectral_pass();
  // 4. uⁿ⁺¹ back in real space
  fftw_execute(as_plan(plan_backward_));
}

void FluidSolver::spectral_pass() {
  const int n = grid_.n;
  const double inertia = params_.density / params_.dt;  // ρ/Δt, g Å⁻³ s⁻¹
  const double mu = params_.viscosity;

  // ûⁿ⁺¹ = P(k) r̂ / (ρ/Δt − μL̂(k)) / n³: the unnormalised FFTW round trip multiplies by n³.
  const int nzh = n / 2 + 1;
  const double norm = 1.0 / double(grid_.size());
  const double* gs = grad_symbol_.data();
  const double* ls = lap_symbol_.data();
  double* r0 = reinterpret_cast<double*>(fh_[0]);  // interleaved (re, im)
  double* r1 = reinterpret_cast<double*>(fh_[1]);
  double* r2 = reinterpret_cast<double*>(fh_[2]);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double gx = gs[i], gy = gs[j];
      const double gxy2 = gx * gx + gy * gy;
      const double lxy = ls[i] + ls[j];
      const std::size_t o = 2 * (std::size_t(i) * n + j) * nzh;
#pragma omp simd
      for (int k = 0; k < nzh; ++k) {
        const double gz = gs[k];
        const double g2 = gxy2 + gz * gz;
        // Where ĝ = 0 (k_j ∈ {0, n/2} for all j) D_h and G_h vanish: no pressure, P = I. Then
        // ĝ·r̂ = 0 exactly and any finite 1/|ĝ|² will do. Adding DBL_MIN instead of branching
        // keeps the loop vectorised (a branch or max() does not) and leaves every nonzero |ĝ|²
        // (≥ sin²(2π/n)/h², Å⁻²) bit-for-bit unchanged.
        const double ig2 = 1.0 / (g2 + DBL_MIN);
        const double scale = norm / (inertia + mu * (lxy + ls[k]));
        const std::size_t q = o + 2 * std::size_t(k);
        const double a0 = r0[q], b0 = r0[q + 1];
        const double a1 = r1[q], b1 = r1[q + 1];
        const double a2 = r2[q], b2 = r2[q + 1];
        const double pa = (gx * a0 + gy * a1 + gz * a2) * ig2;  // ĝ·r̂ / |ĝ|²
        const double pb = (gx * b0 + gy * b1 + gz * b2) * ig2;
        r0[q] = scale * (a0 - gx * pa);
        r0[q + 1] = scale * (b0 - gx * pb);
        r1[q] = scale * (a1 - gy * pa);
        r1[q + 1] = scale * (b1 - gy * pb);
        r2[q] = scale * (a2 - gz * pa);
        r2[q + 1] = scale * (b2 - gz * pb);
      }
    }
  }
}

void FluidSolver::run_spectral_only() { spectral_pass(); }

void FluidSolver::run_forward_fft_only() { fftw_execute(as_plan(plan_forward_)); }
void FluidSolver::run_backward_fft_only() { fftw_execute(as_plan(plan_backward_)); }

void FluidSolver::run_ffts_only() {
  fftw_execute(as_plan(plan_forward_));
  fftw_execute(as_plan(plan_backward_));
}

double FluidSolver::kinetic_energy() const {
  // Partial sums over a fixed number of blocks, added in block order: bit-for-bit the same for
  // any thread count and any thread timing. (An OpenMP reduction(+) adds the threads' partial
  // sums in the order the threads finish, which changes the last bits from run to run with more
  // than two threads; a resumed run must reproduce every bit of the uninterrupted one.)
  constexpr int kBlocks = 64;
  const std::ptrdiff_t total = std::ptrdiff_t(3 * grid_.size());
  const double* u = u_[0];
  double part[kBlocks];
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int b = 0; b < kBlocks; ++b) {
    const std::ptrdiff_t lo = total * b / kBlocks, hi = total * (b + 1) / kBlocks;
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
