// Generalized IB coupling (MODEL §3 (2.9–2.16), §4): Peskin's 4-point kernel, spreading of point
// forces and torques, interpolation of velocity and angular velocity.
//
// The kernel is separable, so for one point X everything is built from three 1-D arrays per
// dimension d over the S = 4m + 2 grid indices i = i₀ − 2m … i₀ + 2m + 1 (i₀ = ⌊X_d/h⌋; the
// support |i h − X_d| < 2c plus one zero halo index each side):
//   φ_d(i)  = φ((i h − X_d)/c) / c                       Å⁻¹
//   dφ_d(i) = (φ_d(i+1) − φ_d(i−1)) / (2h)               Å⁻²  (central difference, zero halo)
// w(x) = φ₁φ₂φ₃ = δ_c(x − X) and g(x) = (dφ₁φ₂φ₃, φ₁dφ₂φ₃, φ₁φ₂dφ₃) = ∇_h w, the central-difference
// gradient. For a constant vector T, curl_h(T w) = g × T exactly, so
//   spreading:     f(x) += F w(x) + ½ g(x) × T                       MODEL §4
//   interpolation: U = Σ_x u w h³,  W = ½ Σ_x (curl_h u) w h³ = ½ Σ_x u × g h³
// The last equality is summation by parts of the symmetric periodic curl_h (Σ (curl a)·b =
// Σ a·(curl b)) together with (g × T)·u = T·(u × g); it makes spreading and interpolation exactly
// adjoint: Σ_x f·u h³ = Σ_k (F_k·U_k + T_k·W_k).
#include "ib/coupling.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "core/error.hpp"

namespace ibrod::ib {

double phi4(double r) {
  // MODEL (2.14). The radicands are 2 − (2|r| − 1)² and 2 − (2|r| − 3)², both in [1, 2] on their
  // branches, so no clamping is needed.
  const double a = std::abs(r);
  if (a <= 1.0) return (3.0 - 2.0 * a + std::sqrt(1.0 + 4.0 * a - 4.0 * a * a)) * 0.125;
  if (a < 2.0) return (5.0 - 2.0 * a - std::sqrt(-7.0 + 12.0 * a - 4.0 * a * a)) * 0.125;
  return 0.0;
}

double delta(const Vec3& x, double c) {
  // MODEL (2.14), Å⁻³
  return phi4(x[0] / c) * phi4(x[1] / c) * phi4(x[2] / c) / (c * c * c);
}

namespace {

constexpr int kMaxStencil = 4 * Coupler::kMaxKernelWidth + 2;

// Points with more coordinates than this (in grid units) are rejected: ⌊s⌋ must fit an int64 and
// s − ⌊s⌋ must keep a useful number of bits.
constexpr double kMaxGridCoordinate = 1099511627776.0;  // 2⁴⁰

// Parallel regions cost a few µs; below this many points the loops run serially (same result).
constexpr std::size_t kParallelMinPoints = 64;

// Where one coordinate falls: the first stencil index, wrapped into [0, n), and the fractional
// part of X_d/h.
struct Locus {
  int first;    ///< wrap(i₀ − 2m)
  double frac;  ///< X_d/h − i₀, in [0, 1] (1 only by round-off for tiny negative X_d/h)
};

inline Locus locate(double x, double h, int n, int m) {
  const double s = x / h;  // grid units
  const double fl = std::floor(s);
  // Exact (both are multiples of ulp(s)), except that a tiny negative s may round up to 1.
  // Working with the fraction instead of x − i h keeps the kernel arguments accurate for
  // unwrapped positions far from the origin.
  const double frac = s - fl;
  const std::int64_t i = static_cast<std::int64_t>(fl) - 2 * m;
  std::int64_t r = i % n;
  if (r < 0) r += n;
  return {static_cast<int>(r), frac};
}

// The separable weights of one point (see the file comment). frac = 1 is harmless: it gives the
// same weights as i₀ + 1 with frac = 0, because φ vanishes at |r| = 2.
struct PointStencil {
  int S;
  int idx[3][kMaxStencil];      // wrapped grid index of stencil entry q
  double phi[3][kMaxStencil];   // φ_d, Å⁻¹
  double dphi[3][kMaxStencil];  // dφ_d, Å⁻²

  PointStencil(const Vec3& X, const GridSpec& grid, int m) : S(4 * m + 2) {
    const int n = grid.n;
    const double h = grid.h();
    const double inv_c = 1.0 / (m * h);
    const double half_inv_h = 0.5 / h;
    for (int d = 0; d < 3; ++d) {
      const Locus loc = locate(X[d], h, n, m);
      int i = loc.first;
      for (int q = 0; q < S; ++q) {
        idx[d][q] = i;
        if (++i == n) i = 0;
        // (i h − X_d)/c with i = i₀ − 2m + q. Divided, not multiplied by 1/m, so that the halo
        // arguments are exactly |r| ≥ 2 and the halo weights exactly zero.
        phi[d][q] = phi4((q - 2 * m - loc.frac) / m) * inv_c;
      }
      for (int q = 0; q < S; ++q) {
        const double up = q + 1 < S ? phi[d][q + 1] : 0.0;
        const double down = q > 0 ? phi[d][q - 1] : 0.0;
        dphi[d][q] = (up - down) * half_inv_h;
      }
    }
  }
};

void check_positions(std::span<const Vec3> X, double h) {
  const double limit = kMaxGridCoordinate * h;
  for (std::size_t k = 0; k < X.size(); ++k) {
    // written so that NaN fails too
    if (!(std::abs(X[k][0]) <= limit && std::abs(X[k][1]) <= limit &&
          std::abs(X[k][2]) <= limit)) {
      throw RunError("ib::Coupler: point " + std::to_string(k) +
                     " has a non-finite or out-of-range position (" + std::to_string(X[k][0]) +
                     ", " + std::to_string(X[k][1]) + ", " + std::to_string(X[k][2]) + ") Å");
    }
  }
}

void check_size(const char* what, std::size_t got, std::size_t want) {
  if (got != want) {
    throw std::invalid_argument(std::string("ib::Coupler: ") + what + " has " +
                                std::to_string(got) + " entries, positions have " +
                                std::to_string(want));
  }
}

// One row of the stencil (fixed x and y index; z runs over a contiguous piece of the grid row):
// f_d[c] += A_d φ₃[c] + B_d dφ₃[c]. restrict: the three components are separate arrays.
inline void spread_row(double* __restrict fx, double* __restrict fy, double* __restrict fz,
                       const double* __restrict p3, const double* __restrict d3, int len,
                       double Ax, double Ay, double Az, double Bx, double By) {
  for (int c = 0; c < len; ++c) {
    fx[c] += Ax * p3[c] + Bx * d3[c];
    fy[c] += Ay * p3[c] + By * d3[c];
    fz[c] += Az * p3[c];
  }
}

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
      spread_row(f[0] + row + z0, f[1] + row + z0, f[2] + row + z0, st.phi[2], st.dphi[2], len1,
                 Ax, Ay, Az, Bx, By);
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
                       const std::array<const double*, 3>& u, Vec3& uw, Vec3& uxg, int x0,
                       int nx) {
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
    throw std::invalid_argument("ib::Coupler: the stencil of kernel width m = " +
                                std::to_string(m_) + " spans 4m + 2 = " +
                                std::to_string(stencil()) + " grid points, more than n = " +
                                std::to_string(grid_.n));
  }
  if (slab_.begin < 0 || slab_.begin >= grid_.n || slab_.count < 1 || slab_.count > grid_.n) {
    throw std::invalid_argument("ib::Coupler: x slab [" + std::to_string(slab_.begin) + ", " +
                                std::to_string(slab_.begin) + " + " +
                                std::to_string(slab_.count) + ") is not within a grid of n = " +
                                std::to_string(grid_.n) + " planes");
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
          spread_point<true>(st, F[k], torques ? T[k] : Vec3::Zero().eval(), grid_, f,
                             slab_.begin, slab_.count);
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
