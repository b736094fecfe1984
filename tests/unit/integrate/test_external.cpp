// Unit tests of the external load on the rod (external.force_pN, external.torque_pN_nm;
// docs/thermal.md): the point forces it adds (total force, zero net force and the torque of the
// rigid-rotation pattern), and a ring pulled through the fluid: it moves along the force with a
// velocity linear in the force while the fluid's mean velocity stays zero. 16³, 60 points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "config/config.hpp"
#include "core/units.hpp"
#include "integrate/implicit.hpp"
#include "integrate/stepper.hpp"
#include "sim/simulation.hpp"

namespace ibrod::integrate {
namespace {

sim::SimParams ring_params(const std::vector<double>& force_pN,
                           const std::vector<double>& torque_pN_nm) {
  config::Config c;
  c.grid_n = 16;
  c.grid_box_A = 200;
  c.rod_base_pairs = 60;
  c.rod_excess_link = 0;
  c.rod_perturbation = {0.0};
  c.solvent_advection = false;
  c.run_threads = 1;
  c.run_fftw_measure = false;
  c.external_force_pN = force_pN;
  c.external_torque_pN_nm = torque_pN_nm;
  sim::SimParams p = config::to_params(c);
  p.stepper.fluid.dt = p.dt;
  return p;
}

Vec3 centroid(const std::vector<Vec3>& X) {
  Vec3 c = Vec3::Zero();
  for (const Vec3& x : X) c += x;
  return c / double(X.size());
}

TEST(External, ForceAndTorqueAddTheirPointForces) {
  const std::vector<double> F{1.5, -2.0, 0.5}, tau{3.0, 1.0, -4.0};
  const sim::SimParams p0 = ring_params({0, 0, 0}, {0, 0, 0});
  const sim::SimParams p1 = ring_params(F, tau);
  rod::RodState s = rod::twisted_circle(p0.stepper.rods[0], p0.shapes[0].circle);
  // a generic shape: the ring tilted and bent a little
  for (int k = 0; k < s.size(); ++k)
    s.X[k] += Vec3(0.3 * std::sin(2.0 * k), 0, 2.0 * std::cos(k * 0.1));
  System a(p0.stepper), b(p1.stepper);
  a.compute_forces(s);
  b.compute_forces(s);
  const Vec3 c = centroid(s.X);
  Vec3 sum = Vec3::Zero(), moment = Vec3::Zero();
  for (int k = 0; k < s.size(); ++k) {
    const Vec3 d = b.forces()[k] - a.forces()[k];
    sum += d;
    moment += (s.X[k] - c).cross(d);
    EXPECT_EQ(b.torques()[k], a.torques()[k]);  // point torques untouched
  }
  const Vec3 Fi = Vec3(F[0], F[1], F[2]) * units::pN;
  const Vec3 ti = Vec3(tau[0], tau[1], tau[2]) * units::pN * units::nm;
  EXPECT_LT((sum - Fi).norm(), 1e-12 * Fi.norm());
  EXPECT_LT((moment - ti).norm(), 1e-10 * ti.norm());
  // the reaction −F/L³ on the fluid
  const double vol = std::pow(p1.stepper.grid.L, 3);
  for (int d = 0; d < 3; ++d) EXPECT_DOUBLE_EQ(b.fluid().mean_force()[d], -Fi[d] / vol);
}

// Mean velocity of the centroid over `steps` steps, Å/s.
Vec3 pulled_velocity(double fx_pN, int steps) {
  const sim::SimParams p = ring_params({fx_pN, 0, 0}, {0, 0, 0});
  rod::RodState s = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
  Stepper st(p.stepper);
  const Vec3 c0 = centroid(s.X);
  for (int i = 0; i < steps; ++i) st.step(s);
  // the fluid's mean velocity stays zero: the reaction balances the spread force
  for (int c = 0; c < 3; ++c) {
    double mean = 0;
    const std::size_t n3 = p.stepper.grid.size();
    for (std::size_t t = 0; t < n3; ++t) mean += st.system().fluid().velocity(c)[t];
    EXPECT_LT(std::abs(mean / double(n3)), 1.0) << "component " << c;  // Å/s; the ring: ~1e10
  }
  return (centroid(s.X) - c0) / (steps * p.dt);
}

TEST(External, PulledRingMovesAlongTheForceLinearly) {
  const Vec3 v1 = pulled_velocity(1.0, 30), v2 = pulled_velocity(2.0, 30),
             vm = pulled_velocity(-1.0, 30);
  EXPECT_GT(v1[0], 0);
  // transverse drift: none by symmetry (the ring lies in a plane through the force)
  EXPECT_LT(std::hypot(v1[1], v1[2]), 1e-3 * v1[0]);
  // linear: twice the force, twice the velocity; the opposite force, the opposite velocity
  // (the kernel weights change as the ring moves, a nonlinearity of relative size ~1e-3 here)
  EXPECT_NEAR(v2[0] / v1[0], 2.0, 2e-2);
  EXPECT_NEAR(vm[0] / v1[0], -1.0, 1e-2);
}

}  // namespace
}  // namespace ibrod::integrate

namespace ibrod::integrate {
namespace {

// The implicit scheme (Stokes limit) picks the external force up through compute_forces: its
// pulled ring moves like the explicit scheme's, whose fluid has inertia. Measured: the implicit
// velocity is 4.7 % higher for this 60-point ring (1.1 % for the 100-point ring of
// docs/thermal.md); not explained yet (docs/thermal.md), hence 8 %: a force missing from either
// scheme, or counted twice, would be O(1).
TEST(External, ImplicitSchemePullsTheRingAtTheExplicitVelocity) {
  config::Config c;
  c.grid_n = 16;
  c.grid_box_A = 200;
  c.rod_base_pairs = 60;
  c.rod_excess_link = 0;
  c.rod_perturbation = {0.0};
  c.run_threads = 1;
  c.run_fftw_measure = false;
  c.external_force_pN = {1.0, 0, 0};
  c.time_scheme = "implicit";
  c.time_dt_ns = 1.0;
  c.time_t_end_us = 0.02;
  sim::Simulation s(config::to_params(c));
  const Vec3 c0 = centroid(s.rod().X);
  s.step();  // the flow develops within the first step of the explicit scheme: skip it in both
  const Vec3 c1 = centroid(s.rod().X);
  const double t1 = s.time();
  while (!s.at_end()) s.step();
  const double v_implicit = (centroid(s.rod().X) - c1)[0] / (s.time() - t1);
  (void)c0;
  // the explicit scheme's steady velocity, after 10 steps of start-up
  const sim::SimParams p = ring_params({1.0, 0, 0}, {0, 0, 0});
  rod::RodState r = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
  Stepper st(p.stepper);
  for (int i = 0; i < 10; ++i) st.step(r);
  const Vec3 e0 = centroid(r.X);
  for (int i = 0; i < 100; ++i) st.step(r);
  const double v_explicit = (centroid(r.X) - e0)[0] / (100 * p.dt);
  std::printf("pulled ring: v_implicit / v_explicit = %.4f\n", v_implicit / v_explicit);
  EXPECT_NEAR(v_implicit / v_explicit, 1.0, 0.08);
}

// The stochastic drift kT ∂_X·M of the overdamped limit (added by solvent.thermal_drift)
// (docs/thermal.md): measured on a 60-point ring at 16³ by central differences of the Stokes
// mobility, column by column: drift_k = Σ_{l,j} ∂M_{k,(l,j)}/∂X_{l,j}. The bound asserted: over one
// step of 0.1 ns the drift moves a point by less than a tenth of the thermal displacement
// √(2 kT M_self Δt).
TEST(ThermalDrift, DivergenceOfTheMobilityIsSmallAgainstTheNoise) {
  const sim::SimParams p = ring_params({0, 0, 0}, {0, 0, 0});
  rod::RodState s = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
  System st(p.stepper);
  ImplicitStepper imp(st, ImplicitParams{});
  const int n = s.size();
  const double delta = 0.01;  // Å; the kernel varies on the scale h = 12.5 Å
  std::vector<Vec3> F(n, Vec3::Zero()), T(n, Vec3::Zero()), Up(n), Um(n), W(n);
  std::vector<Vec3> drift(n, Vec3::Zero());  // ∂·M, s g⁻¹ Å⁻¹
  for (int l = 0; l < n; ++l)
    for (int j = 0; j < 3; ++j) {
      F[l] = Vec3::Unit(j);
      std::vector<Vec3> X = s.X;
      X[l][j] += delta;
      imp.mobility(X, F, T, Up, W);
      X[l][j] -= 2 * delta;
      imp.mobility(X, F, T, Um, W);
      for (int k = 0; k < n; ++k) drift[k] += (Up[k] - Um[k]) / (2 * delta);
      F[l].setZero();
    }
  double worst = 0;
  Vec3 mean = Vec3::Zero();
  for (const Vec3& d : drift) {
    worst = std::max(worst, d.norm());
    mean += d / double(n);
  }
  const double kT = p.kT, dt = p.dt;
  const double M = imp.self_mobility_translation();      // s g⁻¹
  const double drift_step = kT * worst * dt;             // Å
  const double noise_step = std::sqrt(2 * kT * M * dt);  // Å
  std::printf(
      "ThermalDrift: max |kT ∂·M| = %.4g Å/ns (centroid: %.3g Å/ns); per 0.1 ns step %.4g Å "
      "against the thermal %.4g Å (ratio %.3g)\n",
      kT * worst * 1e-9, kT * mean.norm() * 1e-9, drift_step, noise_step, drift_step / noise_step);
  EXPECT_LT(drift_step, 0.1 * noise_step);
}

// The drift that solvent.thermal_drift adds (docs/thermal.md, "The stochastic drift"): one step
// from the fluid at rest, with and without it, the same noise (same seed and noise step), so that
// the difference of the displacements is the drift plus the zero-mean randomness of its random
// finite difference and midpoint. Averaged over 4000 noise steps it must match kT Δt ∂·M from
// central differences of the Stokes mobility (as above) point by point: relative L2 difference
// below 0.2 (measured 0.30, 0.22, 0.11 at 200, 1000, 4000 samples: statistics plus ~0.1 from the
// fluid starting at rest, whose long waves respond within one step by μλΔt/ρ / (1 + μλΔt/ρ) only;
// no drift gives 1, a wrong sign 2). Without noise the switch must change nothing, bit for bit.
TEST(ThermalDrift, TheAddedDriftIsKTTimesTheDivergenceOfTheMobility) {
  sim::SimParams p = ring_params({0, 0, 0}, {0, 0, 0});
  p.stepper.electro.enabled = false;  // the twisted circle is then at rest without noise
  p.stepper.steric.enabled = false;
  const rod::RodState s0 = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
  const int n = s0.size();
  // kT ∂·M by central differences (as in the test above)
  System st0(p.stepper);
  ImplicitStepper imp(st0, ImplicitParams{});
  const double delta = 0.01;
  std::vector<Vec3> F(n, Vec3::Zero()), T(n, Vec3::Zero()), Up(n), Um(n), W(n);
  std::vector<Vec3> div(n, Vec3::Zero());
  for (int l = 0; l < n; ++l)
    for (int j = 0; j < 3; ++j) {
      F[l] = Vec3::Unit(j);
      std::vector<Vec3> X = s0.X;
      X[l][j] += delta;
      imp.mobility(X, F, T, Up, W);
      X[l][j] -= 2 * delta;
      imp.mobility(X, F, T, Um, W);
      for (int k = 0; k < n; ++k) div[k] += (Up[k] - Um[k]) / (2 * delta);
      F[l].setZero();
    }
  const double kT = p.kT, dt = p.dt;
  StepperParams with = p.stepper, without = p.stepper;
  with.fluid.thermal_kT = without.fluid.thermal_kT = kT;
  with.thermal_drift = true;
  without.thermal_drift = false;
  Stepper a(with), b(without);
  const std::size_t cells = std::size_t(p.stepper.grid.n) * p.stepper.grid.n * p.stepper.grid.n;
  const int samples = 4000;
  std::vector<Vec3> mean(n, Vec3::Zero());
  for (int i = 0; i < samples; ++i) {
    rod::RodState sa = s0, sb = s0;
    for (Stepper* x : {&a, &b}) {
      for (int c = 0; c < 3; ++c) std::fill_n(x->system().fluid().velocity(c), cells, 0.0);
      x->system().set_noise_step(std::uint64_t(1000 + i));
    }
    a.step(sa);
    b.step(sb);
    for (int k = 0; k < n; ++k) mean[k] += (sa.X[k] - sb.X[k]) / double(samples);
  }
  double num = 0, den = 0;
  for (int k = 0; k < n; ++k) {
    num += (mean[k] - kT * dt * div[k]).squaredNorm();
    den += (kT * dt * div[k]).squaredNorm();
  }
  std::printf(
      "ThermalDrift: |mean one-step drift − kT Δt ∂·M| / |kT Δt ∂·M| = %.3f (%d samples; "
      "|kT Δt ∂·M| rms %.3g Å)\n",
      std::sqrt(num / den), samples, std::sqrt(den / n));
  EXPECT_LT(std::sqrt(num / den), 0.2);
  // kT = 0: thermal_drift has no effect
  with.fluid.thermal_kT = without.fluid.thermal_kT = 0;
  Stepper c(with), d(without);
  rod::RodState sc = s0, sd = s0;
  sc.X[0].x() += 0.5;  // off equilibrium, so that the step moves the rod
  sd.X[0].x() += 0.5;
  for (int i = 0; i < 3; ++i) {
    c.step(sc);
    d.step(sd);
  }
  for (int k = 0; k < n; ++k) EXPECT_EQ(sc.X[k], sd.X[k]) << k;
}

// Issue 28: the drift must not change the centroid's thermal motion (∂·M of the centroid is zero
// by translation invariance, and the force pairs of the random finite difference add no net
// force). One step of the ring from the same stationary fluid and the same noise, with and
// without the drift: the centroid's mean displacement difference is zero within its standard
// error, and its per-step variance the same within 2 % (a drift that halved or doubled the
// centroid's noise, or pushed it, fails).
TEST(ThermalDrift, TheCentroidsOneStepStatisticsAreThoseWithoutTheDrift) {
  sim::SimParams p = ring_params({0, 0, 0}, {0, 0, 0});
  p.stepper.electro.enabled = false;
  p.stepper.steric.enabled = false;
  const rod::RodState s0 = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
  StepperParams with = p.stepper, without = p.stepper;
  with.fluid.thermal_kT = without.fluid.thermal_kT = p.kT;
  with.thermal_drift = true;
  without.thermal_drift = false;
  Stepper a(with), b(without);
  const std::size_t cells = std::size_t(p.stepper.grid.n) * p.stepper.grid.n * p.stepper.grid.n;
  std::vector<double> u(3 * cells);
  // a stationary fluid: the ring held at s0, 40 steps of burn-in
  for (int i = 0; i < 40; ++i) {
    rod::RodState sb = s0;
    b.system().set_noise_step(std::uint64_t(i));
    b.step(sb);
  }
  const int samples = 1500;
  Vec3 mean_diff = Vec3::Zero();
  double sum2_diff = 0, var_a = 0, var_b = 0;
  for (int i = 0; i < samples; ++i) {
    for (int c = 0; c < 3; ++c)
      std::copy_n(b.system().fluid().velocity(c), cells, u.data() + c * cells);
    for (int c = 0; c < 3; ++c)
      std::copy_n(u.data() + c * cells, cells, a.system().fluid().velocity(c));
    rod::RodState sa = s0, sb = s0;
    a.system().set_noise_step(std::uint64_t(100 + i));
    b.system().set_noise_step(std::uint64_t(100 + i));
    a.step(sa);
    b.step(sb);  // b's fluid carries on: the next sample starts from it
    const Vec3 da = centroid(sa.X) - centroid(s0.X), db = centroid(sb.X) - centroid(s0.X);
    mean_diff += (da - db) / double(samples);
    sum2_diff += (da - db).squaredNorm();
    var_a += da.squaredNorm();
    var_b += db.squaredNorm();
  }
  const double se = std::sqrt(sum2_diff / samples / samples);  // per component, roughly
  const double ratio = var_a / var_b;
  std::printf(
      "ThermalDrift: centroid per step: mean(with − without) = (%.3g, %.3g, %.3g) Å, "
      "standard error %.3g Å; variance with / without = %.4f (rms step %.3g Å)\n",
      mean_diff.x(), mean_diff.y(), mean_diff.z(), se, ratio, std::sqrt(var_b / samples));
  EXPECT_LT(mean_diff.norm(), 5 * se + 1e-12);
  EXPECT_NEAR(ratio, 1.0, 0.02);
}

}  // namespace
}  // namespace ibrod::integrate
