// The slithering that the Hessian stability test projects out (sim/stability.hpp): sliding a
// closed uniform rod's material along its own contour leaves the smooth rod's energy unchanged, so
// along the discrete slithering vector the discrete energy's slope is the discretisation error's,
// falling as Δs², even at a state far from equilibrium — the triads' transport included (the
// positions' part alone gives an O(1) slope). Measured (n = 100, 200, 400): slope 1.5e-1, 2.6e-2,
// 4.7e-3 g Å s⁻² against |∇E| 2.5e3–4.3e3, and 13.6, 9.6, 6.8 for the positions' part alone.
// A rod with per-link moduli is not slither-invariant, nor is an open rod.
#include <gtest/gtest.h>

#include <cmath>

#include "../rod/rod_test_util.hpp"
#include "sim/stability.hpp"

namespace ibrod::sim {
namespace {

using rod::test::smooth_rod;
using rod::test::smooth_rod_length;

constexpr double kR = 60;  // Å

struct Along {
  double slope;     ///< dE/dε along a unit vector, g Å s⁻²
  double gradient;  ///< |∇E| in the same coordinates (δX, ℓδθ)
};

// dE/dε along the unit vector v (coordinates (δX, ℓδθ) per point), central differences, step h.
Along along(const rod::RodParams& p, const rod::RodState& s, Eigen::VectorXd v, double h) {
  v.normalize();
  const double ell = p.ds;
  auto E = [&](double e) {
    rod::RodState q = s;
    for (int k = 0; k < s.size(); ++k) {
      q.X[std::size_t(k)] += e * v.segment<3>(6 * k);
      q.D[std::size_t(k)] = rotation(e / ell * v.segment<3>(6 * k + 3)) * s.D[std::size_t(k)];
    }
    return rod::elastic_energy(p, q).total();
  };
  const double Ep = E(h), Em = E(-h);
  const rod::test::Loads l = rod::test::loads(p, s);
  double g2 = 0;
  for (int k = 0; k < s.size(); ++k)
    g2 += l.F[std::size_t(k)].squaredNorm() + (l.T[std::size_t(k)] / ell).squaredNorm();
  return {(Ep - Em) / (2 * h), std::sqrt(g2)};
}

rod::RodParams uniform_rod(int n) {
  rod::RodParams p;
  p.n = n;
  p.ds = smooth_rod_length(kR) / n;
  return p;
}

TEST(Slithering, IsANearInvarianceOfAUniformRingConvergingAsDsSquared) {
  double prev_slope = 0;
  for (const int n : {100, 200, 400}) {
    const rod::RodParams p = uniform_rod(n);
    ASSERT_TRUE(slither_invariant(p));
    const rod::RodState s = smooth_rod(n, kR, 3);
    const Eigen::VectorXd v = slithering_vector(s, rod::RodRange{0, n, true, p.ds}, p.ds);
    const Along sl = along(p, s, v, 1e-3);
    // the state is far from any equilibrium (|∇E| is large) but the slope along slithering is the
    // discretisation error's
    EXPECT_LT(std::abs(sl.slope), 1e-4 * sl.gradient) << "n " << n;
    // (the curvature along it is not small here: along a straight line in the direction of an
    // invariance d²E/dε² = −∇E·γ'' with γ the curved orbit, O(|∇E|) away from equilibrium — why the
    // stability test projects the invariances out rather than expecting their eigenvalues near 0)
    // the triads' transport matters: the positions' part alone changes E at first order
    Eigen::VectorXd pos = v;
    for (int k = 0; k < n; ++k) pos.segment<3>(6 * k + 3).setZero();
    EXPECT_GT(std::abs(along(p, s, pos, 1e-3).slope), 20 * std::abs(sl.slope)) << "n " << n;
    if (prev_slope != 0) {  // second order in Δs
      EXPECT_GT(std::abs(prev_slope / sl.slope), 3.0) << "n " << n;
    }
    prev_slope = sl.slope;
  }
}

TEST(Slithering, OnlyAClosedUniformRodIsSlitherInvariant) {
  rod::RodParams p = uniform_rod(50);
  EXPECT_TRUE(slither_invariant(p));
  p.a_k.assign(50, p.a);  // per-link moduli, all equal: still uniform
  EXPECT_TRUE(slither_invariant(p));
  p.a_k[7] = 1.1 * p.a;
  EXPECT_FALSE(slither_invariant(p));
  p.a_k.clear();
  p.omega0_k.assign(50, Vec3::Zero());
  p.omega0_k[3] = Vec3(0, 0, 0.01);
  EXPECT_FALSE(slither_invariant(p));
  p.omega0_k.clear();
  p.closed = false;
  EXPECT_FALSE(slither_invariant(p));
}

// a rod's slithering vector vanishes outside its own points, and its cyclic neighbours stay
// within the rod
TEST(Slithering, TheVectorOfOneRodOfSeveralTouchesOnlyItsPoints) {
  const int n = 40;
  const rod::RodState a = smooth_rod(n, kR, 2);
  rod::RodState two = a;
  for (int k = 0; k < n; ++k) {
    two.X.push_back(a.X[std::size_t(k)] + Vec3(500, 0, 0));
    two.D.push_back(a.D[std::size_t(k)]);
  }
  const double ds = 1.0;
  const Eigen::VectorXd v1 = slithering_vector(a, rod::RodRange{0, n, true, ds}, ds);
  const Eigen::VectorXd v2 = slithering_vector(two, rod::RodRange{n, n, true, ds}, ds);
  EXPECT_EQ(v2.head(6 * n).norm(), 0.0);
  EXPECT_LT((v2.tail(6 * n) - v1).norm(), 1e-12 * v1.norm());
}

}  // namespace
}  // namespace ibrod::sim
