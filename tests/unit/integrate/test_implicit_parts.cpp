// Unit tests of the parts of the implicit scheme (issue 14): the Gauss–Newton stiffness (analytic
// small-strain form against finite differences; symmetric, positive semi-definite), the Stokes
// mobility (symmetric, positive), undo(). 16³, 60-point ring: well under a second. Any collection
// of rods (issue 25): an open rod's K has no link past its ends, several rods' K is block-diagonal
// (each rod's alone), and the block solver gives the sparse Cholesky's step on both.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>

#include "config/config.hpp"
#include "integrate/implicit.hpp"
#include "sim/simulation.hpp"

namespace ibrod::integrate {
namespace {

struct Ring {
  sim::SimParams p;
  rod::RodState rod;
  std::unique_ptr<System> st;
  explicit Ring(int excess_link = 2, bool per_link_moduli = false) {
    config::Config c;
    c.grid_n = 16;
    c.grid_box_A = 200;
    c.rod_base_pairs = 60;
    c.rod_excess_link = excess_link;
    c.run_threads = 1;
    c.run_fftw_measure = false;
    p = config::to_params(c);
    if (per_link_moduli) {
      // rod.moduli_file's RodParams: each modulus of each link a factor 1/3 to 3 of the scalar
      rod::RodParams& r = p.stepper.rods[0];
      std::mt19937_64 g(23);
      std::uniform_real_distribution<double> f(std::log(1.0 / 3), std::log(3.0));
      r.a_k.resize(r.n);
      r.b_k.resize(r.n);
      for (int k = 0; k < r.n; ++k)
        for (int i = 0; i < 3; ++i) {
          r.a_k[k][i] = r.a[i] * std::exp(f(g));
          r.b_k[k][i] = r.b[i] * std::exp(f(g));
        }
    }
    rod = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
    // a generic, strained state: random displacements (0.3 Å) and rotations (0.05 rad)
    std::mt19937_64 rng(11);
    std::normal_distribution<double> N(0, 1);
    for (int k = 0; k < rod.size(); ++k) {
      rod.X[k] += 0.3 * Vec3(N(rng), N(rng), N(rng));
      rod.D[k] = rotation(0.05 * Vec3(N(rng), N(rng), N(rng))) * rod.D[k];
    }
    st = std::make_unique<System>(p.stepper);
  }
};

Eigen::MatrixXd dense_K(Ring& s, bool fd) {
  ImplicitParams ip;
  ip.stiffness_fd = fd;
  ImplicitStepper imp(*s.st, ip);
  return Eigen::MatrixXd(imp.stiffness(s.rod));
}

TEST(ImplicitStiffness, AnalyticGaussNewtonMatchesFiniteDifferences) {
  Ring s;
  const Eigen::MatrixXd Ka = dense_K(s, false), Kf = dense_K(s, true);
  // measured 1.5e-2 (the small-strain Jacobian drops terms of the order of the strains, here
  // ~0.1 from the random 0.3 Å displacements)
  EXPECT_LT((Ka - Kf).norm(), 5e-2 * Kf.norm());
  EXPECT_LT((Ka - Ka.transpose()).norm(), 1e-12 * Ka.norm());
  EXPECT_LT((Kf - Kf.transpose()).norm(), 1e-9 * Kf.norm());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Ka);
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-10 * eig.eigenvalues().maxCoeff());
  // rigid translations are in its null space
  Eigen::VectorXd t = Eigen::VectorXd::Zero(Ka.rows());
  for (int k = 0; k < s.rod.size(); ++k) t[6 * k] = 1;
  EXPECT_LT((Ka * t).norm(), 1e-10 * Ka.norm() * t.norm());
}

// With per-link moduli (rod.moduli_file) the analytic Gauss–Newton K uses each link's C_h: it
// matches the finite-difference K (through elastic_forces, which reads the per-link moduli) as
// closely as with scalar moduli, and differs from the K of the scalar moduli by far more.
TEST(ImplicitStiffness, PerLinkModuliMatchFiniteDifferences) {
  Ring s(2, true);
  const Eigen::MatrixXd Ka = dense_K(s, false), Kf = dense_K(s, true);
  const double rel = (Ka - Kf).norm() / Kf.norm();
  std::printf("  per-link moduli: |K_GN − K_fd| / |K_fd| = %.3e\n", rel);
  EXPECT_LT(rel, 5e-2);
  EXPECT_LT((Ka - Ka.transpose()).norm(), 1e-12 * Ka.norm());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Ka);
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-10 * eig.eigenvalues().maxCoeff());
  Ring scalar(2, false);
  scalar.rod = s.rod;
  const Eigen::MatrixXd Ks = dense_K(scalar, false);
  EXPECT_GT((Ks - Kf).norm(), 5 * (Ka - Kf).norm());
}

TEST(ImplicitStiffness, GaussNewtonIsTheFullJacobianUpToStressTerms) {
  // K_full − K_GN is the geometric stiffness, proportional to the stresses: small against the
  // material stiffness of a mildly strained rod, but not zero
  Ring s;
  ImplicitParams ip;
  ip.gauss_newton = false;
  ImplicitStepper imp(*s.st, ip);
  const Eigen::MatrixXd Kfull(imp.stiffness(s.rod));
  const Eigen::MatrixXd Kgn = dense_K(s, true);
  const double rel = (Kfull - Kgn).norm() / Kgn.norm();
  EXPECT_LT(rel, 0.2);  // measured 0.085
  EXPECT_GT(rel, 1e-6);
}

TEST(ImplicitMobility, IsSymmetricAndPositive) {
  Ring s;
  ImplicitStepper imp(*s.st, ImplicitParams{});
  const int n = s.rod.size();
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N(0, 1);
  auto rnd = [&](double scale) {
    std::vector<Vec3> v(n);
    for (auto& x : v) x = scale * Vec3(N(rng), N(rng), N(rng));
    return v;
  };
  const auto F1 = rnd(1.0), T1 = rnd(10.0), F2 = rnd(1.0), T2 = rnd(10.0);
  std::vector<Vec3> U1(n), W1(n), U2(n), W2(n);
  imp.mobility(s.rod.X, F1, T1, U1, W1);
  imp.mobility(s.rod.X, F2, T2, U2, W2);
  double a = 0, b = 0, p1 = 0;
  for (int k = 0; k < n; ++k) {
    a += F2[k].dot(U1[k]) + T2[k].dot(W1[k]);
    b += F1[k].dot(U2[k]) + T1[k].dot(W2[k]);
    p1 += F1[k].dot(U1[k]) + T1[k].dot(W1[k]);
  }
  EXPECT_NEAR(a, b, 1e-10 * std::abs(p1));  // spreading and interpolation are adjoint
  EXPECT_GT(p1, 0.0);                       // the fluid dissipates
  EXPECT_GT(imp.self_mobility_translation(), 0.0);
  EXPECT_GT(imp.self_mobility_rotation(), 0.0);
}

TEST(ImplicitStepper, UndoRestoresTheStateAndTheEnergyBookkeeping) {
  Ring s;
  ImplicitStepper imp(*s.st, ImplicitParams{});
  const rod::RodState q0 = s.rod;
  const ImplicitStepInfo a = imp.step(s.rod, 1e-9);
  EXPECT_GT(a.max_displacement, 0.0);
  imp.undo(s.rod);
  for (int k = 0; k < s.rod.size(); ++k) {
    EXPECT_EQ(s.rod.X[k], q0.X[k]);
    EXPECT_EQ(s.rod.D[k], q0.D[k]);
  }
  EXPECT_THROW(imp.undo(s.rod), std::logic_error);
  const ImplicitStepInfo b = imp.step(s.rod, 1e-9);
  EXPECT_EQ(b.energy_before, a.energy_before);
  EXPECT_EQ(b.energy_after, a.energy_after);  // the same step again, bit for bit
  EXPECT_EQ(b.max_displacement, a.max_displacement);
  EXPECT_LT(b.energy_after, b.energy_before);
}

// A collection of rods from a configuration (sim::initial_state), strained as Ring's.
struct Rods {
  sim::SimParams p;
  rod::RodState rod;
  std::unique_ptr<System> st;
  explicit Rods(const config::Config& c) {
    p = config::to_params(c);
    rod = sim::initial_state(p);
    std::mt19937_64 rng(13);
    std::normal_distribution<double> N(0, 1);
    for (int k = 0; k < rod.size(); ++k) {
      rod.X[k] += 0.3 * Vec3(N(rng), N(rng), N(rng));
      rod.D[k] = rotation(0.05 * Vec3(N(rng), N(rng), N(rng))) * rod.D[k];
    }
    st = std::make_unique<System>(p.stepper);
  }
};

config::Config small(int bp) {
  config::Config c;
  c.grid_n = 16;
  c.grid_box_A = 200;
  c.rod_base_pairs = bp;
  c.rod_excess_link = 0;
  c.run_threads = 1;
  c.run_fftw_measure = false;
  return c;
}
// an open rod of 30 points with intrinsic curvature and twist (a helix when relaxed)
config::Config open_rod() {
  config::Config c = small(30);
  config::apply_override(c, "rod.closed=false");
  config::apply_override(c, "rod.intrinsic_curvature_per_A=[0.04, 0.0]");
  config::apply_override(c, "rod.intrinsic_twist_per_A=0.04");
  return c;
}
// a ring of 40 and an open rod of 24 points, apart (no contacts)
config::Config ring_and_open_rod() {
  config::Config c = small(40);
  config::apply_override(c, "rods.0.offset_A=[0, 0, -40]");
  config::apply_override(c, "rods.1.offset_A=[0, 0, 40]");
  config::apply_override(c, "rods.1.base_pairs=24");
  config::apply_override(c, "rods.1.closed=false");
  return c;
}

Eigen::MatrixXd dense_K(Rods& s, bool fd) {
  ImplicitParams ip;
  ip.stiffness_fd = fd;
  ImplicitStepper imp(*s.st, ip);
  return Eigen::MatrixXd(imp.stiffness(s.rod));
}

TEST(ImplicitStiffness, OpenRodHasNoLinkPastItsEnds) {
  Rods s(open_rod());
  const int n = s.rod.size();
  const Eigen::MatrixXd Ka = dense_K(s, false), Kf = dense_K(s, true);
  ASSERT_EQ(Ka.rows(), 6 * n);
  const double rel = (Ka - Kf).norm() / Kf.norm();
  EXPECT_LT(rel, 5e-2);  // measured 1.3e-2 (as the ring's: small-strain terms)
  EXPECT_LT((Ka - Ka.transpose()).norm(), 1e-12 * Ka.norm());
  // no block couples the two ends (the ring's wrap-around link), in either K
  EXPECT_EQ(Ka.block(0, 6 * (n - 1), 6, 6).norm(), 0.0);
  EXPECT_EQ(Kf.block(0, 6 * (n - 1), 6, 6).norm(), 0.0);
  EXPECT_EQ(Kf.block(6 * (n - 1), 0, 6, 6).norm(), 0.0);
  // rigid translations are in its null space
  Eigen::VectorXd t = Eigen::VectorXd::Zero(Ka.rows());
  for (int k = 0; k < n; ++k) t[6 * k + 1] = 1;
  EXPECT_LT((Ka * t).norm(), 1e-10 * Ka.norm() * t.norm());
}

TEST(ImplicitStiffness, SeveralRodsAreBlockDiagonalEachRodAlone) {
  Rods both(ring_and_open_rod());
  const std::vector<rod::RodRange> g = rod::ranges_of(both.p.stepper.rods);
  ASSERT_EQ(g.size(), 2u);
  for (const bool fd : {false, true}) {
    const Eigen::MatrixXd K = dense_K(both, fd);
    // the off-diagonal rod–rod blocks are zero (no contacts: the rods are 80 Å apart)
    EXPECT_EQ(K.block(0, 6 * g[1].offset, 6 * g[0].n, 6 * g[1].n).norm(), 0.0);
    // each diagonal block is the rod's own K, computed alone
    for (int r = 0; r < 2; ++r) {
      config::Config c = config::rod_config(ring_and_open_rod(), r);
      c.rods.clear();
      Rods one(c);
      rod::extract(both.rod, g[r], one.rod);
      const Eigen::MatrixXd Kr = dense_K(one, fd);
      const Eigen::MatrixXd blk = K.block(6 * g[r].offset, 6 * g[r].offset, 6 * g[r].n, 6 * g[r].n);
      EXPECT_LT((blk - Kr).norm(), 1e-12 * Kr.norm()) << r << " fd " << fd;
    }
  }
}

TEST(ImplicitStepper, BlockSolverAndSparseCholeskyGiveTheSameStep) {
  // no contacts (the ring of Ring): the block-cyclic fast path against the general sparse one
  Ring a, b;
  ImplicitParams pa, pb;
  pb.block_solver = false;
  ImplicitStepper ia(*a.st, pa), ib(*b.st, pb);
  for (int k = 0; k < 3; ++k) {
    ia.step(a.rod, 2e-9);
    ib.step(b.rod, 2e-9);
  }
  double d = 0, u = 0;
  for (int k = 0; k < a.rod.size(); ++k) {
    d = std::max(d, (ia.velocities()[k] - ib.velocities()[k]).norm());
    u = std::max(u, ib.velocities()[k].norm());
  }
  EXPECT_LT(d, 1e-9 * u);
  EXPECT_GT(u, 0.0);
}

// The block path (one tridiagonal factor for the open rod, one cyclic for the ring) against the
// general sparse Cholesky of the whole K, on an open rod alone and on a ring with an open rod.
TEST(ImplicitStepper, BlockSolverMatchesSparseCholeskyOnOpenAndSeveralRods) {
  for (const config::Config& c : {open_rod(), ring_and_open_rod()}) {
    Rods a(c), b(c);
    ImplicitParams pa, pb;
    pb.block_solver = false;
    ImplicitStepper ia(*a.st, pa), ib(*b.st, pb);
    for (int k = 0; k < 3; ++k) {
      ia.step(a.rod, 2e-9);
      ib.step(b.rod, 2e-9);
    }
    EXPECT_EQ(ia.contacts(), 0);
    double d = 0, u = 0;
    for (int k = 0; k < a.rod.size(); ++k) {
      d = std::max(d, (ia.velocities()[k] - ib.velocities()[k]).norm());
      u = std::max(u, ib.velocities()[k].norm());
    }
    EXPECT_LT(d, 1e-9 * u) << config::rod_configs(c).size();
    EXPECT_GT(u, 0.0);
  }
}

}  // namespace
}  // namespace ibrod::integrate
