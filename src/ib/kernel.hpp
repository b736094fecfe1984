#pragma once
// Peskin's 4-point kernel (MODEL (2.14)–(2.16)) and its separable stencil on the periodic grid,
// the pointwise part of the generalized IB coupling; the loops over points and grid rows are
// Coupler (ib/coupler.hpp) and PlaneCoupler (ib/plane_coupler.hpp).
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
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/grid.hpp"
#include "core/types.hpp"

namespace ibrod::ib {

/// Peskin's 4-point function φ(r) (MODEL (2.14)); support |r| < 2, Σ_j φ(r − j) = 1,
/// Σ_j (r − j) φ(r − j) = 0, Σ_j φ(r − j)² = 3/8.
double phi4(double r);

/// δ_c(x) with c = m·h: c⁻³ φ(x₁/c) φ(x₂/c) φ(x₃/c), Å⁻³.
double delta(const Vec3& x, double c);

/// largest kernel width m accepted (fixed-size stencil arrays: 4m + 2 ≤ 34 points)
inline constexpr int kMaxKernelWidth = 8;

/// The stencil machinery shared by Coupler and PlaneCoupler; not an API.
namespace detail {

inline constexpr int kMaxStencil = 4 * kMaxKernelWidth + 2;

// Points with more coordinates than this (in grid units) are rejected: ⌊s⌋ must fit an int64 and
// s − ⌊s⌋ must keep a useful number of bits.
inline constexpr double kMaxGridCoordinate = 1099511627776.0;  // 2⁴⁰

// Parallel regions cost a few µs; below this many points the loops run serially (same result).
inline constexpr std::size_t kParallelMinPoints = 64;

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

/// Throws ibrod::RunError if a position is not finite or absurdly far out (|X_d| > 2⁴⁰ h).
void check_positions(std::span<const Vec3> X, double h);
/// Throws std::invalid_argument unless got == want (`what` has `got` entries, positions `want`).
void check_size(const char* what, std::size_t got, std::size_t want);

// One row of the stencil (fixed x and y index; z runs over a contiguous piece of the grid row):
// f_d[c] += A_d φ₃[c] + B_d dφ₃[c]. restrict: the three components are separate arrays.
inline void spread_row(double* __restrict fx, double* __restrict fy, double* __restrict fz,
                       const double* __restrict p3, const double* __restrict d3, int len, double Ax,
                       double Ay, double Az, double Bx, double By) {
  for (int c = 0; c < len; ++c) {
    fx[c] += Ax * p3[c] + Bx * d3[c];
    fy[c] += Ay * p3[c] + By * d3[c];
    fz[c] += Az * p3[c];
  }
}

}  // namespace detail

}  // namespace ibrod::ib
