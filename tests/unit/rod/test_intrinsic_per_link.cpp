// Per-link intrinsic curvature and twist (RodParams::omega0_k, rod.intrinsic_file): the same
// discrete energy with Ω₀ varying along the rod.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "rod_test_util.hpp"

namespace ibrod::rod {
namespace {

double max_norm(const std::vector<Vec3>& v) {
  double m = 0;
  for (const Vec3& x : v) m = std::max(m, x.norm());
  return m;
}

// A per-link table holding the scalar values everywhere gives the scalar keys' forces, torques
// and energy bit for bit (closed and open).
TEST(IntrinsicPerLink, ConstantTableEqualsScalarBitwise) {
  for (bool closed : {true, false}) {
    RodParams p;
    p.n = 60;
    p.closed = closed;
    p.omega0 = Vec3(0.003, -0.002, 0.01);
    const RodState s = test::perturbed_circle(p, {}, 0.5, 0.1, 3);
    RodParams q = p;
    q.omega0_k.assign(p.n, p.omega0);
    q.omega0 = Vec3(0.5, 0.5, 0.5);  // must be ignored when the table is given
    const test::Loads a = test::loads(p, s), b = test::loads(q, s);
    for (int k = 0; k < p.n; ++k) {
      EXPECT_EQ(a.F[k], b.F[k]) << "closed " << closed << " point " << k;
      EXPECT_EQ(a.T[k], b.T[k]) << "closed " << closed << " point " << k;
    }
    EXPECT_EQ(a.E.bend, b.E.bend);
    EXPECT_EQ(a.E.twist, b.E.twist);
    EXPECT_EQ(a.E.stretch, b.E.stretch);
    EXPECT_EQ(elastic_energy(q, s).total(), b.E.total());
  }
}

// With Ω₀ varying along the rod (a sequence-like table), F_k = −∂E_h/∂X_k by central
// differences at every point, and the table changes the forces (it is used).
TEST(IntrinsicPerLink, ForceIsMinusEnergyGradientWithVaryingOmega0) {
  for (bool closed : {true, false}) {
    RodParams p;
    p.n = 40;
    p.closed = closed;
    const RodState s = test::perturbed_circle(p, {}, 0.5, 0.1, 5);
    p.omega0_k.resize(p.n);
    for (int k = 0; k < p.n; ++k)
      p.omega0_k[k] = Vec3(0.02 * std::sin(0.7 * k), 0.015 * std::cos(1.3 * k),
                           0.05 + 0.03 * std::sin(2.1 * k));
    const test::Loads l = test::loads(p, s);
    double err = 0;
    for (int k = 0; k < p.n; ++k)
      err = std::max(err, (test::fd_force(p, s, k, 1e-3) - l.F[k]).norm());
    err /= max_norm(l.F);
    std::printf("  per-link Ω₀, closed %d: max |F − F_fd| / max |F| = %.2e\n", int(closed), err);
    EXPECT_LT(err, 1e-9);
    RodParams mean = p;
    mean.omega0_k.clear();
    mean.omega0 = Vec3(0, 0, 0.05);
    EXPECT_GT(std::abs(elastic_energy(p, s).total() - elastic_energy(mean, s).total()),
              1e-3 * elastic_energy(p, s).total());
  }
}

TEST(IntrinsicPerLink, WrongTableSizeThrows) {
  RodParams p;
  p.n = 60;
  const RodState s = test::perturbed_circle(p, {}, 0.0, 0.0, 1);
  p.omega0_k.assign(59, Vec3::Zero());
  EXPECT_THROW(elastic_energy(p, s), std::invalid_argument);
  EXPECT_THROW(test::loads(p, s), std::invalid_argument);
}

}  // namespace
}  // namespace ibrod::rod
