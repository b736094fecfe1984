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
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/target_clones.hpp"

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

PlaneCoupler::PlaneCoupler(const Coupler& coupler, int npoints)
    : grid_(coupler.grid()),
      m_(coupler.kernel_width()),
      S_(coupler.stencil()),
      P_((coupler.stencil() + 3) / 4 * 4),
      capacity_(std::size_t(std::max(npoints, 0))) {
  const std::size_t S = std::size_t(S_);
  const std::size_t P = std::size_t(P_);
  first_.resize(3 * capacity_);
  phi_.assign(3 * P * capacity_, 0.0);  // the padding stays zero
  dphi_.assign(3 * P * capacity_, 0.0);
  plane_start_.resize(std::size_t(grid_.n) + 2);
  entries_.resize(2 * S * capacity_);
  entry_of_.resize(S * capacity_);
  share_.resize(6 * S * capacity_);
}

void PlaneCoupler::prepare(std::span<const Vec3> X, std::span<const Vec3> F,
                           std::span<const Vec3> T) {
  if (!F.empty()) check_size("F", F.size(), X.size());
  if (!T.empty()) check_size("T", T.size(), X.size());
  if (X.size() > capacity_) {
    throw std::invalid_argument("ib::PlaneCoupler: " + std::to_string(X.size()) +
                                " points, buffers made for " + std::to_string(capacity_));
  }
  check_positions(X, grid_.h());
  F_ = F;
  T_ = T;
  npoints_ = X.size();
  const std::int64_t npoints = std::int64_t(X.size());
  const std::size_t S = std::size_t(S_), P = std::size_t(P_);
  if (m_ == 1) {
    // c = h: the four nonzero weights of one dimension share one square root. With f the
    // fractional part of X_d/h, the stencil entries q = 1..4 sit at r = −1−f, −f, 1−f, 2−f and
    // MODEL (2.14) gives, with s = √(1 + 4f − 4f²) (the radicand of every branch there):
    //   φ(−1−f) = (3 − 2f − s)/8, φ(−f) = (3 − 2f + s)/8, φ(1−f) = (1 + 2f + s)/8,
    //   φ(2−f) = (1 + 2f − s)/8;  entries 0 and 5 (|r| ≥ 2) are zero. Equal to PointStencil's
    // phi4 calls to round-off (test_plane_coupler.cpp), 6× fewer square roots.
    const int n = grid_.n;
    const double h = grid_.h();
    const double inv_h = 1.0 / h, half_inv_h = 0.5 / h;
#pragma omp parallel for schedule(static) if (X.size() >= kParallelMinPoints)
    for (std::int64_t k = 0; k < npoints; ++k) {
      for (int d = 0; d < 3; ++d) {
        const Locus loc = locate(X[k][d], h, n, 1);
        const double f = loc.frac;
        const double sq = std::sqrt(1.0 + 4.0 * f - 4.0 * f * f);
        double* ph = phi_.data() + (3 * k + d) * P;
        double* dp = dphi_.data() + (3 * k + d) * P;
        const double w[6] = {0.0,
                             (3.0 - 2.0 * f - sq) * 0.125 * inv_h,
                             (3.0 - 2.0 * f + sq) * 0.125 * inv_h,
                             (1.0 + 2.0 * f + sq) * 0.125 * inv_h,
                             (1.0 + 2.0 * f - sq) * 0.125 * inv_h,
                             0.0};
        for (int q = 0; q < 6; ++q) {
          ph[q] = w[q];
          dp[q] = ((q < 5 ? w[q + 1] : 0.0) - (q > 0 ? w[q - 1] : 0.0)) * half_inv_h;
        }
        first_[3 * k + d] = loc.first;
      }
    }
  } else {
#pragma omp parallel for schedule(static) if (X.size() >= kParallelMinPoints)
    for (std::int64_t k = 0; k < npoints; ++k) {
      const PointStencil st(X[k], grid_, m_);
      for (int d = 0; d < 3; ++d) {
        first_[3 * k + d] = st.idx[d][0];
        std::copy_n(st.phi[d], S, phi_.begin() + (3 * k + d) * P);
        std::copy_n(st.dphi[d], S, dphi_.begin() + (3 * k + d) * P);
      }
    }
  }
  // counting sort of (point, x entry) by x-plane, points ascending within a plane
  const int n = grid_.n;
  std::fill(plane_start_.begin(), plane_start_.end(), 0);
  for (std::int64_t k = 0; k < npoints; ++k) {
    int i = first_[3 * k];
    for (int a = 0; a < S_; ++a) {
      ++plane_start_[std::size_t(i) + 2];
      if (++i == n) i = 0;
    }
  }
  for (int i = 0; i < n; ++i) plane_start_[std::size_t(i) + 2] += plane_start_[std::size_t(i) + 1];
  for (std::int64_t k = 0; k < npoints; ++k) {
    int i = first_[3 * k];
    for (int a = 0; a < S_; ++a) {
      const int e = plane_start_[std::size_t(i) + 1]++;
      entries_[2 * std::size_t(e)] = int(k);
      entries_[2 * std::size_t(e) + 1] = a;
      entry_of_[std::size_t(k) * S + std::size_t(a)] = e;
      if (++i == n) i = 0;
    }
  }
  // plane_start_[i + 1] is now the end of plane i, plane_start_[i] its start
}

namespace {

// The per-plane kernels of PlaneCoupler. Each point's weights are stored with the stencil width
// S padded with zeros to P, a multiple of 4 (S = 6 → P = 8 for m = 1). A z row of the stencil
// that neither wraps nor runs off the end of the grid row (z₀ + P ≤ n, most of them) is then
// processed as P contiguous values: whole AVX vectors, the padding adding exact zeros to (or
// reading with zero weight from) the P − S grid values after the stencil, which lie in the same
// row. PC: P at compile time (8), or 0 for a run-time P; the other rows take the generic path.
struct PlaneEntries {
  int n, S, P;
  const int* entries;  // (point, x entry) pairs of the plane
  int begin, end;
  const int* first;
  const double* phi;
  const double* dphi;
};

// Four doubles as one vector (GCC/Clang vector extension: an AVX register in the x86-64-v3
// clone, two SSE2 registers in the baseline one). GCC does not vectorise the fixed 8-long row
// loops by itself (it unrolls them first), so the padded rows are written with it.
// Only ever inlined into one translation unit's functions, so the vector ABI (-Wpsabi) is moot.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
using v4d = double __attribute__((vector_size(32)));
[[gnu::always_inline]] inline v4d load4(const double* p) {
  v4d v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void store4(double* p, v4d v) { std::memcpy(p, &v, sizeof v); }

// f_x += A_x φ₃ + B_x dφ₃, f_y += A_y φ₃ + B_y dφ₃, f_z += A_z φ₃ over 8 padded values
[[gnu::always_inline]] inline void spread_row8(double* fx, double* fy, double* fz,
                                               const double* p3, const double* d3, double Ax,
                                               double Ay, double Az, double Bx, double By) {
  for (int h = 0; h < 8; h += 4) {
    const v4d P = load4(p3 + h), D = load4(d3 + h);
    store4(fx + h, load4(fx + h) + Ax * P + Bx * D);
    store4(fy + h, load4(fy + h) + Ay * P + By * D);
    store4(fz + h, load4(fz + h) + Az * P);
  }
}

template <int PC>
[[gnu::always_inline]] inline void spread_entries(const PlaneEntries& v, const Vec3* F,
                                                  const Vec3* T, std::array<double*, 3> plane) {
  const int S = v.S;
  const int P = PC ? PC : v.P;
  const int n = v.n;
  for (int e = v.begin; e < v.end; ++e) {
    const std::size_t k = std::size_t(v.entries[2 * e]);
    const int a = v.entries[2 * e + 1];
    const double* phi = v.phi + 3 * k * std::size_t(P);
    const double* dphi = v.dphi + 3 * k * std::size_t(P);
    // the rows of spread_point() with x index i: f += F w + ½ g × T (see spread_point)
    const double p1 = phi[a], d1 = dphi[a];
    const Vec3& Fk = F[k];
    const double hTx = T ? 0.5 * T[k][0] : 0.0, hTy = T ? 0.5 * T[k][1] : 0.0,
                 hTz = T ? 0.5 * T[k][2] : 0.0;
    const int z0 = v.first[3 * k + 2];
    const bool padded = z0 + P <= n;
    const int len1 = std::min(S, n - z0);
    const double* p3 = phi + 2 * P;
    const double* d3 = dphi + 2 * P;
    int j = v.first[3 * k + 1];
    for (int b = 0; b < S; ++b) {
      const double p12 = p1 * phi[P + b];
      const double d1p2 = d1 * phi[P + b];
      const double p1d2 = p1 * dphi[P + b];
      const double Ax = Fk[0] * p12 + p1d2 * hTz, Bx = -p12 * hTy;
      const double Ay = Fk[1] * p12 - d1p2 * hTz, By = p12 * hTx;
      const double Az = Fk[2] * p12 + d1p2 * hTy - p1d2 * hTx;
      const std::size_t row = std::size_t(j) * std::size_t(n);
      double* fx = plane[0] + row;
      double* fy = plane[1] + row;
      double* fz = plane[2] + row;
      if (PC && padded) {
        spread_row8(fx + z0, fy + z0, fz + z0, p3, d3, Ax, Ay, Az, Bx, By);
      } else {
        spread_row(fx + z0, fy + z0, fz + z0, p3, d3, len1, Ax, Ay, Az, Bx, By);
        if (len1 < S)
          spread_row(fx, fy, fz, p3 + len1, d3 + len1, S - len1, Ax, Ay, Az, Bx, By);
      }
      if (++j == n) j = 0;
    }
  }
}

// Interpolation sums of interpolate_point() restricted to one x-plane, reorganised as column
// sums over the rows b (length-P vectors, no horizontal sum per row):
//   A_c = Σ_b p₁₂ u_c,  B = Σ_b φ₁dφ₂ u_z,  C = Σ_b dφ₁φ₂ u_z,  D = Σ_b (φ₁dφ₂ u_x − dφ₁φ₂ u_y)
//   Σ u w = (A_x·φ₃, A_y·φ₃, A_z·φ₃),
//   Σ u × g = (A_y·dφ₃ − B·φ₃, C·φ₃ − A_x·dφ₃, D·φ₃)
struct ColumnSums {
  double A0[Coupler::kMaxKernelWidth * 4 + 4], A1[Coupler::kMaxKernelWidth * 4 + 4],
      A2[Coupler::kMaxKernelWidth * 4 + 4], B[Coupler::kMaxKernelWidth * 4 + 4],
      C[Coupler::kMaxKernelWidth * 4 + 4], D[Coupler::kMaxKernelWidth * 4 + 4];
};

// the generic row of the column sums (len values)
inline void sample_row(ColumnSums& cs, const double* u0, const double* u1, const double* u2,
                       int len, double p12, double d1p2, double p1d2) {
  for (int c = 0; c < len; ++c) {
    cs.A0[c] += p12 * u0[c];
    cs.A1[c] += p12 * u1[c];
    cs.A2[c] += p12 * u2[c];
    cs.B[c] += p1d2 * u2[c];
    cs.C[c] += d1p2 * u2[c];
    cs.D[c] += p1d2 * u0[c] - d1p2 * u1[c];
  }
}

// the column sums of 8 padded values, in registers
struct ColumnSums8 {
  v4d A0[2] = {}, A1[2] = {}, A2[2] = {}, B[2] = {}, C[2] = {}, D[2] = {};
};
[[gnu::always_inline]] inline void sample_row8(ColumnSums8& cs, const double* u0,
                                               const double* u1, const double* u2, double p12,
                                               double d1p2, double p1d2) {
  for (int h = 0; h < 2; ++h) {
    const v4d x = load4(u0 + 4 * h), y = load4(u1 + 4 * h), z = load4(u2 + 4 * h);
    cs.A0[h] += p12 * x;
    cs.A1[h] += p12 * y;
    cs.A2[h] += p12 * z;
    cs.B[h] += p1d2 * z;
    cs.C[h] += d1p2 * z;
    cs.D[h] += p1d2 * x - d1p2 * y;
  }
}

template <int PC>
[[gnu::always_inline]] inline void sample_entries(const PlaneEntries& v,
                                                  std::array<const double*, 3> plane,
                                                  double* share) {
  constexpr int kMax = 4 * Coupler::kMaxKernelWidth + 4;
  const int S = v.S;
  const int P = PC ? PC : v.P;
  const int n = v.n;
  for (int e = v.begin; e < v.end; ++e) {
    const std::size_t k = std::size_t(v.entries[2 * e]);
    const int a = v.entries[2 * e + 1];
    const double* phi = v.phi + 3 * k * std::size_t(P);
    const double* dphi = v.dphi + 3 * k * std::size_t(P);
    const double p1 = phi[a], d1 = dphi[a];
    const int z0 = v.first[3 * k + 2];
    const double* p3 = phi + 2 * P;
    const double* d3 = dphi + 2 * P;
    double s[6] = {0, 0, 0, 0, 0, 0};
    int j = v.first[3 * k + 1];
    if (PC == 8 && z0 + 8 <= n) {
      ColumnSums8 cs;
      for (int b = 0; b < S; ++b) {
        const std::size_t row = std::size_t(j) * std::size_t(n) + std::size_t(z0);
        sample_row8(cs, plane[0] + row, plane[1] + row, plane[2] + row, p1 * phi[P + b],
                    d1 * phi[P + b], p1 * dphi[P + b]);
        if (++j == n) j = 0;
      }
      // the padding of φ₃, dφ₃ is zero: the last P − S columns add exact zeros
      v4d t[6] = {};
      for (int h = 0; h < 2; ++h) {
        const v4d P3 = load4(p3 + 4 * h), D3 = load4(d3 + 4 * h);
        t[0] += cs.A0[h] * P3;
        t[1] += cs.A1[h] * P3;
        t[2] += cs.A2[h] * P3;
        t[3] += cs.A1[h] * D3 - cs.B[h] * P3;
        t[4] += cs.C[h] * P3 - cs.A0[h] * D3;
        t[5] += cs.D[h] * P3;
      }
      for (int q = 0; q < 6; ++q) s[q] = (t[q][0] + t[q][1]) + (t[q][2] + t[q][3]);
    } else {
      ColumnSums cs{};
      double wrapped[3][kMax];
      for (int b = 0; b < S; ++b) {
        // gather the S values of the row (it may cross the periodic seam in z)
        const std::size_t row = std::size_t(j) * std::size_t(n);
        for (int c = 0; c < S; ++c) {
          const int z = z0 + c < n ? z0 + c : z0 + c - n;
          wrapped[0][c] = plane[0][row + std::size_t(z)];
          wrapped[1][c] = plane[1][row + std::size_t(z)];
          wrapped[2][c] = plane[2][row + std::size_t(z)];
        }
        sample_row(cs, wrapped[0], wrapped[1], wrapped[2], S, p1 * phi[P + b], d1 * phi[P + b],
                   p1 * dphi[P + b]);
        if (++j == n) j = 0;
      }
      for (int c = 0; c < S; ++c) {
        s[0] += cs.A0[c] * p3[c];
        s[1] += cs.A1[c] * p3[c];
        s[2] += cs.A2[c] * p3[c];
        s[3] += cs.A1[c] * d3[c] - cs.B[c] * p3[c];
        s[4] += cs.C[c] * p3[c] - cs.A0[c] * d3[c];
        s[5] += cs.D[c] * p3[c];
      }
    }
    std::copy_n(s, 6, share + 6 * std::size_t(e));
  }
}

#pragma GCC diagnostic pop

IBROD_TARGET_CLONES void spread_plane_entries(const PlaneEntries& v, const Vec3* F,
                                              const Vec3* T, std::array<double*, 3> plane) {
  if (v.P == 8)
    spread_entries<8>(v, F, T, plane);
  else
    spread_entries<0>(v, F, T, plane);
}

IBROD_TARGET_CLONES void sample_plane_entries(const PlaneEntries& v,
                                              std::array<const double*, 3> plane,
                                              double* share) {
  if (v.P == 8)
    sample_entries<8>(v, plane, share);
  else
    sample_entries<0>(v, plane, share);
}

}  // namespace

void PlaneCoupler::add_plane(int i, std::array<double*, 3> plane) const {
  if (F_.empty()) return;
  const PlaneEntries v{grid_.n, S_, P_, entries_.data(), plane_start_[std::size_t(i)],
                       plane_start_[std::size_t(i) + 1], first_.data(), phi_.data(), dphi_.data()};
  spread_plane_entries(v, F_.data(), T_.empty() ? nullptr : T_.data(), plane);
}

void PlaneCoupler::sample_plane(int i, std::array<const double*, 3> plane) {
  const PlaneEntries v{grid_.n, S_, P_, entries_.data(), plane_start_[std::size_t(i)],
                       plane_start_[std::size_t(i) + 1], first_.data(), phi_.data(), dphi_.data()};
  sample_plane_entries(v, plane, share_.data());
}

void PlaneCoupler::finish_interpolation(std::span<Vec3> U, std::span<Vec3> W) const {
  check_size("U", U.size(), npoints_);
  if (!W.empty()) check_size("W", W.size(), npoints_);
  const double h3 = grid_.h() * grid_.h() * grid_.h();
  const std::size_t S = std::size_t(S_);
  for (std::size_t k = 0; k < npoints_; ++k) {
    double s[6] = {0, 0, 0, 0, 0, 0};
    for (std::size_t a = 0; a < S; ++a) {  // x-stencil order: fixed, whatever the threads
      const double* sh = share_.data() + 6 * std::size_t(entry_of_[k * S + a]);
      for (int c = 0; c < 6; ++c) s[c] += sh[c];
    }
    U[k] = Vec3(s[0], s[1], s[2]) * h3;  // MODEL §4: U = Σ u δ_c h³
    // MODEL §4: W = ½ Σ (curl_h u) δ_c h³ = ½ Σ u × ∇_h δ_c h³ (summation by parts)
    if (!W.empty()) W[k] = Vec3(s[3], s[4], s[5]) * (0.5 * h3);
  }
}

}  // namespace ibrod::ib
