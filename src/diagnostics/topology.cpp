// Writhe, twist, linking number and closest approach of closed polygons (MODEL §6); the twist,
// closest approach and spacing of open ones.
//
// Solid angle of a segment pair. The Gauss integrand for the segments p1→p2 (r₁ = p1 + σ s) and
// p3→p4 (r₂ = p3 + τ u) is minus the solid-angle element of the surface v(σ, τ) = r₂ − r₁, which
// is the flat parallelogram with corners a = p3−p1, d = p3−p2, c = p4−p2, b = p4−p1, traversed
// a→d→c→b. Its signed solid angle is exact as two flat triangles (a,d,c) + (a,c,b), each by
// Van Oosterom & Strackee, IEEE Trans. Biomed. Eng. 30 (1983) 125:
//   tan(Ω_abc/2) = a·(b×c) / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|).
// Both triangles have the same numerator T = a·(d×c) = a·(c×b) = a·(u×s) (a parallelogram is
// flat), and the two half-angles add to Ω/2 ∈ (−π, π), so one atan2 of the product of the two
// complex numbers (den + iT) gives Ω. This is the same quantity as Klenin & Langowski,
// Biopolymers 54 (2000) 307, method 1b (Ω = sign(T)·Σ asin(n_k·n_{k+1})), which the tests keep as
// the oracle. The asin form loses half the digits when the four points are nearly coplanar
// (asin′ → ∞ at ±1), exactly the pairs of a thin ribbon X, X + εd1 and of a planar curve: measured
// Lk of a circle ribbon off by 4e-9 (atan2 form: 4e-14), Wr of a planar polygon 1.4e-7 (1.3e-14).
#include "diagnostics/topology.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace ibrod::diagnostics {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;
constexpr double four_pi = 4.0 * std::numbers::pi;

/// The polygon with X_n = X_0 appended, so that the pair loops need no modulo.
std::vector<Vec3> closed_copy(std::span<const Vec3> X) {
  std::vector<Vec3> Y(X.begin(), X.end());
  Y.push_back(X[0]);
  return Y;
}

/// Σ_{j∈[j0,j1)} Ω(p1→p2, Y_j→Y_{j+1}); Y must hold Y[j1]. The corner vectors b = Y_{j+1} − p1
/// and c = Y_{j+1} − p2 of pair j are the corners a and d of pair j+1, so |b|, |c| and b·c are
/// carried as |a|, |d| and a·d: two sqrt, four dot products and one atan2 per pair.
inline double row_solid_angle(const Vec3& p1, const Vec3& p2, const Vec3* Y, int j0, int j1) {
  const Vec3 s = p2 - p1;
  Vec3 a = Y[j0] - p1;
  Vec3 d = Y[j0] - p2;
  double ra = a.norm(), rd = d.norm(), ad = a.dot(d);
  double sum = 0.0;
  for (int j = j0; j < j1; ++j) {
    const Vec3 b = Y[j + 1] - p1;
    const Vec3 c = Y[j + 1] - p2;
    const Vec3 u = Y[j + 1] - Y[j];
    const double rb = b.norm(), rc = c.norm();
    const double ac = a.dot(c), ab = a.dot(b), bc = b.dot(c), dc = d.dot(c);
    const double T = a.dot(u.cross(s));
    const double den1 = ra * rd * rc + ad * rc + ac * rd + dc * ra;  // triangle (a, d, c)
    const double den2 = ra * rc * rb + ac * rb + ab * rc + bc * ra;  // triangle (a, c, b)
    sum += std::atan2(T * (den1 + den2), den1 * den2 - T * T);       // = Ω/2
    a = b;
    d = c;
    ra = rb;
    rd = rc;
    ad = bc;
  }
  return 2.0 * sum;
}

/// Signed angle (rad, (−π, π]) that turns p into q about the axis t (right-handed). The
/// components of p and q along t only enter p·q, where they are second order.
inline double signed_angle(const Vec3& p, const Vec3& q, const Vec3& t) {
  return std::atan2(t.dot(p.cross(q)), p.dot(q));
}

}  // namespace

double segment_pair_solid_angle(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& p4) {
  const Vec3 Y[2] = {p3, p4};
  return row_solid_angle(p1, p2, Y, 0, 1);
}

// Wr = (1/4π) Σ_{i≠j} Ω_ij = (1/2π) Σ_{i<j} Ω_ij (Ω is symmetric); adjacent segments share a
// vertex, so r₁ − r₂ lies in the plane of dr₁, dr₂ and the integrand vanishes: skipped.
// Rows are summed into row_sum and added in index order, so the result does not depend on the
// thread count or the schedule (a `reduction(+:)` would add the rows in a run-dependent order).
double writhe(std::span<const Vec3> X) {
  const int n = int(X.size());
  if (n < 4) return 0.0;  // a triangle is planar
  const std::vector<Vec3> Y = closed_copy(X);
  std::vector<double> row_sum(n, 0.0);
#pragma omp parallel for schedule(dynamic, 8)
  for (int i = 0; i < n - 2; ++i) {
    const int j1 = (i == 0) ? n - 1 : n;  // segment n−1 is adjacent to segment 0
    row_sum[i] = row_solid_angle(Y[i], Y[i + 1], Y.data(), i + 2, j1);
  }
  double sum = 0.0;
  for (const double r : row_sum) sum += r;
  return sum / two_pi;
}

// Lk = (1/4π) Σ_{i,j} Ω(A_i→A_{i+1}, B_j→B_{j+1}) (Gauss; exact for polygons). Same kernel and
// sign as writhe, so Lk(X, X + εd1) = Wr(X) + Tw in the limit of a thin ribbon.
double linking_number(std::span<const Vec3> A, std::span<const Vec3> B) {
  const int na = int(A.size()), nb = int(B.size());
  if (na < 2 || nb < 2) return 0.0;
  const std::vector<Vec3> Ac = closed_copy(A), Bc = closed_copy(B);
  std::vector<double> row_sum(na, 0.0);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < na; ++i) row_sum[i] = row_solid_angle(Ac[i], Ac[i + 1], Bc.data(), 0, nb);
  double sum = 0.0;
  for (const double r : row_sum) sum += r;
  return sum / four_pi;
}

// Discrete twist (turns). Edge k runs X_k → X_{k+1} with unit tangent t_k; P_k(v) = v − (v·t_k)t_k
// projects onto the plane ⟂ t_k. The reference frame is the discrete parallel transport: constant
// along an edge, and across vertex k+1 turned by R_{k+1}, the minimal rotation taking t_k to
// t_{k+1} (axis t_k × t_{k+1}). The ribbon's angle relative to that frame changes
//   along edge k:        ∠_{t_k}(P_k d1_k, P_k d1_{k+1}),
//   across vertex k+1:   ∠_{t_{k+1}}(R_{k+1} P_k d1_{k+1}, P_{k+1} d1_{k+1}),
// each the signed angle in (−π, π] about the tangent. Tw = Σ_k (both) / 2π.
// Why this is exact: the transport is Levi-Civita transport along the tangent indicatrix, a
// geodesic polygon on the unit sphere, so the frame comes back turned by A (mod 2π), A the area
// the indicatrix encloses, and a closed ribbon has Tw ≡ −A/2π (mod 1). Fuller, PNAS 75 (1978)
// 3557, holds for the polygon (the limit of rounding its corners): Wr ≡ A/2π − 1 (mod 2). So
// Tw + Wr is an integer to round-off, and it is Lk(X, X + εd1) once the ribbon is thin enough
// (ε ≪ edge length, curvature radius) and d1 turns by < π per piece (Călugăreanu–White; Banchoff,
// Indiana Univ. Math. J. 25 (1976) 1171, for polygons).
double twist(std::span<const Vec3> X, std::span<const Vec3> d1) {
  const int n = int(X.size());
  if (int(d1.size()) != n)
    throw std::invalid_argument("diagnostics::twist: X and d1 differ in length");
  if (n < 3) return 0.0;
  std::vector<Vec3> t(n);
  for (int k = 0; k < n; ++k) t[k] = (X[(k + 1) % n] - X[k]).normalized();
  double angle = 0.0;
  for (int k = 0; k < n; ++k) {
    const int kn = (k + 1) % n;
    const Vec3& tk = t[k];
    const Vec3& tn = t[kn];
    const Vec3 u = d1[k] - d1[k].dot(tk) * tk;    // ribbon at the start of edge k
    const Vec3 v = d1[kn] - d1[kn].dot(tk) * tk;  // … at its end
    const Vec3 w = d1[kn] - d1[kn].dot(tn) * tn;  // … at the start of edge k+1
    angle += signed_angle(u, v, tk);
    // R v = v + c×v + c×(c×v)/(1 + t_k·t_{k+1}), c = t_k × t_{k+1} (Rodrigues, sinθ = |c|)
    const Vec3 c = tk.cross(tn);
    const Vec3 cv = c.cross(v);
    const Vec3 Rv = v + cv + c.cross(cv) / (1.0 + tk.dot(tn));
    angle += signed_angle(Rv, w, tn);
  }
  return angle / two_pi;
}

double twist_open(std::span<const Vec3> X, std::span<const Vec3> d1) {
  const int n = int(X.size());
  if (int(d1.size()) != n)
    throw std::invalid_argument("diagnostics::twist_open: X and d1 differ in length");
  if (n < 2) return 0.0;
  std::vector<Vec3> t(n - 1);
  for (int k = 0; k + 1 < n; ++k) t[k] = (X[k + 1] - X[k]).normalized();
  double angle = 0.0;
  for (int k = 0; k + 1 < n; ++k) {  // edge k, then vertex k+1 if it is interior
    const Vec3& tk = t[k];
    const Vec3 u = d1[k] - d1[k].dot(tk) * tk;
    const Vec3 v = d1[k + 1] - d1[k + 1].dot(tk) * tk;
    angle += signed_angle(u, v, tk);
    if (k + 2 < n) {
      const Vec3& tn = t[k + 1];
      const Vec3 w = d1[k + 1] - d1[k + 1].dot(tn) * tn;
      const Vec3 c = tk.cross(tn);
      const Vec3 cv = c.cross(v);
      const Vec3 Rv = v + cv + c.cross(cv) / (1.0 + tk.dot(tn));
      angle += signed_angle(Rv, w, tn);
    }
  }
  return angle / two_pi;
}

// Pairs i < j with cyclic distance min(j − i, n − (j − i)) ≥ m, i.e. i + m ≤ j ≤ i + n − m
// (open: i + m ≤ j ≤ n − 1).
ClosestPair closest_pair(std::span<const Vec3> X, int min_separation, bool closed) {
  const int n = int(X.size());
  const int m = std::max(min_separation, 1);
  ClosestPair best{std::numeric_limits<double>::infinity(), -1, -1};
  if (closed ? n < 2 * m : n <= m) return best;
  std::vector<double> row_d2(n, std::numeric_limits<double>::infinity());
  std::vector<int> row_j(n, -1);
#pragma omp parallel for schedule(dynamic, 16)
  for (int i = 0; i < n; ++i) {
    const Vec3 xi = X[i];
    const int j1 = closed ? std::min(n - 1, i + n - m) : n - 1;
    double d2min = std::numeric_limits<double>::infinity();
    int jmin = -1;
    for (int j = i + m; j <= j1; ++j) {
      const double d2 = (X[j] - xi).squaredNorm();
      if (d2 < d2min) {
        d2min = d2;
        jmin = j;
      }
    }
    row_d2[i] = d2min;
    row_j[i] = jmin;
  }
  for (int i = 0; i < n; ++i)
    if (row_j[i] >= 0 && row_d2[i] < best.distance) best = {row_d2[i], i, row_j[i]};
  if (best.i >= 0) best.distance = std::sqrt(best.distance);
  return best;
}

double closest_approach(std::span<const Vec3> X, int min_separation, bool closed) {
  return closest_pair(X, min_separation, closed).distance;
}

double mean_spacing(std::span<const Vec3> X, bool closed) {
  const int n = int(X.size());
  if (n < 2) return 0.0;
  const int edges = closed ? n : n - 1;
  double sum = 0.0;
  for (int k = 0; k < edges; ++k) sum += (X[(k + 1) % n] - X[k]).norm();
  return sum / edges;
}

bool link_defined(const rod::RodRange& g) { return rod::wraps(g); }

bool link_defined(std::span<const rod::RodRange> rods) {
  return std::all_of(rods.begin(), rods.end(),
                     [](const rod::RodRange& g) { return link_defined(g); });
}

RodTopology rod_topology(std::span<const Vec3> X_all, std::span<const Vec3> d1_all,
                         const rod::RodRange& g, int min_separation) {
  const std::size_t at = std::size_t(g.offset), n = std::size_t(g.n);
  const std::span<const Vec3> X = X_all.subspan(at, n), d1 = d1_all.subspan(at, n);
  const bool closed = rod::wraps(g);
  RodTopology t{};
  if (link_defined(g)) {
    t.writhe = writhe(X);
    t.twist = twist(X, d1);
    t.link = t.writhe + t.twist;
  } else {
    // NaN is "not defined", written as an empty CSV field and null in JSON (io/observables)
    t.writhe = t.link = std::numeric_limits<double>::quiet_NaN();
    t.twist = twist_open(X, d1);
  }
  t.closest = closest_approach(X, min_separation, closed);
  t.links = rod::links(g);
  t.spacing = mean_spacing(X, closed);
  return t;
}

}  // namespace ibrod::diagnostics
