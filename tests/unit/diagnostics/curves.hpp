#pragma once
// Test curves and independent oracles for the topology diagnostics. Nothing here uses ibrod_rod
// or the code under test.
#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include "core/types.hpp"

namespace ibrod::diagnostics::testing {

inline constexpr double pi = std::numbers::pi;

/// A smooth closed curve r(t), t ∈ [0, 2π), with its analytic derivative.
struct SmoothCurve {
  std::function<Vec3(double)> r;
  std::function<Vec3(double)> dr;

  /// n vertices at t_k = 2πk/n + phase.
  std::vector<Vec3> sample(int n, double phase = 0.0) const {
    std::vector<Vec3> X(n);
    for (int k = 0; k < n; ++k) X[k] = r(2 * pi * k / n + phase);
    return X;
  }
};

/// Circle of radius R in the plane spanned by the orthonormal e1, e2, centred at c,
/// counter-clockwise about e1 × e2.
inline std::vector<Vec3> circle(int n, double R, const Vec3& c = Vec3::Zero(),
                                const Vec3& e1 = Vec3::UnitX(), const Vec3& e2 = Vec3::UnitY()) {
  std::vector<Vec3> X(n);
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    X[k] = c + R * (std::cos(t) * e1 + std::sin(t) * e2);
  }
  return X;
}

/// Random 3-D Fourier curve r(t) = Σ_{k=1..modes} (a_k cos kt + b_k sin kt)/k, a_k, b_k ~ N(0, I).
inline SmoothCurve random_fourier_curve(std::mt19937_64& rng, int modes) {
  std::normal_distribution<double> N(0.0, 1.0);
  std::vector<Vec3> a(modes), b(modes);
  for (int k = 0; k < modes; ++k) {
    a[k] = Vec3(N(rng), N(rng), N(rng)) / (k + 1);
    b[k] = Vec3(N(rng), N(rng), N(rng)) / (k + 1);
  }
  SmoothCurve C;
  C.r = [a, b](double t) {
    Vec3 x = Vec3::Zero();
    for (int k = 0; k < int(a.size()); ++k)
      x += a[k] * std::cos((k + 1) * t) + b[k] * std::sin((k + 1) * t);
    return x;
  };
  C.dr = [a, b](double t) {
    Vec3 x = Vec3::Zero();
    for (int k = 0; k < int(a.size()); ++k)
      x += (k + 1) * (-a[k] * std::sin((k + 1) * t) + b[k] * std::cos((k + 1) * t));
    return x;
  };
  return C;
}

/// Klenin & Langowski, Biopolymers 54 (2000) 307, method 1b, as published: the solid angle of
/// the segment pair p1→p2, p3→p4 from the four face normals and asin terms. The slow oracle for
/// diagnostics::segment_pair_solid_angle (same quantity, different formula).
inline double solid_angle_kl1b(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& p4) {
  const Vec3 r12 = p2 - p1, r34 = p4 - p3;
  const Vec3 r13 = p3 - p1, r14 = p4 - p1, r23 = p3 - p2, r24 = p4 - p2;
  const Vec3 n1 = r13.cross(r14).normalized(), n2 = r14.cross(r24).normalized();
  const Vec3 n3 = r24.cross(r23).normalized(), n4 = r23.cross(r13).normalized();
  auto as = [](double x) { return std::asin(std::clamp(x, -1.0, 1.0)); };
  const double omega_star = as(n1.dot(n2)) + as(n2.dot(n3)) + as(n3.dot(n4)) + as(n4.dot(n1));
  const double sgn = r34.cross(r12).dot(r13);
  return sgn > 0 ? omega_star : (sgn < 0 ? -omega_star : 0.0);
}

/// Writhe of a closed polygon by K&L 1b, all ordered non-adjacent pairs, divided by 4π.
inline double writhe_kl1b(const std::vector<Vec3>& X) {
  const int n = int(X.size());
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int d = std::abs(i - j);
      if (d <= 1 || d == n - 1) continue;
      sum += solid_angle_kl1b(X[i], X[(i + 1) % n], X[j], X[(j + 1) % n]);
    }
  return sum / (4 * pi);
}

/// Writhe of a smooth curve by the periodic midpoint rule on an N×N grid of the Gauss double
/// integral (1/4π) ∬ (r′(s) × r′(t))·(r(s) − r(t)) / |r(s) − r(t)|³ ds dt, with the analytic
/// tangent. The integrand tends to 0 like |s − t| on the diagonal, which is left out: error O(N⁻²).
inline double writhe_gauss_quadrature(const SmoothCurve& C, int N) {
  std::vector<Vec3> r(N), dr(N);
  for (int k = 0; k < N; ++k) {
    const double t = 2 * pi * (k + 0.5) / N;
    r[k] = C.r(t);
    dr[k] = C.dr(t);
  }
  double sum = 0.0;
  for (int i = 0; i < N; ++i)
    for (int j = i + 1; j < N; ++j) {
      const Vec3 x = r[i] - r[j];
      const double x2 = x.squaredNorm();
      sum += dr[i].cross(dr[j]).dot(x) / (x2 * std::sqrt(x2));
    }
  const double h = 2 * pi / N;
  return 2.0 * sum * h * h / (4 * pi);
}

/// Signed area (sr) enclosed by the closed geodesic polygon of unit vectors t_0 … t_{n−1} on the
/// unit sphere, counter-clockwise positive, modulo 4π: a fan of flat triangles from the pole e,
/// each by its solid angle (Van Oosterom & Strackee 1983).
inline double spherical_polygon_area(const std::vector<Vec3>& t, const Vec3& e) {
  double A = 0.0;
  const int n = int(t.size());
  for (int k = 0; k < n; ++k) {
    const Vec3& a = e;
    const Vec3& b = t[k];
    const Vec3& c = t[(k + 1) % n];
    A += 2 * std::atan2(a.dot(b.cross(c)), 1 + a.dot(b) + a.dot(c) + b.dot(c));
  }
  return A;
}

/// x reduced to (−p/2, p/2] modulo p.
inline double mod_centered(double x, double p) { return x - p * std::round(x / p); }

}  // namespace ibrod::diagnostics::testing
