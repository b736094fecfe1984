// Elastic force, torque and energy of the discrete rod (MODEL §4 steps 1–4, (2.13)).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "rod_test_util.hpp"

namespace ibrod::rod {
namespace {

using test::Loads;
using test::loads;

// Slow direct transcription of MODEL §4, the oracle for elastic_forces: A = Σᵢ Dⁱ_{k+1}(Dⁱ_k)ᵀ,
// its root via the angle–axis form, strains and constitutive laws component by component.
Loads oracle(const RodParams& p, const RodState& s) {
  const int n = s.size();
  std::vector<Mat3> Dh(n);
  std::vector<Vec3> Fh(n), Nh(n), Xp(n);
  Loads l;
  l.F.assign(n, Vec3::Zero());
  l.T.assign(n, Vec3::Zero());
  for (int k = 0; k < n; ++k) {
    const int k1 = (k + 1) % n;
    Mat3 A = Mat3::Zero();
    for (int i = 0; i < 3; ++i) A += s.D[k1].col(i) * s.D[k].col(i).transpose();
    const Eigen::AngleAxisd aa(A);
    Dh[k] = Eigen::AngleAxisd(0.5 * aa.angle(), aa.axis()).toRotationMatrix() * s.D[k];
    auto d = [&](int i) { return (s.D[k1].col(i) - s.D[k].col(i)) / p.ds; };
    const double O1 = d(1).dot(Dh[k].col(2)), O2 = d(2).dot(Dh[k].col(0)),
                 O3 = d(0).dot(Dh[k].col(1));
    Xp[k] = (s.X[k1] - s.X[k]) / p.ds;
    const double G1 = Dh[k].col(0).dot(Xp[k]), G2 = Dh[k].col(1).dot(Xp[k]),
                 G3 = Dh[k].col(2).dot(Xp[k]) - 1.0;
    Nh[k] = p.a[0] * (O1 - p.omega0[0]) * Dh[k].col(0) +
            p.a[1] * (O2 - p.omega0[1]) * Dh[k].col(1) + p.a[2] * (O3 - p.omega0[2]) * Dh[k].col(2);
    Fh[k] = p.b[0] * G1 * Dh[k].col(0) + p.b[1] * G2 * Dh[k].col(1) + p.b[2] * G3 * Dh[k].col(2);
    l.E.bend += 0.5 * p.ds *
                (p.a[0] * std::pow(O1 - p.omega0[0], 2) + p.a[1] * std::pow(O2 - p.omega0[1], 2));
    l.E.twist += 0.5 * p.ds * p.a[2] * std::pow(O3 - p.omega0[2], 2);
    l.E.stretch += 0.5 * p.ds * (p.b[0] * G1 * G1 + p.b[1] * G2 * G2 + p.b[2] * G3 * G3);
  }
  for (int k = 0; k < n; ++k) {
    const int km = (k + n - 1) % n;
    l.F[k] = Fh[k] - Fh[km];
    l.T[k] = Nh[k] - Nh[km] + 0.5 * p.ds * (Xp[k].cross(Fh[k]) + Xp[km].cross(Fh[km]));
  }
  return l;
}

double max_norm(const std::vector<Vec3>& v) {
  double m = 0;
  for (const Vec3& x : v) m = std::max(m, x.norm());
  return m;
}
double max_diff(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double m = 0;
  for (std::size_t k = 0; k < a.size(); ++k) m = std::max(m, (a[k] - b[k]).norm());
  return m;
}

RodParams with_intrinsic(RodParams p) {
  p.omega0 = Vec3(0.003, -0.002, 0.01);  // Å⁻¹: exercises the intrinsic-strain terms
  return p;
}

TEST(ElasticForces, MatchesDirectTranscriptionOfModel) {
  const RodParams p = with_intrinsic(RodParams{});
  const RodState s = test::perturbed_circle(p, {}, 0.5, 0.1, 1);
  const Loads fast = loads(p, s), slow = oracle(p, s);
  EXPECT_LT(max_diff(fast.F, slow.F), 1e-12 * max_norm(slow.F));
  EXPECT_LT(max_diff(fast.T, slow.T), 1e-12 * max_norm(slow.T));
  EXPECT_NEAR(fast.E.bend, slow.E.bend, 1e-12 * slow.E.bend);
  EXPECT_NEAR(fast.E.twist, slow.E.twist, 1e-12 * slow.E.twist);
  EXPECT_NEAR(fast.E.stretch, slow.E.stretch, 1e-12 * slow.E.stretch);
}

TEST(ElasticForces, AccumulatesAndReusesWork) {
  RodParams p;
  p.n = 50;
  const RodState s = test::perturbed_circle(p, {}, 0.3, 0.05, 2);
  const Loads ref = loads(p, s);
  std::vector<Vec3> F(p.n, Vec3(1, 2, 3)), T(p.n, Vec3(-4, 5, 6));
  RodWork w;  // empty: elastic_forces sizes it
  elastic_forces(p, s, w, F, T);
  const ElasticEnergy e = elastic_forces(p, s, w, F, T);  // second call adds again
  for (int k = 0; k < p.n; ++k) {
    EXPECT_LT((F[k] - Vec3(1, 2, 3) - 2 * ref.F[k]).norm(), 1e-9);
    EXPECT_LT((T[k] - Vec3(-4, 5, 6) - 2 * ref.T[k]).norm(), 1e-9);
  }
  EXPECT_EQ(int(w.Fh.size()), p.n);
  // The energy is summed in index order in both entry points: equal bit for bit.
  const ElasticEnergy e2 = elastic_energy(p, s);
  EXPECT_EQ(e.bend, e2.bend);
  EXPECT_EQ(e.twist, e2.twist);
  EXPECT_EQ(e.stretch, e2.stretch);
  std::vector<Vec3> short_buf(p.n - 1);
  EXPECT_THROW(elastic_forces(p, s, w, short_buf, T), std::invalid_argument);
}

// Newton's third law for the rod as a whole (MODEL §4 step 4): the internal forces and moments
// exert no net force and no net torque about the origin on the fluid, for any configuration.
TEST(ElasticForces, ConserveTotalForceAndTorque) {
  const RodParams p = with_intrinsic(RodParams{});
  CircleParams c;
  c.center = Vec3(300.0, -150.0, 80.0);  // off the origin: X × F is not small
  double worst_f = 0, worst_t = 0;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    for (const RodState& s :
         {test::perturbed_circle(p, c, 2.0, 0.3, seed), test::smooth_rod(p.n, 150.0, 5)}) {
      const Loads l = loads(p, s);
      Vec3 f = Vec3::Zero(), t = Vec3::Zero();
      double fscale = 0, tscale = 0;
      for (int k = 0; k < s.size(); ++k) {
        f += l.F[k];
        t += l.T[k] + s.X[k].cross(l.F[k]);
        fscale += l.F[k].norm();
        tscale += l.T[k].norm() + s.X[k].norm() * l.F[k].norm();
      }
      worst_f = std::max(worst_f, f.norm() / fscale);
      worst_t = std::max(worst_t, t.norm() / tscale);
    }
  }
  std::printf("  |ΣF|/Σ|F| = %.2e, |Σ(T + X×F)|/Σ(|T| + |X||F|) = %.2e\n", worst_f, worst_t);
  EXPECT_LT(worst_f, 1e-14);  // measured 4.0e-16
  EXPECT_LT(worst_t, 1e-14);  // measured 9.4e-17
}

// F_k = −∂E_h/∂X_k exactly (MODEL §4 step 4).
TEST(ElasticForces, ForceIsMinusEnergyGradient) {
  const RodParams p = with_intrinsic(RodParams{});
  const RodState s = test::perturbed_circle(p, {}, 0.5, 0.1, 4);
  const Loads l = loads(p, s);
  double err = 0;
  for (int k = 0; k < s.size(); k += 7)
    err = std::max(err, (test::fd_force(p, s, k, 1e-3) - l.F[k]).norm());
  err /= max_norm(l.F);
  std::printf("  max |F − F_fd| / max |F| = %.2e\n", err);
  EXPECT_LT(err, 1e-9);  // measured 2.0e-11 (round-off of E_h over h; E_h is quadratic in X)
}

// T_k agrees with −∂E_h/∂θ_k to O(Δs²) relative (MODEL §4 step 4). Same smooth rod sampled at
// n and 2n: the relative error must fall by about 4.
double torque_error(RodParams p, int n, double R, int turns) {
  p.n = n;
  p.ds = test::smooth_rod_length(R) / n;
  const RodState s = test::smooth_rod(n, R, turns);
  const Loads l = loads(p, s);
  double err = 0;
  for (int k = 0; k < n; k += n / 50)
    err = std::max(err, (test::fd_torque(p, s, k, 1e-4) - l.T[k]).norm());
  return err / max_norm(l.T);
}

TEST(ElasticForces, TorqueIsMinusRotationGradientToSecondOrder) {
  const double R = 100.0;  // Å
  RodParams bend_only;     // no shear/stretch: the moment N alone
  bend_only.b = Vec3::Zero();
  const RodParams full = with_intrinsic(RodParams{});
  for (const RodParams& p : {bend_only, full}) {
    const double e1 = torque_error(p, 200, R, 4), e2 = torque_error(p, 400, R, 4),
                 e3 = torque_error(p, 800, R, 4);
    std::printf("  b = %g: rel. torque error n=200 %.3e, 400 %.3e, 800 %.3e; ratios %.3f %.3f\n",
                p.b.x(), e1, e2, e3, e1 / e2, e2 / e3);
    // measured: b = 0: 4.64e-3, 1.16e-3, 2.91e-4 (ratios 3.99, 4.00);
    //           b = 5e3: 4.19e-3, 1.04e-3, 2.58e-4 (ratios 4.04, 4.01)
    EXPECT_LT(e2, 2e-3);
    EXPECT_GT(e1 / e2, 3.0);
    EXPECT_LT(e1 / e2, 5.0);
    EXPECT_GT(e2 / e3, 3.0);
    EXPECT_LT(e2 / e3, 5.0);
  }
}

// E_h depends only on the shape: invariant under a rigid motion of the whole rod.
TEST(ElasticEnergy, InvariantUnderRigidMotion) {
  const RodParams p = with_intrinsic(RodParams{});
  RodState s = test::perturbed_circle(p, {}, 0.5, 0.1, 5);
  const ElasticEnergy e0 = elastic_energy(p, s);
  const Mat3 Q = rotation(Vec3(0.7, -1.9, 2.4));
  const Vec3 shift(123.0, -45.6, 7.89);
  for (int k = 0; k < s.size(); ++k) {
    s.X[k] = Q * s.X[k] + shift;
    s.D[k] = Q * s.D[k];
  }
  const ElasticEnergy e1 = elastic_energy(p, s);
  EXPECT_NEAR(e1.bend, e0.bend, 1e-11 * e0.bend);
  EXPECT_NEAR(e1.twist, e0.twist, 1e-11 * e0.twist);
  EXPECT_NEAR(e1.stretch, e0.stretch, 1e-11 * e0.stretch);
}

// E_h ≥ 0 vanishes in the stress-free state. A closed rod with zero intrinsic strain has none, so
// use an untwisted circle (β = 0, D³ tangent at the half points) with Ω₀ set to its own uniform
// strains and Δs equal to its chord length: then every strain equals its intrinsic value.
TEST(ElasticEnergy, ZeroInItsOwnIntrinsicShape) {
  RodParams p;
  p.n = 60;
  CircleParams c;
  c.excess_link = 0;
  c.perturbation = {};
  const RodState s = twisted_circle(p, c);
  p.ds = (s.X[1] - s.X[0]).norm();  // Γ₃ = |X′| − 1 = 0
  RodWork w;
  std::vector<Vec3> F(p.n, Vec3::Zero()), T(p.n, Vec3::Zero());
  const ElasticEnergy e0 = elastic_forces(p, s, w, F, T);
  EXPECT_GT(e0.bend, 1e3);                                        // a genuinely bent rod
  p.omega0 = (w.Dh[0].transpose() * w.Nh[0]).cwiseQuotient(p.a);  // Ω body components at ½
  const ElasticEnergy e = elastic_energy(p, s);
  EXPECT_LT(e.bend + e.twist, 1e-20);
  EXPECT_LT(e.stretch, 1e-20);
}

}  // namespace
}  // namespace ibrod::rod
