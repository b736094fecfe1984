// Unit tests of FluidSolver::solve_stokes (issue 14: the Stokes-limit mobility of the implicit
// scheme): closed-form single modes, zero mean, incompressibility, linearity, and the unsteady
// step's limit. 16³, FFTW_ESTIMATE: milliseconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "fluid/navier_stokes.hpp"

namespace ibrod::fluid {
namespace {

constexpr double kPi = std::numbers::pi;

// A body force given as a whole-grid array, fed plane by plane.
struct ArrayForcing final : PlaneForcing {
  const GridSpec& g;
  const std::array<std::vector<double>, 3>& f;
  ArrayForcing(const GridSpec& grid, const std::array<std::vector<double>, 3>& force)
      : g(grid), f(force) {}
  void add_plane(int i, std::array<double*, 3> plane) const override {
    const std::size_t np = std::size_t(g.n) * g.n;
    for (int c = 0; c < 3; ++c)
      for (std::size_t t = 0; t < np; ++t) plane[c][t] += f[c][i * np + t];
  }
};

FluidParams params() {
  FluidParams p;
  p.density = 1e-24;
  p.viscosity = 1e-10;
  p.dt = 1e-10;
  p.advection = false;
  return p;
}

std::array<std::vector<double>, 3> zeros(const GridSpec& g) {
  return {std::vector<double>(g.size()), std::vector<double>(g.size()),
          std::vector<double>(g.size())};
}

TEST(Stokes, ShearModeHasTheClosedFormAmplitude) {
  // f = A sin(2π m x/L) e_y is divergence-free: u = f / (μ (4/h²) sin²(π m/n)) exactly.
  const GridSpec g{16, 200.0};
  FluidSolver fl(g, params(), 1, false);
  auto f = zeros(g);
  const int m = 2;
  const double A = 3e-7;
  for (int i = 0; i < g.n; ++i)
    for (int j = 0; j < g.n; ++j)
      for (int k = 0; k < g.n; ++k) f[1][g.index(i, j, k)] = A * std::sin(2 * kPi * m * i / g.n);
  fl.solve_stokes(ArrayForcing(g, f));
  const double s = std::sin(kPi * m / g.n);
  const double denom = params().viscosity * 4 / (g.h() * g.h()) * s * s;
  double err = 0, umax = 0;
  for (int i = 0; i < g.n; ++i) {
    const double want = A * std::sin(2 * kPi * m * i / g.n) / denom;
    for (int j = 0; j < g.n; ++j)
      for (int k = 0; k < g.n; ++k) {
        const std::size_t p = g.index(i, j, k);
        err = std::max({err, std::abs(fl.velocity(1)[p] - want), std::abs(fl.velocity(0)[p]),
                        std::abs(fl.velocity(2)[p])});
        umax = std::max(umax, std::abs(want));
      }
  }
  EXPECT_LT(err, 1e-12 * umax);  // round-off only
}

TEST(Stokes, GradientForceMakesNoFlowAndTheMeanIsDropped) {
  // f = ∇_h φ + c (a gradient plus a constant): the projection removes the gradient, the mean
  // mode (a net force, no periodic Stokes solution) is set to zero.
  const GridSpec g{16, 200.0};
  FluidSolver fl(g, params(), 1, false);
  auto f = zeros(g);
  for (int i = 0; i < g.n; ++i)
    for (int j = 0; j < g.n; ++j)
      for (int k = 0; k < g.n; ++k) {
        // φ = cos(2π 3 j/n): D_h φ along y, central difference
        const double d =
            (std::cos(2 * kPi * 3 * (j + 1) / g.n) - std::cos(2 * kPi * 3 * (j - 1) / g.n)) /
            (2 * g.h());
        f[1][g.index(i, j, k)] = 1e-6 * d + 2e-7;
        f[0][g.index(i, j, k)] = -5e-7;
      }
  fl.solve_stokes(ArrayForcing(g, f));
  double umax = 0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t p = 0; p < g.size(); ++p) umax = std::max(umax, std::abs(fl.velocity(c)[p]));
  // scale: the same force as a shear mode would give |u| ~ 1e-6 / (μ 4/h² sin²(π/16)) ~ 1e8
  EXPECT_LT(umax, 1e-6);
}

TEST(Stokes, RandomForceGivesADivergenceFreeZeroMeanLinearResponse) {
  const GridSpec g{16, 200.0};
  FluidSolver fl(g, params(), 1, false);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-1e-6, 1e-6);
  auto f1 = zeros(g), f2 = zeros(g), f12 = zeros(g);
  for (int c = 0; c < 3; ++c)
    for (std::size_t p = 0; p < g.size(); ++p) {
      f1[c][p] = U(rng);
      f2[c][p] = U(rng);
      f12[c][p] = 2 * f1[c][p] - 3 * f2[c][p];
    }
  auto solve = [&](const std::array<std::vector<double>, 3>& f) {
    fl.solve_stokes(ArrayForcing(g, f));
    std::array<std::vector<double>, 3> u;
    for (int c = 0; c < 3; ++c) u[c].assign(fl.velocity(c), fl.velocity(c) + g.size());
    return u;
  };
  const auto u1 = solve(f1), u2 = solve(f2), u12 = solve(f12);
  EXPECT_LT(
      fl.max_divergence() * g.h(), 1e-10 * [&] {
        double m = 0;
        for (double v : u12[0]) m = std::max(m, std::abs(v));
        return m;
      }());
  double lin = 0, umax = 0;
  for (int c = 0; c < 3; ++c) {
    double mean = 0;
    for (std::size_t p = 0; p < g.size(); ++p) {
      lin = std::max(lin, std::abs(u12[c][p] - (2 * u1[c][p] - 3 * u2[c][p])));
      umax = std::max(umax, std::abs(u12[c][p]));
      mean += u1[c][p];
    }
    EXPECT_LT(std::abs(mean / double(g.size())), 1e-12 * umax);
  }
  EXPECT_LT(lin, 1e-12 * umax);
}

TEST(Stokes, IsTheLimitOfTheUnsteadyStepFromRest) {
  // From rest, one unsteady Stokes step gives P f̂/(ρ/Δt − μL̂): as ρ/Δt → 0 it tends to the
  // Stokes solution, with relative difference ~ ρh²/(μΔt).
  const GridSpec g{16, 200.0};
  FluidParams p = params();
  p.dt = 1e-6;  // ρh²/(μΔt) ≈ 1.6e-6
  FluidSolver unsteady(g, p, 1, false), stokes(g, params(), 1, false);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-1e-6, 1e-6);
  auto f = zeros(g);
  for (int c = 0; c < 3; ++c)
    for (std::size_t q = 0; q < g.size(); ++q) f[c][q] = U(rng);
  // a zero-mean force: the unsteady step would accelerate the mean
  for (int c = 0; c < 3; ++c) {
    double m = 0;
    for (double v : f[c]) m += v;
    for (double& v : f[c]) v -= m / double(g.size());
  }
  const auto fa = unsteady.force();
  for (int c = 0; c < 3; ++c) std::copy(f[c].begin(), f[c].end(), fa[c]);
  unsteady.step();
  stokes.solve_stokes(ArrayForcing(g, f));
  double d = 0, umax = 0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t q = 0; q < g.size(); ++q) {
      d = std::max(d, std::abs(unsteady.velocity(c)[q] - stokes.velocity(c)[q]));
      umax = std::max(umax, std::abs(stokes.velocity(c)[q]));
    }
  EXPECT_LT(d, 1e-4 * umax);  // measured ~1e-6 relative
  EXPECT_GT(d, 0.0);
}

}  // namespace
}  // namespace ibrod::fluid

namespace ibrod::fluid {
namespace {

// Issue 28: the Stokes-limit noise (solve_stokes with thermal = true) satisfies the discrete
// fluctuation–dissipation relation Cov(u_c(x), u_d(y)) = (2kT/Δt) G_cd(x, y), G the Stokes
// response to a unit point force (force density e_d/h³ on one node), at offsets 0 and (1, 1, 0)
// and components xx, yy, zz, xy: 300 draws of the noise alone, covariances averaged over all
// nodes (translation invariance), against G from one deterministic solve. Measured within ~1 %;
// the test allows 3 % (an amplitude 4 % too large in the variance fails it), plus the noise is
// divergence-free, zero-mean, and the same bits for the same counter.
TEST(Stokes, ThermalNoiseHasTheCovarianceOfTheStokesResponse) {
  const GridSpec g{16, 200.0};
  FluidParams p = params();
  p.thermal_kT = 414.2;
  p.seed = 7;
  FluidSolver fl(g, p, 1, false);
  const std::size_t n3 = g.size();
  const double h3 = g.h() * g.h() * g.h();
  const auto none = zeros(g);
  // G: the response at every node to a unit point force at node 0, per force component d
  std::array<std::array<std::vector<double>, 3>, 3> G;
  for (int d = 0; d < 3; ++d) {
    auto f = zeros(g);
    f[d][g.index(0, 0, 0)] = 1.0 / h3;
    fl.solve_stokes(ArrayForcing(g, f));
    for (int c = 0; c < 3; ++c) G[d][c].assign(fl.velocity(c), fl.velocity(c) + n3);
  }
  struct Pair {
    int c, d, di, dj;
  };
  const std::vector<Pair> pairs = {{0, 0, 0, 0}, {1, 1, 0, 0}, {2, 2, 0, 0},
                                   {0, 1, 1, 1}, {0, 0, 1, 1}, {2, 2, 1, 1}};
  std::vector<double> cov(pairs.size(), 0.0);
  const int samples = 300;
  double max_div = 0, max_mean = 0;
  for (int s = 0; s < samples; ++s) {
    fl.set_noise_step(std::uint64_t(1000 + s));
    fl.solve_stokes(ArrayForcing(g, none), nullptr, true);
    for (std::size_t q = 0; q < pairs.size(); ++q) {
      const Pair& pr = pairs[q];
      const double* uc = fl.velocity(pr.c);
      const double* ud = fl.velocity(pr.d);
      double acc = 0;
      for (int i = 0; i < g.n; ++i)
        for (int j = 0; j < g.n; ++j)
          for (int k = 0; k < g.n; ++k)
            acc += uc[g.index(i, j, k)] * ud[g.index((i + pr.di) % g.n, (j + pr.dj) % g.n, k)];
      cov[q] += acc / double(n3) / samples;
    }
    max_div = std::max(max_div, fl.max_divergence());
    for (int c = 0; c < 3; ++c) {
      double m = 0;
      for (std::size_t t = 0; t < n3; ++t) m += fl.velocity(c)[t];
      max_mean = std::max(max_mean, std::abs(m / double(n3)));
    }
  }
  double umax = 0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t t = 0; t < n3; ++t) umax = std::max(umax, std::abs(fl.velocity(c)[t]));
  for (std::size_t q = 0; q < pairs.size(); ++q) {
    const Pair& pr = pairs[q];
    // Cov(u_c(x), u_d(x + o)) = (2kT/Δt) G_cd(x, x + o) = (2kT/Δt) × (response in c at node o
    // to a force d at 0... by symmetry of G, the response in d at o to a force c at 0)
    const double expect =
        2 * p.thermal_kT / p.dt * G[pr.c][pr.d][g.index(pr.di % g.n, pr.dj % g.n, 0)];
    std::printf("Stokes noise: cov(u%d(x), u%d(x+(%d,%d,0))) / (2kT/Δt) G = %.4f\n", pr.c, pr.d,
                pr.di, pr.dj, cov[q] / expect);
    EXPECT_NEAR(cov[q] / expect, 1.0, 0.03) << q;
  }
  EXPECT_LT(max_div * p.dt * g.h(), 1e-12 * umax * p.dt + 1e-300);  // |D·u| h / |u| < 1e-12
  EXPECT_LT(max_mean, 1e-12 * umax);
  // the same counter, the same bits
  fl.set_noise_step(1000);
  fl.solve_stokes(ArrayForcing(g, none), nullptr, true);
  std::vector<double> a(fl.velocity(0), fl.velocity(0) + n3);
  fl.solve_stokes(ArrayForcing(g, none), nullptr, true);
  EXPECT_TRUE(std::equal(a.begin(), a.end(), fl.velocity(0)));
  EXPECT_EQ(fl.noise_step(), 1000u);
}

}  // namespace
}  // namespace ibrod::fluid
