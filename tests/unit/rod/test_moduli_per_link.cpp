// Per-link moduli (RodParams::a_k, b_k, rod.moduli_file): the same discrete energy with aᵢ, bᵢ
// varying along the rod; forces and torques still its gradients.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "rod_test_util.hpp"

namespace ibrod::rod {
namespace {

double max_norm(const std::vector<Vec3>& v) {
  double m = 0;
  for (const Vec3& x : v) m = std::max(m, x.norm());
  return m;
}

// Random per-link moduli, each a factor 0.3 to 3 of the scalar reference, every component drawn
// separately (a1 ≠ a2, b1 ≠ b2 ≠ b3).
void random_moduli(RodParams& p, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> f(std::log(0.3), std::log(3.0));
  p.a_k.resize(p.n);
  p.b_k.resize(p.n);
  for (int k = 0; k < p.n; ++k) {
    for (int i = 0; i < 3; ++i) {
      p.a_k[k][i] = p.a[i] * std::exp(f(rng));
      p.b_k[k][i] = p.b[i] * std::exp(f(rng));
    }
  }
}

// A table holding the scalars on every link gives the scalar moduli's forces, torques and energy
// bit for bit (closed and open).
TEST(ModuliPerLink, ConstantTableEqualsScalarBitwise) {
  for (bool closed : {true, false}) {
    RodParams p;
    p.n = 60;
    p.closed = closed;
    p.omega0 = Vec3(0.003, -0.002, 0.01);
    const RodState s = test::perturbed_circle(p, {}, 0.5, 0.1, 3);
    RodParams q = p;
    q.a_k.assign(p.n, p.a);
    q.b_k.assign(p.n, p.b);
    q.a = Vec3(1, 2, 3);  // must be ignored when the table is given
    q.b = Vec3(4, 5, 6);
    const test::Loads l1 = test::loads(p, s), l2 = test::loads(q, s);
    for (int k = 0; k < p.n; ++k) {
      EXPECT_EQ(l1.F[k], l2.F[k]) << "closed " << closed << " point " << k;
      EXPECT_EQ(l1.T[k], l2.T[k]) << "closed " << closed << " point " << k;
    }
    EXPECT_EQ(l1.E.bend, l2.E.bend);
    EXPECT_EQ(l1.E.twist, l2.E.twist);
    EXPECT_EQ(l1.E.stretch, l2.E.stretch);
    EXPECT_EQ(elastic_energy(q, s).total(), l2.E.total());
  }
}

// With random per-link moduli (and a per-link Ω₀): F_k = −∂E_h/∂X_k by central differences at
// every point, to round-off (E_h is quadratic in X); closed and open. The table is used: the
// scalar moduli give other forces.
TEST(ModuliPerLink, ForceIsMinusEnergyGradient) {
  for (bool closed : {true, false}) {
    RodParams p;
    p.n = 40;
    p.closed = closed;
    random_moduli(p, closed ? 7 : 8);
    p.omega0_k.resize(p.n);
    for (int k = 0; k < p.n; ++k)
      p.omega0_k[k] = Vec3(0.02 * std::sin(0.7 * k), 0.015 * std::cos(1.3 * k), 0.03);
    const RodState s = test::perturbed_circle(p, {}, 0.5, 0.1, 5);
    const test::Loads l = test::loads(p, s);
    double err = 0;
    for (int k = 0; k < p.n; ++k)
      err = std::max(err, (test::fd_force(p, s, k, 1e-3) - l.F[k]).norm());
    err /= max_norm(l.F);
    std::printf("  per-link moduli, closed %d: max |F − F_fd| / max |F| = %.2e\n", int(closed),
                err);
    EXPECT_LT(err, 1e-9);
    RodParams scalar = p;
    scalar.a_k.clear();
    scalar.b_k.clear();
    const test::Loads ls = test::loads(scalar, s);
    double d = 0;
    for (int k = 0; k < p.n; ++k) d = std::max(d, (ls.F[k] - l.F[k]).norm());
    EXPECT_GT(d, 0.1 * max_norm(l.F));
  }
}

// T_k against −∂E_h/∂θ_k: O(Δs²) relative, as with scalar moduli (test_forces.cpp,
// test_open_rod.cpp), when the moduli vary smoothly along the rod (each component a factor
// e^{±0.8} about the scalar, a different phase each): the smooth test curve sampled at n, 2n, 4n
// points, the error falls by about 4 each time; closed, and open (the first half of the curve).
double torque_error(int n, bool closed) {
  const double R = 100.0;
  const int n_full = closed ? n : 2 * n;
  RodParams p;
  p.n = n;
  p.closed = closed;
  p.ds = test::smooth_rod_length(R) / n_full;
  p.omega0 = Vec3(0.003, -0.002, 0.01);
  p.a_k.resize(n);
  p.b_k.resize(n);
  for (int k = 0; k < n; ++k) {
    const double t = 2 * test::pi * (k + 0.5) / n_full;
    for (int i = 0; i < 3; ++i) {
      p.a_k[k][i] = p.a[i] * std::exp(0.8 * std::sin(3 * t + i));
      p.b_k[k][i] = p.b[i] * std::exp(0.8 * std::cos(2 * t + i));
    }
  }
  const RodState full = test::smooth_rod(n_full, R, 4);
  RodState s;
  s.X.assign(full.X.begin(), full.X.begin() + n);
  s.D.assign(full.D.begin(), full.D.begin() + n);
  const test::Loads l = test::loads(p, s);
  double err = 0;
  for (int k = 0; k < n; k += std::max(1, n / 50))
    err = std::max(err, (test::fd_torque(p, s, k, 1e-4) - l.T[k]).norm());
  if (!closed)
    for (int k : {n - 2, n - 1})
      err = std::max(err, (test::fd_torque(p, s, k, 1e-4) - l.T[k]).norm());
  return err / max_norm(l.T);
}

TEST(ModuliPerLink, TorqueIsMinusRotationGradientToSecondOrder) {
  for (bool closed : {true, false}) {
    const int n = closed ? 200 : 100;
    const double e1 = torque_error(n, closed), e2 = torque_error(2 * n, closed),
                 e3 = torque_error(4 * n, closed);
    std::printf(
        "  per-link moduli, closed %d: rel. torque error n=%d %.3e, %d %.3e, %d %.3e; "
        "ratios %.3f %.3f\n",
        int(closed), n, e1, 2 * n, e2, 4 * n, e3, e1 / e2, e2 / e3);
    EXPECT_LT(e2, 1e-2);
    EXPECT_GT(e1 / e2, 3.0);
    EXPECT_LT(e1 / e2, 5.0);
    EXPECT_GT(e2 / e3, 3.0);
    EXPECT_LT(e2 / e3, 5.0);
  }
}

// The energy is the per-link formula E = (Δs/2) Σ_k [Σᵢ a_k,i (Ωᵢ − Ωᵢ₀)² + Σᵢ b_k,i Γᵢ²], with Ω
// and Γ of each link from the energy with unit moduli on that link alone (the energy is linear in
// the moduli): Σ_k Σ_i a_k,i e_k,i where e_k,i is the energy of unit modulus i on link k.
TEST(ModuliPerLink, EnergyIsThePerLinkSum) {
  for (bool closed : {true, false}) {
    RodParams p;
    p.n = 24;
    p.closed = closed;
    random_moduli(p, 11);
    CircleParams c;
    c.excess_link = 1;
    const RodState s = test::perturbed_circle(p, c, 0.4, 0.08, 9);
    const ElasticEnergy e = elastic_energy(p, s);
    const int m = half_points(p.n, closed);
    double bend = 0, twist = 0, stretch = 0;
    RodParams unit = p;
    for (int k = 0; k < m; ++k)
      for (int i = 0; i < 6; ++i) {
        unit.a_k.assign(p.n, Vec3::Zero());
        unit.b_k.assign(p.n, Vec3::Zero());
        (i < 3 ? unit.a_k[k][i] : unit.b_k[k][i - 3]) = 1.0;
        const ElasticEnergy u = elastic_energy(unit, s);  // (Δs/2) (Ω − Ω₀)² or (Δs/2) Γ²
        if (i < 2) bend += p.a_k[k][i] * u.bend;
        if (i == 2) twist += p.a_k[k][2] * u.twist;
        if (i >= 3) stretch += p.b_k[k][i - 3] * u.stretch;
      }
    EXPECT_NEAR(e.bend, bend, 1e-12 * e.total());
    EXPECT_NEAR(e.twist, twist, 1e-12 * e.total());
    EXPECT_NEAR(e.stretch, stretch, 1e-12 * e.total());
    // the open rod's last row is unused
    if (!closed) {
      RodParams q = p;
      q.a_k.back() *= 100;
      q.b_k.back() *= 100;
      EXPECT_EQ(elastic_energy(q, s).total(), e.total());
    }
  }
}

TEST(ModuliPerLink, WrongTableSizeThrows) {
  RodParams p;
  p.n = 60;
  const RodState s = test::perturbed_circle(p, {}, 0.0, 0.0, 1);
  RodParams q = p;
  q.a_k.assign(59, p.a);
  q.b_k.assign(60, p.b);
  EXPECT_THROW(elastic_energy(q, s), std::invalid_argument);
  EXPECT_THROW(test::loads(q, s), std::invalid_argument);
  q.a_k.assign(60, p.a);
  q.b_k.assign(61, p.b);
  EXPECT_THROW(elastic_energy(q, s), std::invalid_argument);
}

}  // namespace
}  // namespace ibrod::rod
