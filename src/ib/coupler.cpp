// Spreading and interpolation over the whole grid, one point at a time (ib/coupler.hpp); the
// separable stencil w, g of one point is built by detail::PointStencil (ib/kernel.hpp).
#include "ib/coupler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace ibrod::ib {

using detail::check_positions;
using detail::check_size;
using detail::kParallelMinPoints;
using detail::locate;
using detail::PointStencil;
using detail::spread_row;

namespace {

// f += F w + ½ g × T over the stencil of one point. With w = p₁₂φ₃ and
// g = (dφ₁φ₂ φ₃, φ₁dφ₂ φ₃, p₁₂ dφ₃), p₁₂ = φ₁φ₂, each row is a combination of φ₃ and dφ₃ whose
// coefficients are computed once per row:
//   x: (F_x p₁₂ + φ₁dφ₂ T_z/2) φ₃ − (p₁₂ T_y/2) dφ₃
//   y: (F_y p₁₂ − dφ₁φ₂ T_z/2) φ₃ + (p₁₂ T_x/2) dφ₃
//   z: (F_z p₁₂ + dφ₁φ₂ T_y/2 − φ₁dφ₂ T_x/2) φ₃
// Slab: only the x-planes [x0, x0 + nx) are present, plane i at local index i − x0 (XSlab);
// Slab = false is the whole grid (x0, nx unused).
template <bool Slab>
void spread_point(const PointStencil& st, const Vec3& F, const Vec3& T, const GridSpec& grid,
                  const std::array<double*, 3>& f, int x0, int nx) {
  const int S = st.S;
  const std::size_t n = std::size_t(grid.n);
  const double hTx = 0.5 * T[0], hTy = 0.5 * T[1], hTz = 0.5 * T[2];
  // the z range of the stencil as at most two contiguous pieces of a grid row (periodic wrap)
  const int z0 = st.idx[2][0];
  const int len1 = std::min(S, grid.n - z0);
  for (int a = 0; a < S; ++a) {
    int xi = st.idx[0][a];
    if constexpr (Slab) {
      xi -= x0;
      if (unsigned(xi) >= unsigned(nx)) continue;  // not on this slab
    }
    const double p1 = st.phi[0][a], d1 = st.dphi[0][a];
    for (int b = 0; b < S; ++b) {
      const double p12 = p1 * st.phi[1][b];
      const double d1p2 = d1 * st.phi[1][b];
      const double p1d2 = p1 * st.dphi[1][b];
      const double Ax = F[0] * p12 + p1d2 * hTz, Bx = -p12 * hTy;
      const double Ay = F[1] * p12 - d1p2 * hTz, By = p12 * hTx;
      const double Az = F[2] * p12 + d1p2 * hTy - p1d2 * hTx;
      const std::size_t row = (std::size_t(xi) * n + std::size_t(st.idx[1][b])) * n;
      spread_row(f[0] + row + z0, f[1] + row + z0, f[2] + row + z0, st.phi[2], st.dphi[2], len1, Ax,
                 Ay, Az, Bx, By);
      if (len1 < S) {
        spread_row(f[0] + row, f[1] + row, f[2] + row, st.phi[2] + len1, st.dphi[2] + len1,
                   S - len1, Ax, Ay, Az, Bx, By);
      }
    }
  }
}

// Row sums for interpolation: s = (Σ u_x φ₃, Σ u_y φ₃, Σ u_z φ₃, Σ u_x dφ₃, Σ u_y dφ₃).
inline void interpolate_row(const double* __restrict ux, const double* __restrict uy,
                            const double* __restrict uz, const double* __restrict p3,
                            const double* __restrict d3, int len, double s[5]) {
  for (int c = 0; c < len; ++c) {
    s[0] += ux[c] * p3[c];
    s[1] += uy[c] * p3[c];
    s[2] += uz[c] * p3[c];
    s[3] += ux[c] * d3[c];
    s[4] += uy[c] * d3[c];
  }
}

// Σ u w and Σ u × g over the stencil of one point (the sums of the file comment without h³),
// by row sums: Σ_row u w = p₁₂ (s₀, s₁, s₂) and
//   Σ_row u × g = (p₁₂ s₄ − φ₁dφ₂ s₂,  dφ₁φ₂ s₂ − p₁₂ s₃,  φ₁dφ₂ s₀ − dφ₁φ₂ s₁).
template <bool Slab>
void interpolate_point(const PointStencil& st, const GridSpec& grid,
                       const std::array<const double*, 3>& u, Vec3& uw, Vec3& uxg, int x0, int nx) {
  const int S = st.S;
  const std::size_t n = std::size_t(grid.n);
  const int z0 = st.idx[2][0];
  const int len1 = std::min(S, grid.n - z0);
  // plain scalars, not Eigen temporaries: those went through the stack and stalled on
  // store-to-load forwarding (a third of the time in a profile)
  double wx = 0, wy = 0, wz = 0, gx = 0, gy = 0, gz = 0;
  for (int a = 0; a < S; ++a) {
    int xi = st.idx[0][a];
    if constexpr (Slab) {
      xi -= x0;
      if (unsigned(xi) >= unsigned(nx)) continue;  // not on this slab
    }
    const double p1 = st.phi[0][a], d1 = st.dphi[0][a];
    for (int b = 0; b < S; ++b) {
      const std::size_t row = (std::size_t(xi) * n + std::size_t(st.idx[1][b])) * n;
      double s[5] = {0, 0, 0, 0, 0};
      interpolate_row(u[0] + row + z0, u[1] + row + z0, u[2] + row + z0, st.phi[2], st.dphi[2],
                      len1, s);
      if (len1 < S) {
        interpolate_row(u[0] + row, u[1] + row, u[2] + row, st.phi[2] + len1, st.dphi[2] + len1,
                        S - len1, s);
      }
      const double p12 = p1 * st.phi[1][b];
      const double d1p2 = d1 * st.phi[1][b];
      const double p1d2 = p1 * st.dphi[1][b];
      wx += p12 * s[0];
      wy += p12 * s[1];
      wz += p12 * s[2];
      gx += p12 * s[4] - p1d2 * s[2];
      gy += d1p2 * s[2] - p12 * s[3];
      gz += p1d2 * s[0] - d1p2 * s[1];
    }
  }
  uw = Vec3(wx, wy, wz);
  uxg = Vec3(gx, gy, gz);
}

}  // namespace

Coupler::Coupler(const GridSpec& grid, int kernel_width)
    : Coupler(grid, kernel_width, XSlab{0, grid.n}) {}

Coupler::Coupler(const GridSpec& grid, int kernel_width, XSlab slab)
    : grid_(grid), m_(kernel_width), slab_(slab) {
  if (m_ < 1 || m_ > kMaxKernelWidth) {
    throw std::invalid_argument("ib::Coupler: kernel width m = " + std::to_string(m_) +
                                " (c = m h) must be an integer in [1, " +
                                std::to_string(kMaxKernelWidth) + "]");
  }
  if (!(grid_.L > 0.0) || !std::isfinite(grid_.L)) {
    throw std::invalid_argument("ib::Coupler: box edge L = " + std::to_string(grid_.L) +
                                " Å must be positive");
  }
  if (stencil() > grid_.n) {
    throw std::invalid_argument(
        "ib::Coupler: the stencil of kernel width m = " + std::to_string(m_) + " spans 4m + 2 = " +
        std::to_string(stencil()) + " grid points, more than n = " + std::to_string(grid_.n));
  }
  if (slab_.begin < 0 || slab_.begin >= grid_.n || slab_.count < 1 || slab_.count > grid_.n) {
    throw std::invalid_argument("ib::Coupler: x slab [" + std::to_string(slab_.begin) + ", " +
                                std::to_string(slab_.begin) + " + " + std::to_string(slab_.count) +
                                ") is not within a grid of n = " + std::to_string(grid_.n) +
                                " planes");
  }
  whole_ = slab_.begin == 0 && slab_.count == grid_.n;
  // Slabs at least S wide, so a stencil starting in slab b ends in slab b or b + 1; an even count
  // (or one) so that slabs of equal parity never touch, also across the periodic seam.
  const int n = grid_.n;
  nslabs_ = n / stencil();
  if (nslabs_ > 1 && nslabs_ % 2 == 1) --nslabs_;
  slab_of_.assign(std::size_t(n), 0);
  for (int b = 0; b < nslabs_; ++b) {
    const int begin = int(std::int64_t(b) * n / nslabs_);
    const int end = int(std::int64_t(b + 1) * n / nslabs_);
    for (int i = begin; i < end; ++i) slab_of_[std::size_t(i)] = b;
  }
}

bool Coupler::touches_slab(int first) const {
  // the stencil covers first … first + S − 1 (mod n), the slab begin … begin + count − 1
  const int n = grid_.n;
  const int d1 = (slab_.begin - first + n) % n;  // slab start seen from the stencil start
  const int d2 = (first - slab_.begin + n) % n;  // stencil start seen from the slab start
  return d1 < stencil() || d2 < slab_.count;
}

void Coupler::spread(std::span<const Vec3> X, std::span<const Vec3> F, std::span<const Vec3> T,
                     std::array<double*, 3> f) const {
  check_size("F", F.size(), X.size());
  if (!T.empty()) check_size("T", T.size(), X.size());
  check_positions(X, grid_.h());
  const bool torques = !T.empty();
  const bool parallel = X.size() >= kParallelMinPoints && nslabs_ > 1;
  const std::int64_t npoints = std::int64_t(X.size());
  const double h = grid_.h();
  // Two passes (even slabs, then odd); within a pass each thread owns whole slabs and scans all
  // points for those whose stencil starts in its slab. The scan costs one floor per point and
  // slab, negligible next to the S³ stencil, and needs no scratch memory.
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
    for (int b = parity; b < nslabs_; b += 2) {
      for (std::int64_t k = 0; k < npoints; ++k) {
        const int first = locate(X[k][0], h, grid_.n, m_).first;
        if (slab_of_[std::size_t(first)] != b) continue;
        if (whole_) {
          const PointStencil st(X[k], grid_, m_);
          spread_point<false>(st, F[k], torques ? T[k] : Vec3::Zero().eval(), grid_, f, 0, 0);
        } else if (touches_slab(first)) {
          // the same writes as the whole grid's, less those off the slab: race-free alike
          const PointStencil st(X[k], grid_, m_);
          spread_point<true>(st, F[k], torques ? T[k] : Vec3::Zero().eval(), grid_, f, slab_.begin,
                             slab_.count);
        }
      }
    }
  }
}

void Coupler::interpolate(std::span<const Vec3> X, std::array<const double*, 3> u,
                          std::span<Vec3> U, std::span<Vec3> W) const {
  check_size("U", U.size(), X.size());
  if (!W.empty()) check_size("W", W.size(), X.size());
  check_positions(X, grid_.h());
  const bool rotation = !W.empty();
  const std::int64_t npoints = std::int64_t(X.size());
  const double h = grid_.h();
  const double h3 = h * h * h;
#pragma omp parallel for schedule(static) if (X.size() >= kParallelMinPoints)
  for (std::int64_t k = 0; k < npoints; ++k) {
    Vec3 uw, uxg;
    if (whole_) {
      const PointStencil st(X[k], grid_, m_);
      interpolate_point<false>(st, grid_, u, uw, uxg, 0, 0);
    } else if (touches_slab(locate(X[k][0], h, grid_.n, m_).first)) {
      const PointStencil st(X[k], grid_, m_);
      interpolate_point<true>(st, grid_, u, uw, uxg, slab_.begin, slab_.count);
    } else {
      uw.setZero();  // no stencil point on this slab
      uxg.setZero();
    }
    U[std::size_t(k)] = uw * h3;  // MODEL §4: U = Σ u δ_c h³
    // MODEL §4: W = ½ Σ (curl_h u) δ_c h³ = ½ Σ u × ∇_h δ_c h³ (summation by parts)
    if (rotation) W[std::size_t(k)] = uxg * (0.5 * h3);
  }
}

}  // namespace ibrod::ib
