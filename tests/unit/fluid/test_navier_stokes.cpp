// Unit tests of the periodic Navier–Stokes step (MODEL §4): projection, closed-form decay and
// steady Stokes solutions, skew-symmetry of advection against a direct oracle, energy and
// momentum balances, thread independence. Grids 16³ (32³ for threads) with FFTW_ESTIMATE: each
// test ≪ 1 s.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "fluid/advection.hpp"
#include "fluid/navier_stokes.hpp"

namespace ibrod::fluid {
namespace {

using Field = std::array<std::vector<double>, 3>;
constexpr double kPi = std::numbers::pi;

// Reference parameters of MODEL §1 (g, Å, s) on a coarse grid.
GridSpec small_grid(int n = 16) { return GridSpec{n, 725.0}; }
FluidParams reference_params(bool advection) {
  FluidParams p;
  p.density = 1e-24;
  p.viscosity = 1e-10;
  p.dt = 1e-10;
  p.advection = advection;
  return p;
}

Field zeros(const GridSpec& g) {
  return {std::vector<double>(g.size()), std::vector<double>(g.size()),
          std::vector<double>(g.size())};
}

Field random_field(const GridSpec& g, double amplitude, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> dist(-amplitude, amplitude);
  Field f = zeros(g);
  for (auto& c : f)
    for (auto& v : c) v = dist(rng);
  return f;
}

// Direct oracle of the central difference D_j φ at (i, j, k), written from the definition.
double central(const GridSpec& g, const std::vector<double>& phi, int dir, int i, int j, int k) {
  const int d[3] = {dir == 0, dir == 1, dir == 2};
  const double p = phi[g.index(g.wrap(i + d[0]), g.wrap(j + d[1]), g.wrap(k + d[2]))];
  const double m = phi[g.index(g.wrap(i - d[0]), g.wrap(j - d[1]), g.wrap(k - d[2]))];
  return (p - m) / (2.0 * g.h());
}

// Discrete curl with central differences: D_h·(D_h × A) = 0 exactly in exact arithmetic, so
// this gives divergence-free fields independent of the solver's projection.
Field curl(const GridSpec& g, const Field& A) {
  Field u = zeros(g);
  for (int i = 0; i < g.n; ++i)
    for (int j = 0; j < g.n; ++j)
      for (int k = 0; k < g.n; ++k) {
        const std::size_t q = g.index(i, j, k);
        u[0][q] = central(g, A[2], 1, i, j, k) - central(g, A[1], 2, i, j, k);
        u[1][q] = central(g, A[0], 2, i, j, k) - central(g, A[2], 0, i, j, k);
        u[2][q] = central(g, A[1], 0, i, j, k) - central(g, A[0], 1, i, j, k);
      }
  return u;
}

Field snapshot(const FluidSolver& s);

double oracle_max_divergence(const GridSpec& g, const Field& c) {
  double m = 0.0;
  for (int i = 0; i < g.n; ++i)
    for (int j = 0; j < g.n; ++j)
      for (int k = 0; k < g.n; ++k) {
        double div = 0.0;
        for (int d = 0; d < 3; ++d) div += central(g, c[d], d, i, j, k);
        m = std::max(m, std::abs(div));
      }
  return m;
}

// S_h(u)_i = ½ Σ_j [u_j D_j u_i + D_j(u_j u_i)] straight from MODEL §4, as the slow oracle.
Field oracle_advection(const GridSpec& g, const Field& u) {
  Field s = zeros(g);
  std::vector<double> prod(g.size());
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      for (std::size_t q = 0; q < g.size(); ++q) prod[q] = u[b][q] * u[a][q];
      for (int i = 0; i < g.n; ++i)
        for (int j = 0; j < g.n; ++j)
          for (int k = 0; k < g.n; ++k) {
            const std::size_t q = g.index(i, j, k);
            s[a][q] +=
                0.5 * (u[b][q] * central(g, u[a], b, i, j, k) + central(g, prod, b, i, j, k));
          }
    }
  return s;
}

// Measured errors go to the XML report (--gtest_output=xml), so the bounds' comments can be
// checked.
void record(const std::string& key, double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", value);
  ::testing::Test::RecordProperty(key, buf);
}

void load(FluidSolver& s, const Field& u) {
  for (int c = 0; c < 3; ++c) std::copy(u[c].begin(), u[c].end(), s.velocity(c));
}
void load_force(FluidSolver& s, const Field& f) {
  for (int c = 0; c < 3; ++c) std::copy(f[c].begin(), f[c].end(), s.force(c));
}
Field snapshot(const FluidSolver& s) {
  Field u = zeros(s.grid());
  for (int c = 0; c < 3; ++c)
    std::copy(s.velocity(c), s.velocity(c) + s.grid().size(), u[c].begin());
  return u;
}
double max_abs(const Field& u) {
  double m = 0.0;
  for (const auto& c : u)
    for (double v : c) m = std::max(m, std::abs(v));
  return m;
}
double max_diff(const Field& a, const Field& b) {
  double m = 0.0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t q = 0; q < a[c].size(); ++q) m = std::max(m, std::abs(a[c][q] - b[c][q]));
  return m;
}

// ---------------------------------------------------------------------------------------------

TEST(FluidSolver, RejectsOddOrTinyGrids) {
  EXPECT_THROW(FluidSolver(GridSpec{15, 725.0}, reference_params(true), 1, false),
               std::invalid_argument);
  EXPECT_THROW(FluidSolver(GridSpec{2, 725.0}, reference_params(true), 1, false),
               std::invalid_argument);
  EXPECT_THROW(FluidSolver(GridSpec{0, 725.0}, reference_params(true), 1, false),
               std::invalid_argument);
  EXPECT_NO_THROW(FluidSolver(GridSpec{4, 725.0}, reference_params(true), 1, false));
}

TEST(FluidSolver, StartsAtRestAndEnergyFormula) {
  const GridSpec g = small_grid();
  FluidSolver s(g, reference_params(true), 1, false);
  EXPECT_EQ(s.kinetic_energy(), 0.0);
  // uniform u = (1, 2, 3) Å/s: E = ½ρ·14·n³h³ = 7ρL³
  for (int c = 0; c < 3; ++c) std::fill(s.velocity(c), s.velocity(c) + g.size(), c + 1.0);
  const double expected = 7.0 * 1e-24 * g.L * g.L * g.L;
  EXPECT_NEAR(s.kinetic_energy(), expected, 1e-13 * expected);
}

TEST(FluidSolver, MaxDivergenceMatchesOracle) {
  const GridSpec g = small_grid();
  FluidSolver s(g, reference_params(true), 1, false);
  load(s, random_field(g, 1.0, 7));
  const double oracle = oracle_max_divergence(g, snapshot(s));
  EXPECT_GT(oracle, 0.1 / g.h());  // a random field is far from solenoidal
  EXPECT_NEAR(s.max_divergence(), oracle, 1e-14 * oracle);
}

// Test 1: one step projects a random, non-solenoidal state onto D_h·u = 0.
TEST(FluidSolver, StepLeavesDivergenceAtRoundOff) {
  const GridSpec g = small_grid();
  const FluidParams p = reference_params(true);
  FluidSolver s(g, p, 1, false);
  const double U = 1e4;  // Å/s
  load(s, random_field(g, U, 1));
  // force comparable to the inertial term ρU/Δt so both parts of r̂ matter
  load_force(s, random_field(g, p.density * U / p.dt, 2));
  const double before = oracle_max_divergence(g, snapshot(s));
  s.step();
  const double after = oracle_max_divergence(g, snapshot(s));
  const double scale = max_abs(snapshot(s)) / g.h();
  EXPECT_GT(before, 0.1 * U / g.h());
  // measured 3e-16 relative; bound 1e-12
  EXPECT_LT(after, 1e-12 * scale) << "after/scale = " << after / scale;
  EXPECT_LT(s.max_divergence(), 1e-12 * scale);
  record("relative_divergence", after / scale);
}

// Test 2: divergence-free single modes for which S_h vanishes are exact discrete solutions that
// decay by (ρ/Δt)/(ρ/Δt − μL̂(k)) per step, with or without advection.
struct ModeCase {
  const char* name;
  int m;     // wavenumber
  int kind;  // 0: shear u_z(x); 1: diagonal; 2: Nyquist
};

void check_mode_decay(const ModeCase& mc, bool advection) {
  const GridSpec g = small_grid();
  const FluidParams p = reference_params(advection);
  FluidSolver s(g, p, 1, false);
  const double A = 3e3, h = g.h();
  Field u0 = zeros(g);
  double lap = 0.0;  // −L̂(k), Å⁻²
  const double sx2 = std::pow(std::sin(kPi * mc.m / g.n), 2);
  for (int i = 0; i < g.n; ++i)
    for (int j = 0; j < g.n; ++j)
      for (int k = 0; k < g.n; ++k) {
        const std::size_t q = g.index(i, j, k);
        if (mc.kind == 0) {  // (0, 0, A sin(2πm x/L))
          u0[2][q] = A * std::sin(2 * kPi * mc.m * i / g.n);
        } else if (mc.kind == 1) {  // A(sin φ, −sin φ, 0), φ = 2πm(x + y)/L
          const double v = A * std::sin(2 * kPi * mc.m * (i + j) / g.n);
          u0[0][q] = v;
          u0[1][q] = -v;
        } else {  // checkerboard (A(−1)^i, 0, 0): invisible to D_h and G_h, damped by L_h
          u0[0][q] = (i % 2 == 0) ? A : -A;
        }
      }
  lap = (mc.kind == 1 ? 2.0 : 1.0) * 4.0 / (h * h) * (mc.kind == 2 ? 1.0 : sx2);
  load(s, u0);
  ASSERT_LT(oracle_max_divergence(g, snapshot(s)), 1e-12 * A / h) << mc.name;
  const double a = (p.density / p.dt) / (p.density / p.dt + p.viscosity * lap);
  ASSERT_LT(a, 0.95) << "decay must be visible";  // not a vacuous test
  double worst_amplitude = 0.0, worst_pointwise = 0.0;
  double factor = 1.0;
  for (int step = 1; step <= 5; ++step) {
    s.zero_force();
    s.step();
    factor *= a;
    // amplitude of the mode = projection of u onto u0: filters out the ~1e-16 A round-off noise
    // in the other modes, which decay more slowly (the k = 0 mode not at all)
    // (long double: a plain sum of 4096 near-equal terms drifts by ~1e-14 relative)
    const Field u = snapshot(s);
    long double uu0 = 0.0, u0u0 = 0.0;
    for (int c = 0; c < 3; ++c)
      for (std::size_t q = 0; q < g.size(); ++q) {
        uu0 += (long double)u[c][q] * u0[c][q];
        u0u0 += (long double)u0[c][q] * u0[c][q];
      }
    worst_amplitude = std::max(worst_amplitude, std::abs(double(uu0 / u0u0) / factor - 1.0));
    Field expected = u0;
    for (auto& c : expected)
      for (auto& v : c) v *= factor;
    worst_pointwise = std::max(worst_pointwise, max_diff(u, expected) / A);
  }
  const std::string what = std::string(mc.name) + (advection ? " advection" : " Stokes");
  // amplitude ratio: measured ≤ 9e-16 (m = 3 after 5 steps, a⁵ ≈ 6e-5); bound 1e-12
  EXPECT_LT(worst_amplitude, 1e-12) << what;
  // pointwise, relative to the initial amplitude: measured ≤ 3e-16; bound 1e-14
  EXPECT_LT(worst_pointwise, 1e-14) << what;
  record(what + " amplitude", worst_amplitude);
  record(what + " pointwise", worst_pointwise);
}

TEST(FluidSolver, SingleModeDecaysByExactFactorStokes) {
  for (const ModeCase mc : {ModeCase{"shear m=1", 1, 0}, ModeCase{"shear m=3", 3, 0},
                            ModeCase{"diagonal m=1", 1, 1}, ModeCase{"checkerboard", 0, 2}})
    check_mode_decay(mc, false);
}

TEST(FluidSolver, ShearModeIsExactWithAdvection) {
  for (const ModeCase mc : {ModeCase{"shear m=1", 1, 0}, ModeCase{"shear m=3", 3, 0},
                            ModeCase{"diagonal m=1", 1, 1}, ModeCase{"checkerboard", 0, 2}})
    check_mode_decay(mc, true);
}

// Test 3: a steady force converges to the exact discrete Stokes solution
// u_y = F0 sin(2πx/L) / (μ (4/h²) sin²(π/n)).
TEST(FluidSolver, SteadyForceGivesDiscreteStokesSolution) {
  const GridSpec g = small_grid();
  FluidParams p = reference_params(false);
  p.dt = 1e-6;  // ρ/Δt ≪ μ|L̂|: contraction factor ≈ 1.4e-4 per step, converged in ~4 steps
  FluidSolver s(g, p, 1, false);
  const double F0 = 1e-12, h = g.h();
  const double lap = 4.0 / (h * h) * std::pow(std::sin(kPi / g.n), 2);
  const double U = F0 / (p.viscosity * lap);
  for (int step = 0; step < 8; ++step) {
    s.zero_force();
    for (int i = 0; i < g.n; ++i)
      for (int j = 0; j < g.n; ++j)
        for (int k = 0; k < g.n; ++k)
          s.force(1)[g.index(i, j, k)] = F0 * std::sin(2 * kPi * i / g.n);
    s.step();
  }
  double worst = 0.0;
  for (int i = 0; i < g.n; ++i)
    for (int j = 0; j < g.n; ++j)
      for (int k = 0; k < g.n; ++k) {
        const std::size_t q = g.index(i, j, k);
        worst = std::max({worst, std::abs(s.velocity(1)[q] - U * std::sin(2 * kPi * i / g.n)),
                          std::abs(s.velocity(0)[q]), std::abs(s.velocity(2)[q])});
      }
  // measured 2.8e-13 relative; bound 1e-10. (Round-off in the k = 0 force component is not
  // damped by viscosity and grows by Δt/ρ per step: the error is far above 1e-16 for Δt = 1e-6.)
  EXPECT_LT(worst / U, 1e-10) << "relative error " << worst / U;
  record("relative_error", worst / U);
}

// Test 4a: the fused pass equals the direct definition of S_h (the slow oracle), and adds a·u.
TEST(Advection, FusedPassMatchesDirectOracle) {
  const GridSpec g = small_grid();
  std::vector<int> next, prev;
  detail::make_neighbour_tables(g.n, next, prev);
  const Field u = random_field(g, 2.0, 3);
  const Field r0 = random_field(g, 1.0, 4);
  Field r = r0;
  const double a = 0.7, b = 1.3;
  detail::accumulate_rhs(g, next.data(), prev.data(), {u[0].data(), u[1].data(), u[2].data()},
                         {r[0].data(), r[1].data(), r[2].data()}, a, b, 1);
  const Field s = oracle_advection(g, u);
  Field expected = r0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t q = 0; q < g.size(); ++q) expected[c][q] += a * u[c][q] - b * s[c][q];
  // measured 1.9e-16 relative; bound 1e-13
  EXPECT_LT(max_diff(r, expected), 1e-13 * max_abs(expected));
  record("relative_error", max_diff(r, expected) / max_abs(expected));
  EXPECT_GT(max_abs(s), 1e-3);  // the advection term is really there

  // b = 0 skips advection: only a·u is added
  r = r0;
  detail::accumulate_rhs(g, next.data(), prev.data(), {u[0].data(), u[1].data(), u[2].data()},
                         {r[0].data(), r[1].data(), r[2].data()}, a, 0.0, 1);
  expected = r0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t q = 0; q < g.size(); ++q) expected[c][q] += a * u[c][q];
  EXPECT_LT(max_diff(r, expected), 1e-15 * max_abs(expected));
}

// Test 4b: Σ_x u·S_h(u) = 0 for any u (summation by parts), to round-off.
TEST(Advection, IsSkewSymmetric) {
  const GridSpec g = small_grid();
  std::vector<int> next, prev;
  detail::make_neighbour_tables(g.n, next, prev);
  for (int divergence_free = 0; divergence_free < 2; ++divergence_free) {
    const Field u = divergence_free ? curl(g, random_field(g, 100.0, 5)) : random_field(g, 1.0, 6);
    Field s = zeros(g);
    detail::accumulate_rhs(g, next.data(), prev.data(), {u[0].data(), u[1].data(), u[2].data()},
                           {s[0].data(), s[1].data(), s[2].data()}, 0.0, -1.0, 1);  // s = S_h(u)
    double work = 0.0, scale = 0.0;
    for (int c = 0; c < 3; ++c)
      for (std::size_t q = 0; q < g.size(); ++q) {
        work += u[c][q] * s[c][q];
        scale += std::abs(u[c][q] * s[c][q]);
      }
    ASSERT_GT(scale, 0.0);
    // measured 5e-18 relative; bound 1e-13
    EXPECT_LT(std::abs(work), 1e-13 * scale) << "divergence_free=" << divergence_free;
    record(divergence_free ? "relative_work_solenoidal" : "relative_work_random", work / scale);
  }
}

// Test 4c: inviscid, unforced, advective step from a solenoidal uⁿ. With P uⁿ = uⁿ the step is
// uⁿ⁺¹ = uⁿ − Δt P S_h(uⁿ), and skew-symmetry makes the change orthogonal to uⁿ, so
//   E(uⁿ⁺¹) − E(uⁿ) = ½ρh³ Σ|uⁿ⁺¹ − uⁿ|² = ½ρh³ Δt² Σ|P S_h|²  ≥ 0.
// The kinetic energy does NOT stay constant: explicit (forward-Euler) advection adds exactly this
// O(Δt²) amount, which viscosity (or a small enough Δt) must outweigh. That identity is asserted.
TEST(FluidSolver, InviscidAdvectionEnergyIdentity) {
  const GridSpec g = small_grid();
  FluidParams p = reference_params(true);
  p.viscosity = 0.0;
  // |u| ~ 2e3 Å/s, h ≈ 45 Å: Δt = 1e-4 s gives |Δu|/|u| ~ 1e-2 per step. At the reference Δt the
  // change (~1e-8 |u|) would drown in the round-off of the projection (~1e-15 |u|).
  p.dt = 1e-4;
  FluidSolver s(g, p, 1, false);
  const Field u0 = curl(g, random_field(g, 1e5, 8));
  load(s, u0);
  const double h3 = std::pow(g.h(), 3);
  double e_prev = s.kinetic_energy();
  const double e0 = e_prev;
  Field prev = u0;
  for (int step = 0; step < 3; ++step) {
    s.zero_force();
    s.step();
    const Field now = snapshot(s);
    double dot = 0.0, du2 = 0.0, norms = 0.0;
    for (int c = 0; c < 3; ++c)
      for (std::size_t q = 0; q < g.size(); ++q) {
        const double du = now[c][q] - prev[c][q];
        dot += prev[c][q] * du;
        du2 += du * du;
        norms += std::abs(prev[c][q] * du);
      }
    const double e = s.kinetic_energy();
    const double predicted = 0.5 * p.density * h3 * du2;
    ASSERT_GT(du2, 0.0);
    // change orthogonal to the state: measured 2.4e-14 relative; bound 1e-11
    EXPECT_LT(std::abs(dot), 1e-11 * norms) << "step " << step << ": " << dot / norms;
    // growth equals ½ρh³Σ|Δu|²: measured 9e-10 relative (a difference of two energies; the
    // growth itself is 4e-6 E per step); bound 1e-6
    EXPECT_GT(e - e_prev, 0.0);
    EXPECT_NEAR(e - e_prev, predicted, 1e-6 * predicted)
        << "step " << step << ": " << (e - e_prev) / predicted - 1;
    record("step" + std::to_string(step) + "_dot", dot / norms);
    record("step" + std::to_string(step) + "_energy_identity", (e - e_prev) / predicted - 1);
    record("step" + std::to_string(step) + "_relative_growth", (e - e_prev) / e_prev);
    e_prev = e;
    prev = now;
  }
  EXPECT_LT(e_prev - e0, 1e-3 * e0);  // second order in Δt: small even at this large Δt
}

// Viscous Stokes without force: every Fourier mode is multiplied by a factor in (0, 1], so the
// kinetic energy strictly decreases.
TEST(FluidSolver, ViscousStokesEnergyDecreases) {
  const GridSpec g = small_grid();
  FluidSolver s(g, reference_params(false), 1, false);
  load(s, curl(g, random_field(g, 1e5, 9)));
  double e = s.kinetic_energy();
  for (int step = 0; step < 4; ++step) {
    s.zero_force();
    s.step();
    const double e_new = s.kinetic_energy();
    EXPECT_LT(e_new, e);
    e = e_new;
  }
}

// Test 5: a uniform force density F raises the mean velocity by FΔt/ρ per step (k = 0 mode),
// with advection on from a solenoidal state plus a mean flow.
TEST(FluidSolver, UniformForceMeanMomentum) {
  const GridSpec g = small_grid();
  const FluidParams p = reference_params(true);
  FluidSolver s(g, p, 1, false);
  Field u0 = curl(g, random_field(g, 1e5, 10));
  const double U0[3] = {300.0, -200.0, 100.0};  // Å/s
  for (int c = 0; c < 3; ++c)
    for (auto& v : u0[c]) v += U0[c];
  load(s, u0);
  const double F[3] = {2e-12, -1e-12, 5e-13};  // g Å⁻² s⁻²; FΔt/ρ = 200, −100, 50 Å/s
  auto mean = [&](int c) {
    double m = 0.0;
    for (std::size_t q = 0; q < g.size(); ++q) m += s.velocity(c)[q];
    return m / double(g.size());
  };
  double worst = 0.0;
  for (int step = 1; step <= 3; ++step) {
    s.zero_force();
    for (int c = 0; c < 3; ++c) std::fill(s.force(c), s.force(c) + g.size(), F[c]);
    s.step();
    for (int c = 0; c < 3; ++c) {
      const double expected = U0[c] + step * F[c] * p.dt / p.density;
      // measured 5.7e-16 of max|u|; bound 1e-11 of max|u|
      EXPECT_NEAR(mean(c), expected, 1e-11 * max_abs(u0)) << "step " << step << " c " << c;
      worst = std::max(worst, std::abs(mean(c) - expected) / max_abs(u0));
    }
  }
  record("mean_error_over_max_u", worst);
}

// Test 6: 1 and 2 threads (FFTW + OpenMP) give the same field to round-off.
TEST(FluidSolver, ThreadIndependence) {
  const GridSpec g = small_grid(32);  // large enough that FFTW's threaded plans really split
  const FluidParams p = reference_params(true);
  const Field u0 = random_field(g, 1e4, 11);
  const Field f = random_field(g, p.density * 1e4 / p.dt, 12);
  Field result[2];
  double energy[2], divergence[2];
  for (int t = 1; t <= 2; ++t) {
    FluidSolver s(g, p, t, false);
    EXPECT_EQ(s.threads(), t);
    load(s, u0);
    for (int step = 0; step < 3; ++step) {
      s.zero_force();
      load_force(s, f);
      s.step();
    }
    result[t - 1] = snapshot(s);
    energy[t - 1] = s.kinetic_energy();
    divergence[t - 1] = s.max_divergence();
  }
  // bitwise equal by design: every plane and y-slice is transformed by the same single-threaded
  // FFTW plan and solved by the same code, whichever thread takes it
  EXPECT_EQ(max_diff(result[0], result[1]), 0.0);
  record("relative_difference", max_diff(result[0], result[1]) / max_abs(result[0]));
  EXPECT_EQ(energy[0], energy[1]);
  EXPECT_EQ(divergence[0], divergence[1]);
}

// A body force supplied plane by plane (what the IB coupling does) and a sampler reading the new
// velocity plane by plane, against the force array and velocity() of the plain step.
struct FieldForcing final : PlaneForcing {
  const Field& f;
  GridSpec g;
  FieldForcing(const Field& field, const GridSpec& grid) : f(field), g(grid) {}
  void add_plane(int i, std::array<double*, 3> plane) const override {
    const std::size_t np = std::size_t(g.n) * g.n;
    for (int c = 0; c < 3; ++c)
      for (std::size_t q = 0; q < np; ++q) plane[c][q] += f[c][i * np + q];
  }
};
struct FieldSampler final : PlaneSampler {
  Field& out;
  GridSpec g;
  FieldSampler(Field& field, const GridSpec& grid) : out(field), g(grid) {}
  void sample_plane(int i, std::array<const double*, 3> plane) const override {
    const std::size_t np = std::size_t(g.n) * g.n;
    for (int c = 0; c < 3; ++c) std::copy_n(plane[c], np, out[c].begin() + i * np);
  }
};

TEST(FluidSolver, PlaneForcingAndSamplerMatchTheForceArrayStep) {
  const GridSpec g = small_grid(16);
  const FluidParams p = reference_params(true);
  const Field u0 = random_field(g, 1e4, 21);
  const Field f = random_field(g, p.density * 1e4 / p.dt, 22);
  FluidSolver a(g, p, 2, false), b(g, p, 2, false);
  load(a, u0);
  load(b, u0);
  Field sampled = zeros(g);
  for (int step = 0; step < 3; ++step) {
    a.begin_step();
    load_force(a, f);
    a.finish_step();
    b.begin_step();
    b.step(FieldForcing(f, g), FieldSampler(sampled, g));
    // the sampler saw exactly the final planes of uⁿ⁺¹
    EXPECT_EQ(max_diff(sampled, snapshot(b)), 0.0);
  }
  // the same sum in another order: r + f against f + r
  EXPECT_LE(max_diff(snapshot(a), snapshot(b)), 1e-13 * max_abs(snapshot(a)));
  EXPECT_GT(max_abs(snapshot(a)), 0.0);
  // the force array was consumed and left zero, so the next step needs no zeroing pass
  Field left = zeros(g);
  for (int c = 0; c < 3; ++c) std::copy_n(a.force(c), g.size(), left[c].begin());
  EXPECT_EQ(max_abs(left), 0.0);
}

TEST(FluidSolver, BeginStepClearsAForceArrayWrittenOutsideAStep) {
  // force() written but never stepped (e.g. a caller that gave up): begin_step() must not let
  // that force leak into the next step
  const GridSpec g = small_grid(8);
  const FluidParams p = reference_params(false);
  FluidSolver a(g, p, 1, false), b(g, p, 1, false);
  load_force(a, random_field(g, 1.0, 31));
  a.begin_step();
  a.finish_step();
  b.begin_step();
  b.finish_step();
  EXPECT_EQ(max_abs(snapshot(a)), 0.0);
  EXPECT_EQ(max_abs(snapshot(b)), 0.0);
}

TEST(FluidSolver, SplitFftsOnlyRoundTripScalesByGridSize) {
  // the benchmark aid for the step's own transforms: forward + backward multiplies by n³
  const GridSpec g = small_grid(8);
  FluidSolver s(g, reference_params(true), 2, false);
  const Field f = random_field(g, 1.0, 14);
  load_force(s, f);
  s.run_split_ffts_only();
  Field expected = f;
  for (auto& c : expected)
    for (auto& v : c) v *= double(g.size());
  EXPECT_LT(max_diff(snapshot(s), expected), 1e-12 * max_abs(expected));
}

TEST(FluidSolver, RunFftsOnlyRoundTripScalesByGridSize) {
  // The unnormalised forward + backward pair multiplies by n³: a check that the benchmark aid
  // really runs the two plans on the solver's buffers (force in, velocity out).
  const GridSpec g = small_grid(8);
  FluidSolver s(g, reference_params(true), 1, false);
  const Field f = random_field(g, 1.0, 13);
  load_force(s, f);
  s.run_ffts_only();
  Field expected = f;
  for (auto& c : expected)
    for (auto& v : c) v *= double(g.size());
  EXPECT_LT(max_diff(snapshot(s), expected), 1e-12 * max_abs(expected));
  record("relative_error", max_diff(snapshot(s), expected) / max_abs(expected));
}

}  // namespace
}  // namespace ibrod::fluid
