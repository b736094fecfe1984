// Unit tests of the fluid's thermal noise (docs/thermal.md): the Philox generator against the
// published known-answer vectors, the discrete fluctuation–dissipation value of the equal-time
// covariance of every Fourier mode of u, reproducibility (seed, thread count, resume from the
// noise counter), and the uniform body force of the k = 0 mode. 16³, FFTW_ESTIMATE: about a
// second.
#include <fftw3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

#include "core/philox.hpp"
#include "fluid/navier_stokes.hpp"

namespace ibrod::fluid {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(Philox, KnownAnswerVectors) {
  // Salmon et al. (SC 2011), the known-answer vectors of Philox4x32-10
  EXPECT_EQ(philox4x32_10({0, 0, 0, 0}, 0, 0),
            (Philox4x32{0x6627e8d5u, 0xe169c58du, 0xbc57ac4cu, 0x9b00dbd8u}));
  EXPECT_EQ(
      philox4x32_10({0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu}, 0xffffffffu, 0xffffffffu),
      (Philox4x32{0x408f276du, 0x41c83b0eu, 0xa20bc7c6u, 0x6d5451fdu}));
  EXPECT_EQ(
      philox4x32_10({0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u}, 0xa4093822u, 0x299f31d0u),
      (Philox4x32{0xd16cfe09u, 0x94fdccebu, 0x5001e420u, 0x24126ea1u}));
}

TEST(Philox, SixUnitVarianceNumbersPerOutput) {
  // mean 0, variance 1, fourth moment 9/5 (uniform) of each of the six numbers, and no
  // correlation between them, over 10⁵ outputs (standard errors 0.003, 0.003, 0.008; bounds ≥ 5 of
  // them)
  double s1[6] = {}, s2[6] = {}, s4[6] = {}, s01 = 0, s34 = 0, s05 = 0;
  const int m = 100000;
  for (int i = 0; i < m; ++i) {
    double z[6];
    unit_variance6(philox4x32_10({std::uint32_t(i), 0, 7, 0}, 3, 0), z);
    for (int d = 0; d < 6; ++d) {
      s1[d] += z[d];
      s2[d] += z[d] * z[d];
      s4[d] += z[d] * z[d] * z[d] * z[d];
    }
    s01 += z[0] * z[1];
    s34 += z[3] * z[4];
    s05 += z[0] * z[5];
  }
  for (int d = 0; d < 6; ++d) {
    EXPECT_NEAR(s1[d] / m, 0.0, 0.015) << d;
    EXPECT_NEAR(s2[d] / m, 1.0, 0.02) << d;
    EXPECT_NEAR(s4[d] / m, 1.8, 0.04) << d;
  }
  for (double s : {s01, s34, s05}) EXPECT_NEAR(s / m, 0.0, 0.015);
}

FluidParams thermal_params(double kT) {
  FluidParams p;
  p.density = 1e-24;
  p.viscosity = 1e-10;
  p.dt = 1e-10;
  p.advection = false;
  p.thermal_kT = kT;
  p.seed = 12345;
  return p;
}

std::vector<double> copy_velocity(const FluidSolver& f) {
  const std::size_t n3 = f.grid().size();
  std::vector<double> v(3 * n3);
  for (int c = 0; c < 3; ++c) std::copy_n(f.velocity(c), n3, v.begin() + c * n3);
  return v;
}

// The equal-time covariance of the discrete Fourier modes of u (docs/thermal.md):
//   ⟨ũ_c(k) ũ_c(k)*⟩ = n³ kT/(ρh³) P_cc(k) / (1 + μλ(k)Δt/(2ρ)),
// P the discrete projection (I − ĝĝᵀ/|ĝ|², I where ĝ = 0), λ = −L̂. Each mode is an AR(1) process
// with coefficient α = 1/(1 + μλΔt/ρ) (0.02–0.57 here). Tolerance: the per-mode time averages of
// |ũ_c|²/S_cc are independent across modes (one of each pair k, −k); their standard error over a
// group of modes is estimated from their own spread (which includes the time correlation) and
// every group's mean must be within 5 standard errors of 1 (expected ~0.1–0.5 %; the amplitude of
// the equal-time-equipartition choice would be off by 27–97 %, a Δt/2 error of λ by > 2 %).
TEST(Thermal, EqualTimeCovarianceOfEveryModeIsTheDiscreteFluctuationDissipationValue) {
  const GridSpec g{16, 725.0};
  const double kT = 414.2;
  const FluidParams p = thermal_params(kT);
  FluidSolver fl(g, p, 1, false);
  const int n = g.n, nzh = n / 2 + 1;
  const double h = g.h();
  const std::size_t n3 = g.size(), nc = std::size_t(n) * n * nzh;
  std::vector<double> in(n3);
  std::vector<std::complex<double>> out(nc);
  fftw_plan plan = fftw_plan_dft_r2c_3d(n, n, n, in.data(),
                                        reinterpret_cast<fftw_complex*>(out.data()), FFTW_ESTIMATE);
  std::vector<double> gs(n), ls(n);
  for (int k = 0; k < n; ++k) {
    gs[k] = (k == 0 || 2 * k == n) ? 0.0 : std::sin(2 * kPi * k / n) / h;
    ls[k] = 4 / (h * h) * std::pow(std::sin(kPi * k / n), 2);
  }
  for (int s = 0; s < 30; ++s) fl.step();  // burn-in: α^60 < 1e-14
  const int samples = 300;
  std::vector<double> sum(3 * nc, 0.0);
  for (int s = 0; s < samples; ++s) {
    fl.step();
    for (int c = 0; c < 3; ++c) {
      std::copy_n(fl.velocity(c), n3, in.data());
      fftw_execute(plan);
      for (std::size_t t = 0; t < nc; ++t) sum[c * nc + t] += std::norm(out[t]);
    }
  }
  fftw_destroy_plan(plan);
  EXPECT_LT(fl.max_divergence() * p.dt, 1e-12);  // D_h·u = 0: the noise is projected

  // per-mode ratios, grouped by λ (the k-dependence) and by the Hermitian planes k_z = 0, n/2
  const double base = double(n3) * kT / (p.density * h * h * h);
  struct Group {
    double s = 0, s2 = 0;
    int m = 0;
  };
  std::vector<Group> by_lambda(6);
  Group hermitian, all;
  const double lam_max = 12 / (h * h);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int kz = 0; kz < nzh; ++kz) {
        const double lam = ls[i] + ls[j] + ls[kz];
        if (lam == 0) continue;
        const bool herm = kz == 0 || 2 * kz == n;
        const int ni = (n - i) % n, nj = (n - j) % n;
        if (herm && ni * n + nj < i * n + j) continue;  // its conjugate is counted
        const double gv[3] = {gs[i], gs[j], gs[kz]};
        const double g2 = gv[0] * gv[0] + gv[1] * gv[1] + gv[2] * gv[2];
        const double S = base / (1 + p.viscosity * lam * p.dt / (2 * p.density));
        for (int c = 0; c < 3; ++c) {
          const double P = g2 > 0 ? 1 - gv[c] * gv[c] / g2 : 1.0;
          if (P < 0.2) continue;  // nearly longitudinal: a ratio of small numbers
          const std::size_t t = (std::size_t(i) * n + j) * nzh + kz;
          const double r = sum[c * nc + t] / samples / (S * P);
          for (Group* gr : {&by_lambda[std::min(5, int(6 * lam / lam_max))],
                            herm ? &hermitian : nullptr, &all}) {
            if (!gr) continue;
            gr->s += r;
            gr->s2 += r * r;
            ++gr->m;
          }
        }
      }
  auto check = [](const Group& gr, const char* what) {
    ASSERT_GT(gr.m, 20) << what;
    const double mean = gr.s / gr.m;
    const double se = std::sqrt((gr.s2 / gr.m - mean * mean) / (gr.m - 1));
    EXPECT_LT(se, 0.02) << what;
    EXPECT_NEAR(mean, 1.0, 5 * se)
        << what << ": mean ratio " << mean << " ± " << se << " over " << gr.m << " modes";
  };
  for (std::size_t b = 0; b < by_lambda.size(); ++b)
    if (by_lambda[b].m > 20) check(by_lambda[b], ("λ bin " + std::to_string(b)).c_str());
  check(hermitian, "modes of the planes k_z = 0, n/2");
  check(all, "all modes");
}

TEST(Thermal, SameSeedSameBitsForAnyThreadCountAndAResumeFromTheCounter) {
  const GridSpec g{16, 725.0};
  const FluidParams p = thermal_params(414.2);
  FluidSolver a(g, p, 1, false), b(g, p, 3, false);
  for (int s = 0; s < 5; ++s) {
    a.step();
    b.step();
  }
  const std::vector<double> half = copy_velocity(a);
  for (int s = 0; s < 5; ++s) {
    a.step();
    b.step();
  }
  const std::vector<double> ua = copy_velocity(a), ub = copy_velocity(b);
  EXPECT_EQ(std::memcmp(ua.data(), ub.data(), ua.size() * sizeof(double)), 0);
  // a fresh solver given the velocity and the counter of step 5 continues bit for bit
  FluidSolver r(g, p, 2, false);
  for (int c = 0; c < 3; ++c) std::copy_n(half.begin() + c * g.size(), g.size(), r.velocity(c));
  r.set_noise_step(5);
  for (int s = 0; s < 5; ++s) r.step();
  EXPECT_EQ(r.noise_step(), 10u);
  const std::vector<double> ur = copy_velocity(r);
  EXPECT_EQ(std::memcmp(ua.data(), ur.data(), ua.size() * sizeof(double)), 0);
  // another seed, other numbers
  FluidParams q = p;
  q.seed = 12346;
  FluidSolver d(g, q, 1, false);
  for (int s = 0; s < 10; ++s) d.step();
  const std::vector<double> ud = copy_velocity(d);
  double diff = 0, norm = 0;
  for (std::size_t t = 0; t < ua.size(); ++t) {
    diff += (ua[t] - ud[t]) * (ua[t] - ud[t]);
    norm += ua[t] * ua[t];
  }
  EXPECT_GT(diff, 0.5 * norm);  // independent fields: |a − d|² ≈ 2|a|²
}

TEST(Thermal, NoNoiseWithoutTemperature) {
  // thermal_kT = 0: a fluid at rest stays at rest (bitwise zero)
  const GridSpec g{16, 725.0};
  FluidSolver fl(g, thermal_params(0.0), 1, false);
  for (int s = 0; s < 3; ++s) fl.step();
  for (int c = 0; c < 3; ++c)
    EXPECT_EQ(*std::max_element(fl.velocity(c), fl.velocity(c) + g.size()), 0.0);
}

TEST(Thermal, UniformBodyForceChangesTheMeanVelocityByDtFOverRho) {
  // the k = 0 mode: ρ(ū' − ū)/Δt = f, no other mode excited
  const GridSpec g{16, 725.0};
  const FluidParams p = thermal_params(0.0);
  FluidSolver fl(g, p, 2, false);
  const std::array<double, 3> f{3e-9, -1e-9, 2e-9};
  fl.set_mean_force(f);
  fl.step();
  fl.step();
  for (int c = 0; c < 3; ++c) {
    const double* u = fl.velocity(c);
    const auto [lo, hi] = std::minmax_element(u, u + g.size());
    EXPECT_NEAR(*lo, 2 * p.dt * f[c] / p.density, 1e-12 * std::abs(2 * p.dt * f[c] / p.density));
    EXPECT_NEAR(*hi, *lo, 1e-12 * std::abs(*lo));
  }
}

}  // namespace
}  // namespace ibrod::fluid
