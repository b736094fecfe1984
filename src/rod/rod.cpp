// Rod mechanics: half-point triads, strains, internal force and moment, nodal force and torque on
// the fluid, energy, explicit update, twisted-circle initial condition (MODEL §3–§5).
#include "rod/rod.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/error.hpp"

namespace ibrod::rod {
namespace {

// Principal square root of the rotation A = D_{k+1} D_kᵀ applied to D_k (MODEL §4 step 1).
// A as a unit quaternion q = (cos φ/2, sin φ/2 u) with w ≥ 0 (so φ ∈ [0, π]); the half rotation is
// (cos φ/4, sin φ/4 u) ∝ (1 + w, x, y, z), which never degenerates because 1 + w ≥ 1.
inline Mat3 half_triad(const Mat3& Dk, const Mat3& Dk1) {
  const Mat3 A = Dk1 * Dk.transpose();
  Eigen::Quaterniond q(A);
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  Eigen::Quaterniond h(1.0 + q.w(), q.x(), q.y(), q.z());
  h.normalize();
  return h.toRotationMatrix() * Dk;
}

// Everything the rod defines at one half point k+½ (MODEL §4 steps 1–3).
struct HalfPoint {
  Mat3 Dh;  ///< D_{k+½}
  Vec3 Xp;  ///< X′_{k+½}, dimensionless
  Vec3 Fh;  ///< F_{k+½}, lab frame, g Å s⁻²
  Vec3 Nh;  ///< N_{k+½}, lab frame, g Å² s⁻²
  Vec3 E;   ///< (bend, twist, stretch) share of E_h from this half point, g Å² s⁻²
};

inline HalfPoint eval_half(const RodParams& p, int k, const Vec3& Xk, const Vec3& Xk1,
                           const Mat3& Dk, const Mat3& Dk1) {
  const double inv_ds = 1.0 / p.ds;
  HalfPoint h;
  h.Dh = half_triad(Dk, Dk1);
  // Strains in the half-point body frame, one-sided differences (MODEL §4 step 2).
  const Mat3 dD = (Dk1 - Dk) * inv_ds;
  const Vec3 omega(dD.col(1).dot(h.Dh.col(2)), dD.col(2).dot(h.Dh.col(0)),
                   dD.col(0).dot(h.Dh.col(1)));
  h.Xp = (Xk1 - Xk) * inv_ds;
  Vec3 gamma = h.Dh.transpose() * h.Xp;  // Γᵢ = Dⁱ·X′ − δᵢ₃
  gamma.z() -= 1.0;
  const Vec3 dom = omega - (p.omega0_k.empty() ? p.omega0 : p.omega0_k[k]);
  // Constitutive laws MODEL (2.5–2.8): body components, then to the lab frame.
  const Vec3 Nb = (p.a_k.empty() ? p.a : p.a_k[k]).cwiseProduct(dom);
  const Vec3 Fb = (p.b_k.empty() ? p.b : p.b_k[k]).cwiseProduct(gamma);
  h.Nh = h.Dh * Nb;
  h.Fh = h.Dh * Fb;
  // MODEL (2.13) discretised: E_h = (Δs/2) Σ [Σ bᵢΓᵢ² + Σ aᵢ(Ωᵢ − Ωᵢ₀)²].
  const double half_ds = 0.5 * p.ds;
  h.E = Vec3(half_ds * (Nb.x() * dom.x() + Nb.y() * dom.y()), half_ds * Nb.z() * dom.z(),
             half_ds * Fb.dot(gamma));
  return h;
}

void check_size(std::size_t got, int n, const char* what) {
  if (got != std::size_t(n))
    throw std::invalid_argument(std::string("rod: ") + what + " has " + std::to_string(got) +
                                " entries, the rod has " + std::to_string(n));
}

}  // namespace

Mat3 half_point_triad(const Mat3& Dk, const Mat3& Dk1) { return half_triad(Dk, Dk1); }

ElasticEnergy elastic_forces(const RodParams& p, const RodState& s, RodWork& w, std::span<Vec3> F,
                             std::span<Vec3> T) {
  const int n = s.size();
  check_size(s.D.size(), n, "D");
  check_size(F.size(), n, "F");
  check_size(T.size(), n, "T");
  if (!p.omega0_k.empty()) check_size(p.omega0_k.size(), n, "omega0_k");
  if (!p.a_k.empty()) check_size(p.a_k.size(), n, "a_k");
  if (!p.b_k.empty()) check_size(p.b_k.size(), n, "b_k");
  if (w.Dh.size() != std::size_t(n) || w.Fh.size() != std::size_t(n) ||
      w.Nh.size() != std::size_t(n) || w.Xp.size() != std::size_t(n) ||
      w.Eh.size() != std::size_t(n))
    w.resize(n);  // allocates once; every later call with the same n reuses it
  const double half_ds = 0.5 * p.ds;

  // Half points k+½ between k and k+1: n of them on a closed rod (cyclic), n − 1 on an open one
  // (its ends have no half point beyond them: free ends). One parallel region, two loops; below a
  // few hundred points the fork/join costs more than the work (at n = 600 one thread took 50 µs,
  // two 36 µs).
  const int m = half_points(n, p.closed);
#pragma omp parallel if (n >= 256)
  {
#pragma omp for schedule(static)
    for (int k = 0; k < m; ++k) {
      const int k1 = (k + 1 == n) ? 0 : k + 1;
      const HalfPoint h = eval_half(p, k, s.X[k], s.X[k1], s.D[k], s.D[k1]);
      w.Dh[k] = h.Dh;
      w.Xp[k] = h.Xp;
      w.Fh[k] = h.Fh;
      w.Nh[k] = h.Nh;
      w.Eh[k] = h.E;
    }
    // Nodes: Δs f_k and Δs n_k of MODEL §4 step 4 (the implicit barrier above orders the loops;
    // every thread takes the same branch).
    if (p.closed) {
#pragma omp for schedule(static)
      for (int k = 0; k < n; ++k) {
        const int km = (k == 0) ? n - 1 : k - 1;
        F[k] += w.Fh[k] - w.Fh[km];
        T[k] += w.Nh[k] - w.Nh[km] + half_ds * (w.Xp[k].cross(w.Fh[k]) + w.Xp[km].cross(w.Fh[km]));
      }
    } else {
#pragma omp for schedule(static)
      for (int k = 0; k < n; ++k) {
        Vec3 f = Vec3::Zero(), t = Vec3::Zero();
        if (k < m) {
          f += w.Fh[k];
          t += w.Nh[k] + half_ds * w.Xp[k].cross(w.Fh[k]);
        }
        if (k > 0) {
          f -= w.Fh[k - 1];
          t += -w.Nh[k - 1] + half_ds * w.Xp[k - 1].cross(w.Fh[k - 1]);
        }
        F[k] += f;
        T[k] += t;
      }
    }
  }

  // Serial sum in index order: the energy does not depend on the thread count, and equals
  // elastic_energy() bit for bit.
  Vec3 e = Vec3::Zero();
  for (int k = 0; k < m; ++k) e += w.Eh[k];
  return {e.x(), e.y(), e.z()};
}

ElasticEnergy elastic_energy(const RodParams& p, const RodState& s) {
  const int n = s.size();
  check_size(s.D.size(), n, "D");
  if (!p.omega0_k.empty()) check_size(p.omega0_k.size(), n, "omega0_k");
  if (!p.a_k.empty()) check_size(p.a_k.size(), n, "a_k");
  if (!p.b_k.empty()) check_size(p.b_k.size(), n, "b_k");
  Vec3 e = Vec3::Zero();
  for (int k = 0; k < half_points(n, p.closed); ++k) {
    const int k1 = (k + 1 == n) ? 0 : k + 1;
    e += eval_half(p, k, s.X[k], s.X[k1], s.D[k], s.D[k1]).E;
  }
  return {e.x(), e.y(), e.z()};
}

void advance(RodState& s, std::span<const Vec3> U, std::span<const Vec3> W, double dt) {
  const int n = s.size();
  check_size(s.D.size(), n, "D");
  check_size(U.size(), n, "U");
  check_size(W.size(), n, "W");
  // MODEL §4 "Rod update": a rotation (not D += dt W×D) keeps each triad orthonormal.
  for (int k = 0; k < n; ++k) {
    s.X[k] += dt * U[k];
    s.D[k] = rotation(dt * W[k]) * s.D[k];
  }
}

RodState initial_shape(const RodParams& p, const CircleParams& c) {
  return p.closed ? twisted_circle(p, c) : straight_rod(p, c.perturbation, c.center);
}

double circle_radius(int n, double ds) { return n * ds / (2.0 * std::numbers::pi); }

double circle_tilt_sin_beta(double a1, double a3, double b1, double r0, double excess_link) {
  // MODEL §5: the tilt β of D³ out of the plane that balances twist against shear
  return -a3 * excess_link / (b1 * r0 * r0 + a3 - a1);
}

RodState straight_rod(const RodParams& p, const std::vector<double>& eps, const Vec3& center) {
  const int n = p.n;
  if (n < 2) throw ConfigError("rod: straight_rod needs n >= 2 points, got " + std::to_string(n));
  if (!(p.ds > 0)) throw ConfigError("rod: straight_rod needs ds > 0 Å");
  constexpr double two_pi = 2.0 * std::numbers::pi;
  RodState s;
  s.X.resize(n);
  s.D.resize(n);
  const Vec3 y(0.0, 1.0, 0.0), z(0.0, 0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    double psi = 0;  // the circle's perturbation g(s), s/r0 = 2π k/n
    for (std::size_t m = 0; m < eps.size(); ++m)
      psi += eps[m] * std::sin(double(m + 1) * two_pi * k / n);
    s.D[k].col(0) = std::cos(psi) * y + std::sin(psi) * z;
    s.D[k].col(1) = -std::sin(psi) * y + std::cos(psi) * z;
    s.D[k].col(2) = Vec3(1.0, 0.0, 0.0);
    s.X[k] = center + Vec3((k - 0.5 * (n - 1)) * p.ds, 0.0, 0.0);
  }
  return s;
}

RodState twisted_circle(const RodParams& p, const CircleParams& c) {
  const int n = p.n;
  if (n < 3) throw ConfigError("rod: twisted_circle needs n >= 3 points, got " + std::to_string(n));
  if (!(p.ds > 0)) throw ConfigError("rod: twisted_circle needs ds > 0 Å");
  constexpr double two_pi = 2.0 * std::numbers::pi;
  const double r0 = circle_radius(n, p.ds);  // Å
  const double dlk = c.excess_link;
  const double sin_b = circle_tilt_sin_beta(p.a.x(), p.a.z(), p.b.x(), r0, dlk);
  if (!(std::abs(sin_b) <= 1.0))
    throw ConfigError("rod: twisted_circle with excess_link " + std::to_string(c.excess_link) +
                      " gives |sin beta| = " + std::to_string(std::abs(sin_b)) + " > 1");
  const double cos_b = std::sqrt(1.0 - sin_b * sin_b);
  const Vec3 z(0.0, 0.0, 1.0);

  RodState s;
  s.X.resize(n);
  s.D.resize(n);
  for (int k = 0; k < n; ++k) {
    const double th = two_pi * k / n;  // s/r0 with s = k Δs
    const Vec3 rh(std::cos(th), std::sin(th), 0.0);
    const Vec3 thh(-std::sin(th), std::cos(th), 0.0);
    double psi = dlk * th;  // ψ = ΔLk s/r0 + g(s)
    for (std::size_t m = 0; m < c.perturbation.size(); ++m)
      psi += c.perturbation[m] * std::sin(double(m + 1) * th);
    const Vec3 d3 = cos_b * thh + sin_b * z;
    const Vec3 e = -sin_b * thh + cos_b * z;
    // (E, r̂, D³) is right-handed (E × r̂ = D³), so rotating E, r̂ by ψ about D³ keeps D¹×D² = D³.
    s.D[k].col(0) = std::cos(psi) * e + std::sin(psi) * rh;
    s.D[k].col(1) = -std::sin(psi) * e + std::cos(psi) * rh;
    s.D[k].col(2) = d3;
    s.X[k] = c.center + r0 * cos_b * rh;
  }
  return s;
}

}  // namespace ibrod::rod
