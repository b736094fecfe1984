// The implicit scheme with the kernel-overlap local mobility (issue 24, docs/large_dt.md "A local
// mobility with the kernel's null space") on the small ring of test_implicit.cpp: 16³ grid
// (h = 12.5 Å), 100 bp, 0.1 M, electrostatics and steric on.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "config/config.hpp"
#include "helpers.hpp"
#include "integrate/implicit.hpp"

namespace ibrod {
namespace {

using LocalMobility = integrate::ImplicitParams::LocalMobility;

struct Ring {
  sim::SimParams p;
  rod::RodState rod;
  std::unique_ptr<integrate::System> st;
  std::unique_ptr<integrate::ImplicitStepper> imp;
  Ring(LocalMobility mloc, double beta, int order, int excess_link,
       std::vector<double> perturbation = {1.0}, int jacobian_every = 1) {
    config::Config c = test::small_config(excess_link);
    c.run_threads = 1;
    c.rod_perturbation = perturbation;
    p = config::to_params(c);
    rod = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
    st = std::make_unique<integrate::System>(p.stepper);
    integrate::ImplicitParams ip;
    ip.local_mobility = mloc;
    ip.mobility_scale = beta;  // 0: the explicit Stokes-limit Euler step δ = Δt M F
    ip.order = order;
    ip.jacobian_every = jacobian_every;
    imp = std::make_unique<integrate::ImplicitStepper>(*st, ip);
  }
  void run(double dt, double t_end) {
    const long n = std::lround(t_end / dt);
    for (long k = 0; k < n; ++k) imp->step(rod, dt);
  }
  double potential_kT() { return imp->step(rod, 0.0).energy_before / p.kT; }
};

TEST(ImplicitOverlap, FollowsTheExplicitPathWhereTheSelfMobilityRunsAhead) {
  // 100 ns of the collapsing ΔLk = 4 ring, all at Δt = 0.1 ns (the explicit scheme's own step):
  // the explicit Stokes-limit Euler step, the IMEX step with the diagonal self mobility (β = 8,
  // the default) and with the kernel overlap (β = 1, factorised every 10 steps). The diagonal
  // M_loc moves the short-wave modes that the Stokes mobility hardly moves and relaxes them: a
  // bias that Δt → 0 does not remove (measured: explicit 313.54, self 311.30, overlap 313.91 kT).
  const double T = 100e-9, dt = 0.1e-9;
  Ring ex(LocalMobility::self, 0.0, 1, 4);
  Ring self(LocalMobility::self, 8.0, 1, 4);
  Ring ov(LocalMobility::overlap, 1.0, 1, 4, {1.0}, 10);
  ex.run(dt, T);
  self.run(dt, T);
  ov.run(dt, T);
  const double e_ex = ex.potential_kT(), e_self = self.potential_kT(), e_ov = ov.potential_kT();
  std::printf("E at 100 ns: explicit %.3f, self %.3f, overlap %.3f kT\n", e_ex, e_self, e_ov);
  EXPECT_NEAR(e_ov, e_ex, 0.8);
  EXPECT_LT(e_self, e_ex - 1.5);  // the old default's bias, which this test is there to catch
}

TEST(ImplicitOverlap, StiffModesDecayAtStepsFarBeyondTheExplicitLimit) {
  // The untwisted ring with a large perturbation relaxing at 2 and 8 ns (the explicit limit is
  // ~0.15 ns) with M_loc = the overlap at β = 1, refreshed every step: M/M_loc lies within
  // 0.15–2 on every mode (prototypes/large_dt/mobility_spectrum.py), where the order-1
  // amplification 1 − r x/(1 + x) stays within (−1, 1] and ROS2's too (r < 2γ): every mode
  // decays, the energy falls at every step. (A factorisation kept over 5 steps of this fast
  // relaxation at 4 ns lets it rise: the controller's energy check catches that in a run.)
  for (int order : {1, 2})
    for (double dt : {2e-9, 8e-9}) {
      Ring r(LocalMobility::overlap, 1.0, order, 0, {3.0}, 1);
      const double e0 = r.potential_kT();
      double prev = e0;
      for (int k = 0; k < 30; ++k) {
        const auto info = r.imp->step(r.rod, dt);
        ASSERT_TRUE(info.finite) << "order " << order << " dt " << dt << " step " << k;
        const double e = info.energy_after / r.p.kT;
        ASSERT_LE(e, prev + 1e-6) << "order " << order << " dt = " << dt << " step " << k;
        prev = e;
      }
      EXPECT_LT(prev, e0 - 50) << "order " << order << " dt " << dt;  // 191.6 → ~77–85 kT
    }
}

TEST(ImplicitOverlap, ARefreshDisplacementRemakesWWhereverThePointsHaveMovedThatFar) {
  // time.implicit_refresh_displacement_A (docs/large_dt.md §8): W = I + γΔt M_loc K is remade
  // before its count of steps once a rod point has moved farther than δ since it was made. The
  // relaxing untwisted ring (perturbation 3) at 2 ns, ROS2, W kept for up to 1000 steps:
  //  - δ below any step's motion: W at every step, bitwise the run that refreshes every step;
  //  - δ above the whole motion: one W, bitwise the run without the rule;
  //  - δ in between: W remade only once a point has moved farther than δ, never used at a
  //    state farther than δ from the one it was made at, and the path closer to the every-step
  //    one than the single W's.
  const double dt = 2e-9;
  const int steps = 25;
  auto run = [&](int every, double delta, std::vector<double>* max_age) {
    Ring r(LocalMobility::overlap, 1.0, 2, 0, {3.0}, every);
    integrate::ImplicitParams ip;
    ip.local_mobility = LocalMobility::overlap;
    ip.mobility_scale = 1.0;
    ip.order = 2;
    ip.jacobian_every = every;
    ip.refresh_displacement = delta;
    r.imp = std::make_unique<integrate::ImplicitStepper>(*r.st, ip);
    std::vector<Vec3> made = r.rod.X;  // where the latest W was made
    for (int k = 0; k < steps; ++k) {
      const std::vector<Vec3> xn = r.rod.X;
      double age = 0;  // how far the points are from where W was made
      for (std::size_t i = 0; i < xn.size(); ++i) age = std::max(age, (xn[i] - made[i]).norm());
      const auto info = r.imp->step(r.rod, dt);
      EXPECT_TRUE(info.finite);
      if (info.jacobian_refreshed) {
        if (max_age && k > 0) max_age->push_back(age);
        made = xn;
      } else if (delta > 0) {
        EXPECT_LE(age, delta) << "step " << k << ": W used " << age << " Å from where it was made";
      }
    }
    return r;
  };
  Ring every = run(1, 0.0, nullptr);
  Ring tiny = run(1000, 1e-9, nullptr);
  Ring once = run(1000, 0.0, nullptr);
  Ring huge = run(1000, 1e4, nullptr);
  EXPECT_EQ(every.imp->timings().factorizations, steps);
  EXPECT_EQ(tiny.imp->timings().factorizations, steps);
  EXPECT_EQ(tiny.imp->timings().moved_refreshes, steps - 1);
  EXPECT_EQ(once.imp->timings().factorizations, 1);
  EXPECT_EQ(huge.imp->timings().factorizations, 1);
  EXPECT_EQ(huge.imp->timings().moved_refreshes, 0);
  for (std::size_t i = 0; i < every.rod.X.size(); ++i) {
    ASSERT_EQ(tiny.rod.X[i], every.rod.X[i]) << i;
    ASSERT_EQ(huge.rod.X[i], once.rod.X[i]) << i;
  }
  const double delta = 0.5;  // Å
  std::vector<double> ages;
  Ring mid = run(1000, delta, &ages);
  const long lu = mid.imp->timings().factorizations;
  EXPECT_GT(lu, 2);
  EXPECT_LT(lu, steps);
  std::printf("delta %.2f A: %ld LUs in %d steps; ages at refresh:", delta, lu, steps);
  for (double a : ages) std::printf(" %.3f", a);
  std::printf("\n");
  for (std::size_t j = 0; j < ages.size(); ++j) EXPECT_GT(ages[j], delta) << j;  // not early
  auto dist = [&](const Ring& a) {
    double d = 0;
    for (std::size_t i = 0; i < a.rod.X.size(); ++i)
      d = std::max(d, (a.rod.X[i] - every.rod.X[i]).norm());
    return d;
  };
  std::printf("distance to every-step W: delta %.4f, single W %.4f A\n", dist(mid), dist(once));
  EXPECT_LT(dist(mid), dist(once));
}

}  // namespace
}  // namespace ibrod
