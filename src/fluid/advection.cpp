#include "fluid/advection.hpp"

#include "core/target_clones.hpp"

#include <cstddef>
#include <type_traits>

namespace ibrod::fluid::detail {
namespace {

// The default x86-64 target has only 2-wide SSE2 vectors, while FFTW picks AVX kernels at run
// time: in SSE2 the advection pass costs ~1.15 ms at 64³, 27 % of the step's FFTs. An AVX2+FMA
// clone, chosen once by the loader, takes ~0.74 ms (the Stokes pass, pure memory traffic, takes
// 0.46 ms). FMA changes round-off only, like FFTW's own run-time choice of kernels and plans.
// (IBROD_TARGET_CLONES, core/target_clones.hpp)

// One z-row (n contiguous points) of r_c += a u_c − b S_h(u)_c, with b4 = b/(4h) (the 1/(4h) of
// the flux form folded in). c: the centre rows of u; xp, xm, yp, ym: the rows of the x/y
// neighbours; z neighbours are k ± 1 in the same row, wrapped only at the two row ends.
// assign: r_c = a u_c − b S_h(u)_c instead of r_c += …; a run-time flag, because target_clones
// does not combine with templates, but the two loops below are separate, so both vectorise.
IBROD_TARGET_CLONES void advect_row(int n, const double* const* c, const double* const* xp,
                                    const double* const* xm, const double* const* yp,
                                    const double* const* ym, double* const* r, double a, double b4,
                                    bool assign) {
  const double *u0 = c[0], *u1 = c[1], *u2 = c[2];
  const double *x0p = xp[0], *x1p = xp[1], *x2p = xp[2];
  const double *x0m = xm[0], *x1m = xm[1], *x2m = xm[2];
  const double *y0p = yp[0], *y1p = yp[1], *y2p = yp[2];
  const double *y0m = ym[0], *y1m = ym[1], *y2m = ym[2];
  double *r0 = r[0], *r1 = r[1], *r2 = r[2];
  // MODEL §4: r_c += a u_c − b S_h(u)_c in the flux form of advection.hpp
  auto point = [&](int k, int kp, int km, auto assign_tag) {
    const double ux = u0[k], uy = u1[k], uz = u2[k];
    const double fxp = ux + x0p[k], fxm = ux + x0m[k];  // twice the face velocities
    const double fyp = uy + y1p[k], fym = uy + y1m[k];
    const double fzp = uz + u2[kp], fzm = uz + u2[km];
    const double s0 =
        fxp * x0p[k] - fxm * x0m[k] + fyp * y0p[k] - fym * y0m[k] + fzp * u0[kp] - fzm * u0[km];
    const double s1 =
        fxp * x1p[k] - fxm * x1m[k] + fyp * y1p[k] - fym * y1m[k] + fzp * u1[kp] - fzm * u1[km];
    const double s2 =
        fxp * x2p[k] - fxm * x2m[k] + fyp * y2p[k] - fym * y2m[k] + fzp * u2[kp] - fzm * u2[km];
    if constexpr (decltype(assign_tag)::value) {
      r0[k] = a * ux - b4 * s0;
      r1[k] = a * uy - b4 * s1;
      r2[k] = a * uz - b4 * s2;
    } else {
      r0[k] += a * ux - b4 * s0;
      r1[k] += a * uy - b4 * s1;
      r2[k] += a * uz - b4 * s2;
    }
  };
  auto row = [&](auto assign_tag) {
    point(0, 1, n - 1, assign_tag);
#pragma omp simd
    for (int k = 1; k < n - 1; ++k) point(k, k + 1, k - 1, assign_tag);
    point(n - 1, 0, n - 2, assign_tag);
  };
  if (assign)
    row(std::true_type{});
  else
    row(std::false_type{});
}

}  // namespace

void rhs_plane(int n, double h, const int* next, const int* prev, std::array<const double*, 3> uc,
               std::array<const double*, 3> uxp, std::array<const double*, 3> uxm,
               std::array<double*, 3> r, double a, double b, bool assign) {
  const std::size_t nz = std::size_t(n);
  // S_h carries 1/(4h): ½ from the skew average, ½h from each central difference.
  const double b4 = b / (4.0 * h);
  for (int j = 0; j < n; ++j) {
    const std::size_t oc = std::size_t(j) * nz;
    if (b == 0.0) {  // Stokes: memory-bound, plain SSE2 is as fast as it gets
      const double *u0 = uc[0] + oc, *u1 = uc[1] + oc, *u2 = uc[2] + oc;
      double *r0 = r[0] + oc, *r1 = r[1] + oc, *r2 = r[2] + oc;
      if (assign) {
#pragma omp simd
        for (int k = 0; k < n; ++k) {
          r0[k] = a * u0[k];
          r1[k] = a * u1[k];
          r2[k] = a * u2[k];
        }
      } else {
#pragma omp simd
        for (int k = 0; k < n; ++k) {
          r0[k] += a * u0[k];
          r1[k] += a * u1[k];
          r2[k] += a * u2[k];
        }
      }
      continue;
    }
    const std::size_t oyp = std::size_t(next[j]) * nz;
    const std::size_t oym = std::size_t(prev[j]) * nz;
    const double* c[3] = {uc[0] + oc, uc[1] + oc, uc[2] + oc};
    const double* xp[3] = {uxp[0] + oc, uxp[1] + oc, uxp[2] + oc};
    const double* xm[3] = {uxm[0] + oc, uxm[1] + oc, uxm[2] + oc};
    const double* yp[3] = {uc[0] + oyp, uc[1] + oyp, uc[2] + oyp};
    const double* ym[3] = {uc[0] + oym, uc[1] + oym, uc[2] + oym};
    double* r_row[3] = {r[0] + oc, r[1] + oc, r[2] + oc};
    advect_row(n, c, xp, xm, yp, ym, r_row, a, b4, assign);
  }
}

void accumulate_rhs(const GridSpec& grid, const int* next, const int* prev,
                    std::array<const double*, 3> u, std::array<double*, 3> r, double a, double b,
                    int threads) {
  const int n = grid.n;
  const std::size_t plane = std::size_t(n) * n;
  const double h = grid.h();
  auto at = [plane](std::array<const double*, 3> v, int i) {
    return std::array<const double*, 3>{v[0] + i * plane, v[1] + i * plane, v[2] + i * plane};
  };
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int i = 0; i < n; ++i) {
    std::array<double*, 3> ri{r[0] + i * plane, r[1] + i * plane, r[2] + i * plane};
    rhs_plane(n, h, next, prev, at(u, i), at(u, next[i]), at(u, prev[i]), ri, a, b, false);
  }
}

}  // namespace ibrod::fluid::detail
