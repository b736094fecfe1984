#include "fluid/distributed_fluid.hpp"

#include <stdexcept>
#include <string>

#ifdef IBROD_MPI
#include <fftw3-mpi.h>
#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <mutex>
#include <new>

#include "fluid/advection.hpp"
#include "fluid/fftw_wisdom.hpp"
#include "fluid/spectral.hpp"
#endif

namespace ibrod::fluid {

#ifndef IBROD_MPI

bool distributed_available() { return false; }

DistributedFluid::DistributedFluid(const GridSpec&, const FluidParams&, int, bool) {
  throw std::invalid_argument("DistributedFluid: this ibrod was built without MPI");
}
DistributedFluid::~DistributedFluid() = default;
// No object can exist without MPI (the constructor throws): the rest is never called, and is
// here only so that callers link.
void DistributedFluid::begin_step() {}
void DistributedFluid::finish_step() {}
void DistributedFluid::exchange_halos() {}
double DistributedFluid::kinetic_energy() const { return 0.0; }
double DistributedFluid::max_divergence() const { return 0.0; }
void DistributedFluid::gather_velocity(std::vector<double>&) const {}
void DistributedFluid::scatter_velocity(std::array<const double*, 3>) {}
void DistributedFluid::sum_over_ranks(double*, std::size_t) {}

#else

namespace {

fftw_plan as_plan(void* p) { return static_cast<fftw_plan>(p); }

// Once per process, after MPI_Init: threads first, then the MPI layer (FFTW's documented order).
void init_fftw_mpi() {
  static std::once_flag once;
  std::call_once(once, [] {
    init_fftw_threads();
    fftw_mpi_init();
  });
}

}  // namespace

bool distributed_available() { return true; }

DistributedFluid::DistributedFluid(const GridSpec& grid, const FluidParams& params, int threads,
                                   bool plan_measure)
    : grid_(grid), params_(params) {
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
  // The same checks as FluidSolver; every rank sees the same arguments, so all throw alike.
  detail::check_fluid_args("DistributedFluid", grid, params, threads);
  if (params.thermal_kT > 0)
    throw std::invalid_argument(
        "DistributedFluid: thermal noise (solvent.thermal) runs on one process only");
  if (grid.n % ranks_ != 0)
    throw std::invalid_argument("DistributedFluid: the grid of n = " + std::to_string(grid.n) +
                                " x-planes cannot be split evenly over " + std::to_string(ranks_) +
                                " MPI ranks: the rank count must divide n");
  threads_ = threads > 0 ? threads : std::max(1, omp_get_max_threads());

  const int n = grid_.n;
  const double h = grid_.h();
  const int nzh = n / 2 + 1;
  plane_ = std::size_t(n) * n;
  detail::make_neighbour_tables(n, next_, prev_);
  detail::make_spectral_symbols(n, h, grad_symbol_, lap_symbol_);

  init_fftw_mpi();
  // Complex dimensions n × n × (n/2+1), 3 interleaved components; x distributed in real space,
  // y in the transposed spectrum. K | n makes FFTW's default blocks exactly n/K.
  const ptrdiff_t cdims[3] = {n, n, nzh};
  ptrdiff_t ln0 = 0, l0s = 0, ln1 = 0, l1s = 0;
  ptrdiff_t alloc = fftw_mpi_local_size_many_transposed(3, cdims, 3, FFTW_MPI_DEFAULT_BLOCK,
                                                        FFTW_MPI_DEFAULT_BLOCK, MPI_COMM_WORLD,
                                                        &ln0, &l0s, &ln1, &l1s);
  if (ln0 != n / ranks_ || l0s != ptrdiff_t(rank_) * (n / ranks_) || ln1 != n / ranks_ ||
      l1s != ptrdiff_t(rank_) * (n / ranks_))
    throw std::runtime_error("DistributedFluid: unexpected FFTW MPI distribution");
  x0_ = int(l0s);
  nx_ = int(ln0);
  y0_ = int(l1s);
  ny_ = int(ln1);
  alloc = std::max<ptrdiff_t>(alloc, 3 * ptrdiff_t(nx_) * n * nzh);

  buf_ = fftw_alloc_real(std::size_t(2 * alloc));
  for (int c = 0; c < 3; ++c) {
    u_[c] = fftw_alloc_real(std::size_t(nx_ + 2) * plane_);
    f_[c] = fftw_alloc_real(std::size_t(nx_) * plane_);
  }
  if (!buf_ || !u_[0] || !u_[1] || !u_[2] || !f_[0] || !f_[1] || !f_[2]) {
    release();
    throw std::bad_alloc();
  }

  const ptrdiff_t rdims[3] = {n, n, n};
  auto* spec = reinterpret_cast<fftw_complex*>(buf_);
  const unsigned flags = plan_measure ? FFTW_MEASURE : FFTW_ESTIMATE;
  const std::string cache = plan_measure && rank_ == 0 ? wisdom_cache_path() : std::string();
  if (plan_measure) {
    // rank 0's wisdom (the run's own on resume, --fftw-wisdom, the cache) for everybody
    if (!cache.empty()) import_wisdom(cache);
    fftw_mpi_broadcast_wisdom(MPI_COMM_WORLD);
  }
  fftw_plan_with_nthreads(threads_);
  plan_forward_ =
      fftw_mpi_plan_many_dft_r2c(3, rdims, 3, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, buf_,
                                 spec, MPI_COMM_WORLD, flags | FFTW_MPI_TRANSPOSED_OUT);
  plan_backward_ =
      fftw_mpi_plan_many_dft_c2r(3, rdims, 3, FFTW_MPI_DEFAULT_BLOCK, FFTW_MPI_DEFAULT_BLOCK, spec,
                                 buf_, MPI_COMM_WORLD, flags | FFTW_MPI_TRANSPOSED_IN);
  int ok = plan_forward_ && plan_backward_ ? 1 : 0, all_ok = 0;
  MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (!all_ok) {
    release();
    throw std::runtime_error("DistributedFluid: FFTW MPI planning failed");
  }
  if (plan_measure) {
    fftw_mpi_gather_wisdom(MPI_COMM_WORLD);  // rank 0 exports it (run driver, cache)
    if (!cache.empty()) save_wisdom_cache(cache);
  }
  // FFTW_MEASURE scribbles on the buffer: start from rest only afterwards
  std::fill(buf_, buf_ + 2 * alloc, 0.0);
  for (int c = 0; c < 3; ++c) {
    std::fill(u_[c], u_[c] + std::size_t(nx_ + 2) * plane_, 0.0);
    std::fill(f_[c], f_[c] + std::size_t(nx_) * plane_, 0.0);
  }
}

DistributedFluid::~DistributedFluid() { release(); }

void DistributedFluid::release() {
  if (plan_forward_) fftw_destroy_plan(as_plan(plan_forward_));
  if (plan_backward_) fftw_destroy_plan(as_plan(plan_backward_));
  plan_forward_ = plan_backward_ = nullptr;
  fftw_free(buf_);
  buf_ = nullptr;
  for (int c = 0; c < 3; ++c) {
    fftw_free(u_[c]);
    fftw_free(f_[c]);
  }
  u_ = {};
  f_ = {};
}

void DistributedFluid::exchange_halos() {
  // own first plane → the left neighbour's upper halo; own last plane → the right neighbour's
  // lower halo (periodic; with 2 ranks both neighbours are the same rank, told apart by tag)
  const int left = (rank_ + ranks_ - 1) % ranks_, right = (rank_ + 1) % ranks_;
  const int count = int(plane_);
  MPI_Request req[12];
  int q = 0;
  for (int c = 0; c < 3; ++c) {
    double* u = u_[c];
    MPI_Irecv(u + std::size_t(nx_ + 1) * plane_, count, MPI_DOUBLE, right, 2 * c, MPI_COMM_WORLD,
              &req[q++]);
    MPI_Irecv(u, count, MPI_DOUBLE, left, 2 * c + 1, MPI_COMM_WORLD, &req[q++]);
    MPI_Isend(u + plane_, count, MPI_DOUBLE, left, 2 * c, MPI_COMM_WORLD, &req[q++]);
    MPI_Isend(u + std::size_t(nx_) * plane_, count, MPI_DOUBLE, right, 2 * c + 1, MPI_COMM_WORLD,
              &req[q++]);
  }
  MPI_Waitall(q, req, MPI_STATUSES_IGNORE);
}

void DistributedFluid::begin_step() {
  // r = ρuⁿ/Δt − ρS_h(uⁿ) over the own planes (MODEL §4); plane p of u_ is x = x0 − 1 + p
  const int n = grid_.n;
  const double h = grid_.h();
  const double a = params_.density / params_.dt;
  const double b = params_.advection ? params_.density : 0.0;
  const std::size_t pl = plane_;
  auto at = [&](int p) {
    return std::array<const double*, 3>{u_[0] + p * pl, u_[1] + p * pl, u_[2] + p * pl};
  };
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int i = 0; i < nx_; ++i) {
    std::array<double*, 3> r{f_[0] + i * pl, f_[1] + i * pl, f_[2] + i * pl};
    detail::rhs_plane(n, h, next_.data(), prev_.data(), at(i + 1), at(i + 2), at(i), r, a, b, true);
  }
}

void DistributedFluid::finish_step() {
  const int n = grid_.n;
  const std::size_t nz = std::size_t(n), row2 = 2 * std::size_t(n / 2 + 1);
  const int rows = nx_ * n;
  // r into FFTW's layout: rows of 2(n/2+1) padded z, 3 components interleaved
  {
    const double *f0 = f_[0], *f1 = f_[1], *f2 = f_[2];
    double* b = buf_;
#pragma omp parallel for num_threads(threads_) schedule(static)
    for (int r = 0; r < rows; ++r) {
      const std::size_t s = std::size_t(r) * nz, d = std::size_t(r) * row2 * 3;
      for (std::size_t k = 0; k < nz; ++k) {
        b[d + 3 * k] = f0[s + k];
        b[d + 3 * k + 1] = f1[s + k];
        b[d + 3 * k + 2] = f2[s + k];
      }
    }
  }
  fftw_execute(as_plan(plan_forward_));
  spectral_pass();
  fftw_execute(as_plan(plan_backward_));
  {
    double *u0 = u_[0] + plane_, *u1 = u_[1] + plane_, *u2 = u_[2] + plane_;
    const double* b = buf_;
#pragma omp parallel for num_threads(threads_) schedule(static)
    for (int r = 0; r < rows; ++r) {
      const std::size_t d = std::size_t(r) * nz, s = std::size_t(r) * row2 * 3;
      for (std::size_t k = 0; k < nz; ++k) {
        u0[d + k] = b[s + 3 * k];
        u1[d + k] = b[s + 3 * k + 1];
        u2[d + k] = b[s + 3 * k + 2];
      }
    }
  }
  exchange_halos();
}

void DistributedFluid::spectral_pass() {
  // the per-wavenumber solve of FluidSolver (solve_row, navier_stokes.cpp) on the transposed,
  // interleaved layout: complex (jl, i, k, c) at
  // ((jl n + i)(n/2+1) + k) 3 + c, global y index y0 + jl, x index i, z index k.
  const int n = grid_.n;
  const int nzh = n / 2 + 1;
  const double inertia = params_.density / params_.dt;  // ρ/Δt
  const double mu = params_.viscosity;
  const double norm = 1.0 / double(grid_.size());
  const double* gs = grad_symbol_.data();
  const double* ls = lap_symbol_.data();
  double* r = buf_;
  const int lines = ny_ * n;
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (int line = 0; line < lines; ++line) {
    const int j = y0_ + line / n, i = line % n;
    const double gx = gs[i], gy = gs[j];
    const double gxy2 = gx * gx + gy * gy;
    const double lxy = ls[i] + ls[j];
    double* rl = r + 6 * std::size_t(line) * nzh;
#pragma omp simd
    for (int k = 0; k < nzh; ++k) {
      const double gz = gs[k];
      const double g2 = gxy2 + gz * gz;
      // ĝ = 0 (every k_j ∈ {0, n/2}): no pressure, ĝ·r̂ = 0 exactly; DBL_MIN keeps every
      // nonzero |ĝ|² bit-for-bit and the loop branch-free (see solve_row in navier_stokes.cpp)
      const double ig2 = 1.0 / (g2 + DBL_MIN);
      const double scale = norm / (inertia + mu * (lxy + ls[k]));
      double* q = rl + 6 * std::size_t(k);
      const double a0 = q[0], b0 = q[1], a1 = q[2], b1 = q[3], a2 = q[4], b2 = q[5];
      const double pa = (gx * a0 + gy * a1 + gz * a2) * ig2;
      const double pb = (gx * b0 + gy * b1 + gz * b2) * ig2;
      q[0] = scale * (a0 - gx * pa);
      q[1] = scale * (b0 - gx * pb);
      q[2] = scale * (a1 - gy * pa);
      q[3] = scale * (b1 - gy * pb);
      q[4] = scale * (a2 - gz * pa);
      q[5] = scale * (b2 - gz * pb);
    }
  }
}

double DistributedFluid::kinetic_energy() const {
  // fixed blocks per component, added in order (thread-count independent, as FluidSolver)
  constexpr int kBlocks = 64;
  const std::ptrdiff_t total = std::ptrdiff_t(nx_) * std::ptrdiff_t(plane_);
  double part[3][kBlocks];
  for (int c = 0; c < 3; ++c) {
    const double* u = velocity(c);
#pragma omp parallel for num_threads(threads_) schedule(static)
    for (int b = 0; b < kBlocks; ++b) {
      const std::ptrdiff_t lo = total * b / kBlocks, hi = total * (b + 1) / kBlocks;
      double s = 0.0;
#pragma omp simd reduction(+ : s)
      for (std::ptrdiff_t i = lo; i < hi; ++i) s += u[i] * u[i];
      part[c][b] = s;
    }
  }
  double local = 0.0;
  for (int c = 0; c < 3; ++c)
    for (int b = 0; b < kBlocks; ++b) local += part[c][b];
  std::vector<double> all(std::size_t(ranks_), 0.0);
  MPI_Allgather(&local, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, MPI_COMM_WORLD);
  double sum = 0.0;
  for (double v : all) sum += v;  // rank order, on every rank
  const double h = grid_.h();
  return 0.5 * params_.density * sum * h * h * h;
}

double DistributedFluid::max_divergence() const {
  const int n = grid_.n;
  const std::size_t nz = std::size_t(n), pl = plane_;
  const double inv2h = 0.5 / grid_.h();
  const int* next = next_.data();
  const int* prev = prev_.data();
  const double *ux = u_[0], *uy = u_[1], *uz = u_[2];
  double dmax = 0.0;
#pragma omp parallel for num_threads(threads_) schedule(static) reduction(max : dmax)
  for (int p = 1; p <= nx_; ++p) {
    for (int j = 0; j < n; ++j) {
      const std::size_t oc = p * pl + std::size_t(j) * nz;
      const std::size_t oxp = oc + pl, oxm = oc - pl;
      const std::size_t oyp = p * pl + std::size_t(next[j]) * nz;
      const std::size_t oym = p * pl + std::size_t(prev[j]) * nz;
      for (int k = 0; k < n; ++k) {
        const double d = (ux[oxp + k] - ux[oxm + k]) + (uy[oyp + k] - uy[oym + k]) +
                         (uz[oc + next[k]] - uz[oc + prev[k]]);
        dmax = std::max(dmax, std::abs(d) * inv2h);
      }
    }
  }
  double all = 0.0;
  MPI_Allreduce(&dmax, &all, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return all;
}

void DistributedFluid::gather_velocity(std::vector<double>& full) const {
  const std::size_t n3 = grid_.size();
  const int count = int(std::size_t(nx_) * plane_);
  if (rank_ == 0) full.resize(3 * n3);
  for (int c = 0; c < 3; ++c)  // rank order is x order: the slabs land in place
    MPI_Gather(velocity(c), count, MPI_DOUBLE, rank_ == 0 ? full.data() + c * n3 : nullptr, count,
               MPI_DOUBLE, 0, MPI_COMM_WORLD);
}

void DistributedFluid::scatter_velocity(std::array<const double*, 3> full) {
  const std::size_t own = std::size_t(nx_) * plane_;
  for (int c = 0; c < 3; ++c) std::copy_n(full[c] + std::size_t(x0_) * plane_, own, velocity(c));
  exchange_halos();
}

void DistributedFluid::sum_over_ranks(double* data, std::size_t count) {
  if (gathered_.size() < count * std::size_t(ranks_)) gathered_.resize(count * ranks_);
  MPI_Allgather(data, int(count), MPI_DOUBLE, gathered_.data(), int(count), MPI_DOUBLE,
                MPI_COMM_WORLD);
  for (std::size_t i = 0; i < count; ++i) {
    double s = gathered_[i];
    for (int r = 1; r < ranks_; ++r) s += gathered_[std::size_t(r) * count + i];
    data[i] = s;
  }
}

#endif  // IBROD_MPI

}  // namespace ibrod::fluid
