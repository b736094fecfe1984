// Short runs of the full coupled scheme on a small system (see helpers.hpp): the physics a run
// must respect whatever the parameters — energy never increases, the link is conserved, triads
// stay orthonormal, a weakly twisted ring stays circular.
#include <gtest/gtest.h>

#include <cmath>

#include "helpers.hpp"
#include "integrate/stepper.hpp"
#include "sim/rod_problem.hpp"
#include "sim/simulation.hpp"

using namespace ibrod;

namespace {

double total_potential_plus_kinetic(const sim::Observables& o) { return o.E_total_kT; }

double max_radius_deviation(const rod::RodState& s) {
  Vec3 c = Vec3::Zero();
  for (const auto& x : s.X) c += x;
  c /= s.size();
  double rmin = 1e300, rmax = 0;
  for (const auto& x : s.X) {
    const double r = (x - c).norm();
    rmin = std::min(rmin, r);
    rmax = std::max(rmax, r);
  }
  return (rmax - rmin) / (0.5 * (rmax + rmin));
}

}  // namespace

TEST(Dynamics, LowLinkRingStaysCircularAndKeepsItsLink) {
  auto c = test::small_config(1);
  c.electrostatics_enabled = false;
  sim::Simulation s(config::to_params(c));
  const auto o0 = s.observe();
  EXPECT_NEAR(o0.link, 1.0, 1e-6);
  EXPECT_NEAR(o0.writhe, 0.0, 1e-9);
  for (int i = 0; i < 2000; ++i) s.step();
  const auto o = s.observe();
  EXPECT_EQ(sim::rod_problem(s.rod(), c.rod_rise_A), "");
  EXPECT_TRUE(std::isfinite(o.E_total_kT));
  EXPECT_NEAR(o.link, 1.0, 1e-3);
  EXPECT_LT(std::abs(o.writhe), 0.01);
  EXPECT_LT(max_radius_deviation(s.rod()), 0.01);
}

TEST(Dynamics, TotalEnergyNeverIncreasesAndLinkIsConserved) {
  auto c = test::small_config(3);
  c.electrostatics_enabled = false;
  c.rod_perturbation = {0.5, 0.3, 0.2};
  sim::Simulation s(config::to_params(c));
  auto prev = s.observe();
  const double E0 = prev.E_total_kT;
  ASSERT_GT(E0, 0);
  double dissipated = 0;
  for (int block = 0; block < 150; ++block) {
    for (int i = 0; i < 20; ++i) s.step();
    const auto o = s.observe();
    // Energy may only go down (the fluid dissipates it); allow round-off relative to E0.
    ASSERT_LE(total_potential_plus_kinetic(o), total_potential_plus_kinetic(prev) + 1e-10 * E0)
        << "at step " << o.step;
    ASSERT_NEAR(o.link, 3.0, 1e-3) << "at step " << o.step;
    dissipated += prev.E_total_kT - o.E_total_kT;
    prev = o;
  }
  EXPECT_GT(dissipated, 0.0);  // the perturbed ring is not at rest: something happened
  for (const auto& D : s.rod().D) ASSERT_LT((D.transpose() * D - Mat3::Identity()).norm(), 1e-10);
}

TEST(Dynamics, ChargedRodEnergyIncludingElectrostaticsNeverIncreases) {
  auto c = test::small_config(2);
  c.solvent_salt_M = 0.01;
  c.rod_perturbation = {0.5, 0.3};
  sim::Simulation s(config::to_params(c));
  auto prev = s.observe();
  ASSERT_GT(prev.E_electro_kT, 0);  // like charges: positive energy
  const double E0 = std::abs(prev.E_total_kT);
  for (int block = 0; block < 100; ++block) {
    for (int i = 0; i < 20; ++i) s.step();
    const auto o = s.observe();
    ASSERT_LE(o.E_total_kT, prev.E_total_kT + 1e-10 * E0) << "at step " << o.step;
    prev = o;
  }
}

TEST(Dynamics, LikeChargesPushTwoParallelLinesApart) {
  // Two parallel lines of charges with no elasticity (zero moduli): only electrostatics acts, and
  // through the fluid the lines must separate (MODEL §3 sign convention).
  auto p = config::to_params(test::small_config(0)).stepper;
  p.rods[0].a.setZero();
  p.rods[0].b.setZero();
  p.steric.enabled = false;
  p.electro.law.kappa = 0.05;
  p.electro.cutoff = 0;
  integrate::Stepper st(p);
  rod::RodState r;
  const int n = p.rods[0].n, half = n / 2;
  for (int k = 0; k < n; ++k) {
    const int line = k < half ? 0 : 1;
    const int j = line == 0 ? k : k - half;
    r.X.push_back(Vec3(100.0 + (line ? 10.0 : -10.0), 100.0, 100.0 - 40.0 + 1.6 * j));
    r.D.push_back(Mat3::Identity());
  }
  auto gap = [&] {
    double a = 0, b = 0;
    for (int k = 0; k < half; ++k) a += r.X[k].x();
    for (int k = half; k < n; ++k) b += r.X[k].x();
    return b / (n - half) - a / half;
  };
  const double g0 = gap();
  for (int i = 0; i < 200; ++i) st.step(r);
  EXPECT_GT(gap(), g0 + 0.01);
}

TEST(Dynamics, CollapsingRingKeepsItsLinkAndItsHardCore) {
  // ΔLk = 4 without electrostatics collapses into a tight supercoil within ~0.2 µs (measured:
  // writhe ≈ 1.9 by step 4000); the hard core alone must keep the strands apart and the link.
  auto c = test::small_config(4);
  c.electrostatics_enabled = false;
  c.rod_perturbation = {0.5, 0.3, 0.2};
  sim::Simulation s(config::to_params(c));
  double closest = 1e300, max_writhe = 0;
  for (int block = 0; block < 40; ++block) {
    for (int i = 0; i < 100; ++i) s.step();
    const auto o = s.observe();
    ASSERT_NEAR(o.link, 4.0, 1e-3) << "at step " << o.step;
    closest = std::min(closest, o.closest_approach_A);
    max_writhe = std::max(max_writhe, o.writhe);
  }
  EXPECT_GT(max_writhe, 1.0);  // it did collapse, and strands came into contact
  EXPECT_LT(closest, 21.0);
  EXPECT_GE(closest, 0.95 * c.steric_diameter_A);
}
