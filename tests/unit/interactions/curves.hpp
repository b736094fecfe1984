#pragma once
// Test configurations for the interaction tests, built here (not from src/rod) so that these
// tests depend on src/interactions alone.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include "core/types.hpp"

namespace ibrod::interactions::test {

inline constexpr double pi = std::numbers::pi;
inline constexpr double kT = 414.2;      ///< g Å² s⁻² at 300 K, MODEL §1
inline constexpr double kR0 = 324.676;   ///< reference ring radius, Å
inline constexpr int kN = 600;           ///< reference number of points
inline constexpr double kDs = 3.4;       ///< Δs, Å
inline constexpr double kCharge = 0.48;  ///< q, e
inline constexpr double kDielectric = 77.7;

inline Vec3 unit_random(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Vec3 v(g(rng), g(rng), g(rng));
  return v.normalized();
}

inline Vec3 random_vec(std::mt19937_64& rng, double r) {
  std::uniform_real_distribution<double> u(-r, r);
  return Vec3(u(rng), u(rng), u(rng));
}

/// The reference circle: n points on a ring of radius r in the plane z = 0, centred at c.
inline std::vector<Vec3> circle(int n = kN, double r = kR0, Vec3 c = Vec3::Zero()) {
  std::vector<Vec3> X(n);
  for (int k = 0; k < n; ++k) {
    const double th = 2 * pi * k / n;
    X[k] = c + r * Vec3(std::cos(th), std::sin(th), 0);
  }
  return X;
}

/// A compact 3-D configuration: a self-avoiding random walk of n − 1 steps of `step` Å (no two
/// points closer than min_sep; a trial step that would be is redrawn). n = 600, 3.4 Å spans
/// ≈ 200 Å: much more compact than the ring.
inline std::vector<Vec3> compact_walk(unsigned seed, int n = kN, double step = kDs,
                                      double min_sep = 3.0) {
  std::mt19937_64 rng(seed);
  std::vector<Vec3> X;
  X.reserve(n);
  X.push_back(Vec3::Zero());
  while (int(X.size()) < n) {
    const Vec3 y = X.back() + step * unit_random(rng);
    const bool ok = std::none_of(X.begin(), X.end() - 1, [&](const Vec3& x) {
      return (x - y).squaredNorm() < min_sep * min_sep;
    });
    if (ok) X.push_back(y);
  }
  return X;
}

/// A random cloud of n points in a cube of edge `box`, no two closer than min_sep.
inline std::vector<Vec3> cloud(unsigned seed, int n, double box, double min_sep) {
  std::mt19937_64 rng(seed);
  std::vector<Vec3> X;
  while (int(X.size()) < n) {
    const Vec3 y = random_vec(rng, box / 2);
    if (std::none_of(X.begin(), X.end(),
                     [&](const Vec3& x) { return (x - y).squaredNorm() < min_sep * min_sep; }))
      X.push_back(y);
  }
  return X;
}

/// A closed figure-eight that crosses itself once, the two strands 2h apart at the crossing:
/// X(θ) = (R sin θ, R sin θ cos θ, h cos θ), crossing near θ = 0 and θ = π (at right angles),
/// which are n/2 points apart along the rod. Phase-shifted and jittered by up to `jitter` Å so
/// that no vertex sits exactly on the crossing.
inline std::vector<Vec3> figure_eight(int n, double R, double h, double jitter, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::vector<Vec3> X(n);
  for (int k = 0; k < n; ++k) {
    const double th = 2 * pi * (k + 0.3) / n;
    X[k] = Vec3(R * std::sin(th), R * std::sin(th) * std::cos(th), h * std::cos(th)) +
           random_vec(rng, jitter);
  }
  return X;
}

/// A collapsed supercoil: a closed interwound (plectonemic) curve, two strands wound about each
/// other at superhelical radius r (strand separation 2r in the middle, tapering into the end
/// loops) with pitch `pitch`, n points equally spaced by ds along it. Parametrised by θ:
/// X = (a cos θ, r sin θ cos(k a cos θ), r sin θ sin(k a cos θ)), k = 2π/pitch, with a set so
/// that the length is n ds; θ and −θ are the two strands at the same x.
inline std::vector<Vec3> plectoneme(int n = kN, double ds = kDs, double r = 12.0,
                                    double pitch = 60.0) {
  const int m = 40 * n;  // fine sampling for the arclength
  const double k = 2 * pi / pitch;
  double a = n * ds / 4;
  std::vector<Vec3> Y(m + 1);
  std::vector<double> len(m + 1);
  for (int iter = 0; iter < 30; ++iter) {
    for (int i = 0; i <= m; ++i) {
      const double th = 2 * pi * i / m, x = a * std::cos(th);
      Y[i] = Vec3(x, r * std::sin(th) * std::cos(k * x), r * std::sin(th) * std::sin(k * x));
      len[i] = i == 0 ? 0 : len[i - 1] + (Y[i] - Y[i - 1]).norm();
    }
    a *= n * ds / len[m];
  }
  std::vector<Vec3> X(n);
  for (int j = 0, i = 0; j < n; ++j) {
    const double target = len[m] * j / n;
    while (len[i + 1] < target) ++i;
    const double w = (target - len[i]) / (len[i + 1] - len[i]);
    X[j] = (1 - w) * Y[i] + w * Y[i + 1];
  }
  return X;
}

/// Mean spacing of a closed polygon, Å.
inline double mean_spacing(std::span<const Vec3> X) {
  const int n = int(X.size());
  double L = 0;
  for (int k = 0; k < n; ++k) L += (X[(k + 1) % n] - X[k]).norm();
  return L / n;
}

/// max_i |A_i − B_i| / max_i |B_i|
inline double max_rel_diff(std::span<const Vec3> A, std::span<const Vec3> B) {
  double num = 0, den = 0;
  for (size_t i = 0; i < A.size(); ++i) {
    num = std::max(num, (A[i] - B[i]).norm());
    den = std::max(den, B[i].norm());
  }
  return num / den;
}

}  // namespace ibrod::interactions::test
