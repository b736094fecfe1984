// The implicit rod–fluid scheme (issue 14, docs/large_dt.md) on a small ring: 16³ grid
// (h = 12.5 Å), 100 bp, ΔLk = 3, 0.1 M, electrostatics and steric on. The twisted circle buckles
// at 30–60 ns and its strands touch at ~75 ns. Its explicit Stokes-limit Euler step is stable
// at 0.15 ns and blows up at 0.2 ns (measured with prototypes/large_dt). Seconds each.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "config/config.hpp"
#include "diagnostics/topology.hpp"
#include "helpers.hpp"
#include "integrate/implicit.hpp"

namespace ibrod {
namespace {

constexpr double kExplicitLimit = 0.15e-9;  // s, measured (see the file comment)

struct Ring {
  sim::SimParams p;
  rod::RodState rod;
  std::unique_ptr<integrate::System> st;
  std::unique_ptr<integrate::ImplicitStepper> imp;
  Ring(double beta, int threads = 1) {
    config::Config c = test::small_config(3);
    c.run_threads = threads;
    p = config::to_params(c);
    rod = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
    st = std::make_unique<integrate::System>(p.stepper);
    integrate::ImplicitParams ip;
    ip.mobility_scale = beta;  // 0: the explicit Stokes-limit Euler step δ = Δt M F
    imp = std::make_unique<integrate::ImplicitStepper>(*st, ip);
  }
  void run(double dt, double t_end) {
    const long n = std::lround(t_end / dt);
    for (long k = 0; k < n; ++k) imp->step(rod, dt);
  }
};

double max_distance(const rod::RodState& a, const rod::RodState& b) {
  double d = 0;
  for (int k = 0; k < a.size(); ++k) d = std::max(d, (a.X[k] - b.X[k]).norm());
  return d;
}

double link(const rod::RodState& s) {
  std::vector<Vec3> d1(s.size());
  for (int k = 0; k < s.size(); ++k) d1[k] = s.D[k].col(0);
  return diagnostics::writhe(s.X) + diagnostics::twist(s.X, d1);
}

TEST(Implicit, FirstOrderConvergenceTowardASmallStepExplicitReference) {
  // 40 ns (buckling under way) at Δt = 0.4, 0.2, 0.1 ns against explicit Euler at 0.01 ns
  // (whose own error, 0.025 Å against 0.005 ns, is ~1 % of the smallest one here).
  const double T = 40e-9;
  Ring ref(0.0);
  ref.run(0.01e-9, T);
  double err[3];
  for (int i = 0; i < 3; ++i) {
    Ring r(8.0);
    r.run(0.4e-9 / (1 << i), T);
    err[i] = max_distance(r.rod, ref.rod);
  }
  // measured 9.3, 4.0, 2.1 Å: ratios 2.3, 1.9 (analytic Gauss–Newton K)
  EXPECT_LT(err[0], 20.0);
  for (int i = 0; i < 2; ++i) {
    const double ratio = err[i] / err[i + 1];
    EXPECT_GT(ratio, 1.6) << i;
    EXPECT_LT(ratio, 2.7) << i;
  }
}

TEST(Implicit, TendsToTheExplicitStepAsDtGoesToZero) {
  // From a buckling state, δ/Δt of one implicit step minus the explicit velocity M F is
  // −Δt M_loc K δ/Δt: linear in Δt once Δt M_loc K ≪ 1 on the stiffest (stretch) modes, i.e.
  // Δt ≪ Δs/(4 b β m_t) ≈ 1e-12 s here.
  Ring base(0.0);
  base.run(0.05e-9, 30e-9);
  double diff[3];
  for (int i = 0; i < 3; ++i) {
    const double dt = 2e-14 / (1 << i);
    Ring r(8.0);
    r.rod = base.rod;
    Ring e(0.0);
    e.rod = base.rod;
    r.imp->step(r.rod, dt);
    e.imp->step(e.rod, dt);
    double d = 0, u = 0;
    for (int k = 0; k < r.rod.size(); ++k) {
      d = std::max(d, (r.imp->velocities()[k] - e.imp->velocities()[k]).norm());
      u = std::max(u, e.imp->velocities()[k].norm());
    }
    diff[i] = d / u;
  }
  EXPECT_LT(diff[2], 0.05);
  for (int i = 0; i < 2; ++i) {
    EXPECT_GT(diff[i] / diff[i + 1], 1.7) << i;
    EXPECT_LT(diff[i] / diff[i + 1], 2.3) << i;
  }
}

TEST(Implicit, TwentyTimesTheExplicitLimitThroughCollapseAndContact) {
  // Δt up to 20× the explicit limit, adaptive (max displacement 0.2 min(1/κ, D) = 1.9 Å, the
  // potential energy never rising), through buckling and contact to 150 ns.
  Ring r(8.0);
  integrate::AdaptiveDtParams ap;
  ap.dt_max = 20 * kExplicitLimit;
  ap.dt_min = 1e-3 * kExplicitLimit;
  ap.max_displacement =
      0.2 * std::min(1 / r.p.stepper.electro.law.kappa, r.p.stepper.steric.diameter);
  ap.energy_tolerance = 1e-6 * r.p.kT;
  integrate::AdaptiveDt ctl(ap);
  const double lk0 = link(r.rod);
  double t = 0, closest = 1e300, e_prev = HUGE_VAL;
  long steps = 0, at_max = 0;
  while (t < 150e-9) {
    double dt = 0;
    const auto info = integrate::step_adaptive(*r.imp, r.rod, ctl, 150e-9 - t + 1e-15, &dt);
    t += dt;
    ++steps;
    at_max += dt == ap.dt_max;
    ASSERT_TRUE(info.finite);
    // the total energy (the Stokes fluid holds none) never increases
    ASSERT_LE(info.energy_after, info.energy_before + ap.energy_tolerance) << t;
    if (std::isfinite(e_prev)) {
      ASSERT_EQ(info.energy_before, e_prev);
    }
    e_prev = info.energy_after;
    if (steps % 5 == 0) {
      ASSERT_NEAR(link(r.rod), lk0, 1e-3) << "t = " << t;
      closest = std::min(closest, diagnostics::closest_approach(r.rod.X, 20));
    }
  }
  EXPECT_NEAR(link(r.rod), lk0, 1e-3);
  EXPECT_LT(closest, 21.0);  // the strands did touch (D = 20 Å)
  const double spacing = diagnostics::mean_spacing(r.rod.X);
  EXPECT_GT(spacing, 3.3);
  EXPECT_LT(spacing, 3.7);
  // the point of it: a mean step of at least 5× the explicit limit, with steps at the maximum
  // (measured: 101 steps and 5 rejected trials for 150 ns, mean 1.5 ns = 10× the limit)
  EXPECT_GT(t / steps, 5 * kExplicitLimit) << steps << " steps";
  EXPECT_GT(at_max, 5);
}

TEST(Implicit, AResumedRunWithAChangingStepIsBitwiseTheSame) {
  // The integrator's state (rod, time, the controller's next Δt and run of accepted steps) is
  // all a resume needs: a fresh integrator restored from it at 60 ns, when the collapse has
  // already changed Δt, continues bit for bit as the uninterrupted one (which refreshes K at
  // the same point, as at a checkpoint write), and the time is continuous.
  integrate::AdaptiveDtParams ap;
  ap.dt_max = 20 * kExplicitLimit;
  ap.dt_min = 1e-3 * kExplicitLimit;
  ap.max_displacement = 1.9;
  ap.energy_tolerance = 1e-6 * 414.2;
  Ring a(8.0);
  integrate::ImplicitIntegrator ia(*a.st, integrate::ImplicitParams{}, ap);
  double t = 0;
  std::vector<double> dts;
  while (t < 60e-9) {
    const double dt = ia.advance(a.rod, 1.0);
    dts.push_back(dt);
    t += dt;
  }
  const double t_ck = t;
  const rod::RodState q_ck = a.rod;
  const auto st_ck = ia.state();
  ia.refresh();
  EXPECT_LT(*std::min_element(dts.begin(), dts.end()), ap.dt_max);  // Δt did change
  for (int k = 0; k < 40; ++k) t += ia.advance(a.rod, 1.0);

  Ring b(8.0);
  integrate::ImplicitIntegrator ib(*b.st, integrate::ImplicitParams{}, ap);
  b.rod = q_ck;
  ib.restore(st_ck);
  double tb = t_ck;
  for (int k = 0; k < 40; ++k) tb += ib.advance(b.rod, 1.0);
  EXPECT_EQ(tb, t);
  for (int k = 0; k < a.rod.size(); ++k) {
    ASSERT_EQ(a.rod.X[k], b.rod.X[k]) << k;
    ASSERT_EQ(a.rod.D[k], b.rod.D[k]) << k;
  }
  EXPECT_EQ(ia.state().next_dt, ib.state().next_dt);
}

}  // namespace
}  // namespace ibrod
