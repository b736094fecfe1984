#pragma once
// Configurations and finite-difference helpers shared by the rod unit tests.
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "rod/rod.hpp"

namespace ibrod::rod::test {

inline constexpr double kT = 414.2;  ///< g Å² s⁻², MODEL §1 (300 K)
inline constexpr double pi = std::numbers::pi;

/// Uniform random vector with components in [−r, r].
inline Vec3 random_vec(std::mt19937_64& rng, double r) {
  std::uniform_real_distribution<double> u(-r, r);
  return Vec3(u(rng), u(rng), u(rng));
}

/// The reference twisted circle with every X_k moved by up to dx (Å) per component and every
/// triad turned by a random rotation of up to dtheta (rad) per component.
inline RodState perturbed_circle(const RodParams& p, const CircleParams& c, double dx,
                                 double dtheta, unsigned seed) {
  std::mt19937_64 rng(seed);
  RodState s = twisted_circle(p, c);
  for (int k = 0; k < s.size(); ++k) {
    s.X[k] += random_vec(rng, dx);
    s.D[k] = rotation(random_vec(rng, dtheta)) * s.D[k];
  }
  return s;
}

/// A smooth closed rod sampled at n points t_k = 2πk/n: a non-planar curve of size R (Å) with an
/// adapted frame twisted `turns` times plus a smooth twist modulation, then tilted by a smooth
/// small rotation so that shear is non-zero. The same curve and frame for any n; use
/// Δs = smooth_rod_length(R)/n so that the mean stretch is about zero.
inline RodState smooth_rod(int n, double R, int turns) {
  RodState s;
  s.X.resize(n);
  s.D.resize(n);
  const Vec3 z(0.0, 0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    const double t = 2.0 * pi * k / n;
    s.X[k] = R * Vec3(std::cos(t) + 0.15 * std::cos(2 * t), std::sin(t) - 0.1 * std::sin(3 * t),
                      0.2 * std::sin(2 * t));
    const Vec3 xt = R * Vec3(-std::sin(t) - 0.3 * std::sin(2 * t),
                             std::cos(t) - 0.3 * std::cos(3 * t), 0.4 * std::cos(2 * t));
    const Vec3 tan = xt.normalized();
    const Vec3 e1 = (z - z.dot(tan) * tan).normalized();
    const Vec3 e2 = tan.cross(e1);
    const double psi = turns * t + 0.3 * std::sin(t);
    Mat3 D;
    D.col(0) = std::cos(psi) * e1 + std::sin(psi) * e2;
    D.col(1) = -std::sin(psi) * e1 + std::cos(psi) * e2;
    D.col(2) = tan;
    s.D[k] = rotation(0.02 * Vec3(std::sin(2 * t), std::cos(t), 0.5 * std::sin(t))) * D;
  }
  return s;
}
inline double smooth_rod_length(double R) {
  const RodState s = smooth_rod(1 << 14, R, 0);
  double L = 0;
  for (int k = 0; k < s.size(); ++k) L += (s.X[(k + 1) % s.size()] - s.X[k]).norm();
  return L;
}

/// Nodal force and torque of s (fresh zeroed buffers).
struct Loads {
  std::vector<Vec3> F, T;
  ElasticEnergy E;
};
inline Loads loads(const RodParams& p, const RodState& s) {
  Loads l;
  l.F.assign(s.size(), Vec3::Zero());
  l.T.assign(s.size(), Vec3::Zero());
  RodWork w;
  l.E = elastic_forces(p, s, w, l.F, l.T);
  return l;
}

/// −∂E_h/∂θ at node k, where θ rotates triad k in the lab frame (D_k ← R(θ) D_k): fourth-order
/// central differences with step h (rad).
inline Vec3 fd_torque(const RodParams& p, RodState s, int k, double h) {
  const Mat3 D0 = s.D[k];
  auto E = [&](const Vec3& th) {
    s.D[k] = rotation(th) * D0;
    return elastic_energy(p, s).total();
  };
  Vec3 g;
  for (int j = 0; j < 3; ++j) {
    const Vec3 e = Vec3::Unit(j);
    g[j] = (8.0 * (E(h * e) - E(-h * e)) - (E(2 * h * e) - E(-2 * h * e))) / (12.0 * h);
  }
  return -g;
}

/// −∂E_h/∂X_k by second-order central differences with step h (Å); exact up to round-off
/// because E_h is quadratic in X for fixed triads.
inline Vec3 fd_force(const RodParams& p, RodState s, int k, double h) {
  const Vec3 X0 = s.X[k];
  Vec3 g;
  for (int j = 0; j < 3; ++j) {
    s.X[k] = X0 + h * Vec3::Unit(j);
    const double ep = elastic_energy(p, s).total();
    s.X[k] = X0 - h * Vec3::Unit(j);
    const double em = elastic_energy(p, s).total();
    g[j] = (ep - em) / (2.0 * h);
  }
  return -g;
}

}  // namespace ibrod::rod::test
