// The open rod (RodParams::closed = false; docs/model.md "Open rods"): free ends, force- and
// torque-free, n − 1 half points; the straight initial shape.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "rod_test_util.hpp"

namespace ibrod::rod {
namespace {

RodParams open_params(int n) {
  RodParams p;
  p.n = n;
  p.closed = false;
  p.omega0 = Vec3(0.003, -0.002, 0.01);  // Å⁻¹: the intrinsic-strain terms too
  return p;
}

/// An open rod far from any equilibrium: a random walk of steps about Δs with random triads
/// near the walk's tangent, off the origin so that X × F is not small.
RodState random_open_rod(const RodParams& p, unsigned seed) {
  std::mt19937_64 rng(seed);
  RodState s = straight_rod(p, {}, Vec3(300.0, -150.0, 80.0));
  Vec3 x = s.X[0];
  for (int k = 0; k < p.n; ++k) {
    s.X[k] = x;
    s.D[k] = rotation(test::random_vec(rng, 0.6)) * rotation(Vec3(0.0, 0.05 * k, 0.0)) * s.D[k];
    x += rotation(Vec3(0.0, 0.05 * k, 0.0)) * Vec3(p.ds, 0.0, 0.0) + test::random_vec(rng, 0.8);
  }
  return s;
}

double max_norm(const std::vector<Vec3>& v) {
  double m = 0;
  for (const Vec3& x : v) m = std::max(m, x.norm());
  return m;
}

// Newton's third law for the open rod: the internal forces and moments exert no net force and no
// net torque (about the origin) on the fluid.
TEST(OpenRod, ConservesTotalForceAndTorque) {
  const RodParams p = open_params(120);
  double worst_f = 0, worst_t = 0;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const RodState s = random_open_rod(p, seed);
    const test::Loads l = test::loads(p, s);
    Vec3 f = Vec3::Zero(), t = Vec3::Zero();
    double fscale = 0, tscale = 0;
    for (int k = 0; k < s.size(); ++k) {
      f += l.F[k];
      t += l.T[k] + s.X[k].cross(l.F[k]);
      fscale += l.F[k].norm();
      tscale += l.T[k].norm() + s.X[k].norm() * l.F[k].norm();
    }
    ASSERT_GT(fscale, 0);
    worst_f = std::max(worst_f, f.norm() / fscale);
    worst_t = std::max(worst_t, t.norm() / tscale);
  }
  std::printf("  open: |ΣF|/Σ|F| = %.2e, |Σ(T + X×F)|/Σ(|T| + |X||F|) = %.2e\n", worst_f, worst_t);
  EXPECT_LT(worst_f, 1e-14);
  EXPECT_LT(worst_t, 1e-14);
}

// F_k = −∂E_h/∂X_k exactly at every point, the two free ends included: no force from a missing
// neighbour (the closed rod's closing link would put a force of order b3 |X_{n−1} − X_0|/Δs on
// both ends, which the finite differences of the open energy do not see).
TEST(OpenRod, ForceIsMinusEnergyGradientIncludingTheEnds) {
  const RodParams p = open_params(40);
  const RodState s = random_open_rod(p, 7);
  const test::Loads l = test::loads(p, s);
  double err = 0;
  for (int k = 0; k < p.n; ++k)
    err = std::max(err, (test::fd_force(p, s, k, 1e-3) - l.F[k]).norm());
  err /= max_norm(l.F);
  std::printf("  open: max |F − F_fd| / max |F| = %.2e (all points)\n", err);
  EXPECT_LT(err, 1e-9);
  // the end points carry only their one half point: F_0 = F_½, F_{n−1} = −F_{n−3/2}
  RodParams closed = p;
  closed.closed = true;
  const test::Loads c = test::loads(closed, s);
  EXPECT_GT((c.F[0] - l.F[0]).norm(), 1e3 * err * max_norm(l.F));  // the closing link differs
}

// At the free ends T_k is the negative rotation gradient of E_h to O(Δs²) like everywhere else:
// a smooth open curve sampled at n and 2n points, the end torques' relative error falls by ~4.
double end_torque_error(int n) {
  RodParams p = open_params(n);
  p.omega0 = Vec3(0.003, -0.002, 0.01);
  const double R = 100.0;
  // the first half of the smooth closed test curve, as an open rod
  const RodState full = test::smooth_rod(2 * n, R, 4);
  RodState s;
  s.X.assign(full.X.begin(), full.X.begin() + n);
  s.D.assign(full.D.begin(), full.D.begin() + n);
  p.ds = test::smooth_rod_length(R) / (2 * n);
  const test::Loads l = test::loads(p, s);
  double err = 0;
  for (int k : {0, 1, n - 2, n - 1})
    err = std::max(err, (test::fd_torque(p, s, k, 1e-4) - l.T[k]).norm());
  return err / max_norm(l.T);
}

TEST(OpenRod, EndTorqueIsMinusRotationGradientToSecondOrder) {
  const double e1 = end_torque_error(100), e2 = end_torque_error(200), e3 = end_torque_error(400);
  std::printf("  open ends: rel. torque error n=100 %.3e, 200 %.3e, 400 %.3e; ratios %.3f %.3f\n",
              e1, e2, e3, e1 / e2, e2 / e3);
  EXPECT_LT(e2, 5e-3);
  EXPECT_GT(e1 / e2, 3.0);
  EXPECT_LT(e1 / e2, 5.0);
  EXPECT_GT(e2 / e3, 3.0);
  EXPECT_LT(e2 / e3, 5.0);
}

// The straight open rod with no intrinsic strain is stress-free: zero energy and (to round-off of
// its positions) zero loads at every point, the ends included; as a closed rod the same points
// would be pulled together by the closing link.
TEST(OpenRod, StraightRodIsStressFree) {
  RodParams p = open_params(64);
  p.omega0 = Vec3::Zero();
  const RodState s = straight_rod(p, {}, Vec3(100.0, 100.0, 100.0));
  const test::Loads l = test::loads(p, s);
  const double kT = test::kT;
  EXPECT_LT(l.E.total(), 1e-20 * kT);
  // unit force scale: b3 × 1 (a 100 % strain) ≈ 5e3 g Å s⁻²
  EXPECT_LT(max_norm(l.F), 1e-9 * p.b.z());
  EXPECT_LT(max_norm(l.T), 1e-9 * p.b.z() * p.ds);
  for (int k = 0; k < p.n; ++k) {
    EXPECT_NEAR(s.X[k].y(), 100.0, 0.0);
    EXPECT_LT((s.D[k].transpose() * s.D[k] - Mat3::Identity()).norm(), 1e-15);
    EXPECT_NEAR(s.D[k].determinant(), 1.0, 1e-15);
  }
  EXPECT_NEAR(0.5 * (s.X.front().x() + s.X.back().x()), 100.0, 1e-12);  // centred
  EXPECT_NEAR(s.X.back().x() - s.X.front().x(), (p.n - 1) * p.ds, 1e-9);
  RodParams closed = p;
  closed.closed = true;
  EXPECT_GT(elastic_energy(closed, s).total(), 1e3 * kT);
}

// The twist perturbation of the circle turns an open rod's triads about its axis by the same ψ_k.
TEST(OpenRod, StraightRodCarriesTheTwistPerturbation) {
  RodParams p = open_params(50);
  const RodState s = straight_rod(p, {0.4, 0.1}, Vec3::Zero());
  for (int k = 0; k < p.n; ++k) {
    const double th = 2 * test::pi * k / p.n;
    const double psi = 0.4 * std::sin(th) + 0.1 * std::sin(2 * th);
    EXPECT_NEAR(s.D[k].col(0).y(), std::cos(psi), 1e-14);
    EXPECT_NEAR(s.D[k].col(0).z(), std::sin(psi), 1e-14);
    EXPECT_NEAR(s.D[k].col(2).x(), 1.0, 0.0);
  }
  EXPECT_THROW(straight_rod(open_params(1), {}, Vec3::Zero()), std::exception);
}

}  // namespace
}  // namespace ibrod::rod
