// PlaneCoupler (ib/plane_coupler.hpp): the kernel weights of every point once, then spreading and
// interpolation one x-plane at a time. The sums are those of Coupler (ib/coupler.cpp), with the
// stencil rows of ib/kernel.hpp.
#include "ib/plane_coupler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/target_clones.hpp"

namespace ibrod::ib {

using detail::check_positions;
using detail::check_size;
using detail::kParallelMinPoints;
using detail::locate;
using detail::Locus;
using detail::PointStencil;
using detail::spread_row;

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
[[gnu::always_inline]] inline void spread_row8(double* fx, double* fy, double* fz, const double* p3,
                                               const double* d3, double Ax, double Ay, double Az,
                                               double Bx, double By) {
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
        if (len1 < S) spread_row(fx, fy, fz, p3 + len1, d3 + len1, S - len1, Ax, Ay, Az, Bx, By);
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
[[gnu::always_inline]] inline void sample_row8(ColumnSums8& cs, const double* u0, const double* u1,
                                               const double* u2, double p12, double d1p2,
                                               double p1d2) {
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

IBROD_TARGET_CLONES void spread_plane_entries(const PlaneEntries& v, const Vec3* F, const Vec3* T,
                                              std::array<double*, 3> plane) {
  if (v.P == 8)
    spread_entries<8>(v, F, T, plane);
  else
    spread_entries<0>(v, F, T, plane);
}

IBROD_TARGET_CLONES void sample_plane_entries(const PlaneEntries& v,
                                              std::array<const double*, 3> plane, double* share) {
  if (v.P == 8)
    sample_entries<8>(v, plane, share);
  else
    sample_entries<0>(v, plane, share);
}

}  // namespace

void PlaneCoupler::add_plane(int i, std::array<double*, 3> plane) const {
  if (F_.empty()) return;
  const PlaneEntries v{grid_.n,
                       S_,
                       P_,
                       entries_.data(),
                       plane_start_[std::size_t(i)],
                       plane_start_[std::size_t(i) + 1],
                       first_.data(),
                       phi_.data(),
                       dphi_.data()};
  spread_plane_entries(v, F_.data(), T_.empty() ? nullptr : T_.data(), plane);
}

void PlaneCoupler::sample_plane(int i, std::array<const double*, 3> plane, std::size_t points) {
  const int begin = plane_start_[std::size_t(i)];
  int end = plane_start_[std::size_t(i) + 1];
  if (points < npoints_) {
    // the plane's entries are in ascending point order: stop at the first point ≥ `points`
    int lo = begin, hi = end;
    while (lo < hi) {
      const int mid = lo + (hi - lo) / 2;
      if (std::size_t(entries_[2 * std::size_t(mid)]) < points)
        lo = mid + 1;
      else
        hi = mid;
    }
    end = lo;
  }
  const PlaneEntries v{grid_.n,       S_,          P_,          entries_.data(), begin, end,
                       first_.data(), phi_.data(), dphi_.data()};
  sample_plane_entries(v, plane, share_.data());
}

void PlaneCoupler::finish_interpolation(std::span<Vec3> U, std::span<Vec3> W,
                                        std::size_t points) const {
  // U of every point, or of the first `points` (sample_plane's)
  check_size("U", U.size(), std::min(points, npoints_));
  if (!W.empty()) check_size("W", W.size(), U.size());
  const double h3 = grid_.h() * grid_.h() * grid_.h();
  const std::size_t S = std::size_t(S_);
  for (std::size_t k = 0; k < U.size(); ++k) {
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
