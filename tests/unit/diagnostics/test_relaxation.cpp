// Time-series analysis (diagnostics/relaxation.hpp) on synthetic series with known answers:
// an exponential final approach with known τ behind a faster mode, a writhe curve with a known
// last exit from the ±δ band, a power law behind an early transient, and transient states on a
// staircase of total energy (with negative controls: no plateau, no minimum).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "diagnostics/relaxation.hpp"

namespace ibrod::diagnostics {
namespace {

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> x(n);
  for (int i = 0; i < n; ++i) x[i] = a + (b - a) * i / (n - 1);
  return x;
}

TEST(FitLine, ExactLineAndNoisyLine) {
  const auto x = linspace(-3, 7, 50);
  std::vector<double> y(x.size());
  for (size_t i = 0; i < x.size(); ++i) y[i] = 2.5 - 0.75 * x[i];
  const LineFit f = fit_line(x, y);
  EXPECT_NEAR(f.slope, -0.75, 1e-13);
  EXPECT_NEAR(f.intercept, 2.5, 1e-12);
  EXPECT_NEAR(f.r2, 1.0, 1e-14);
  EXPECT_LT(f.max_abs_residual, 1e-12);
  EXPECT_EQ(f.count, x.size());
  // a zigzag of ±0.1 about the line: residuals 0.1, slope unchanged (even count, symmetric)
  for (size_t i = 0; i < y.size(); ++i) y[i] += (i % 2 ? 0.1 : -0.1);
  const LineFit g = fit_line(x, y);
  EXPECT_NEAR(g.max_abs_residual, 0.1, 0.01);
  EXPECT_LT(g.r2, 1.0);
  EXPECT_THROW(fit_line(std::vector<double>{1.0}, std::vector<double>{1.0}), std::invalid_argument);
  EXPECT_THROW(fit_line(x, std::vector<double>(3, 0.0)), std::invalid_argument);
}

TEST(FinalLinearWindow, StopsWhereTheCurveBends) {
  // y = |x| on [−10, 10]: the final linear stretch is x ≥ 0, i.e. 101 of 201 samples (a window
  // reaching a few samples past the kink still fits within the tolerance)
  const auto x = linspace(-10, 10, 201);
  std::vector<double> y(x.size());
  for (size_t i = 0; i < x.size(); ++i) y[i] = std::abs(x[i]);
  const auto f = fit_final_linear_window(x, y, {.tolerance = 0.05, .min_points = 5});
  ASSERT_TRUE(f);
  EXPECT_NEAR(double(f->count), 101.0, 3.0);
  EXPECT_LE(f->max_abs_residual, 0.05);
  EXPECT_NEAR(f->slope, 1.0, 0.01);
  EXPECT_EQ(f->first + f->count, x.size());
}

TEST(RelaxationTime, RecoversTauBehindAFasterMode) {
  // E_K = e^{−2t/τ} + 30 e^{−2t/τ_f}, rising from 0 over the first 10 ns: the fast mode and the
  // start-up must be left out of the window, the slow τ recovered to 1 %
  const double tau = 0.35, tau_f = 0.04;  // µs
  const auto t = linspace(0, 8, 801);
  std::vector<double> E(t.size());
  for (size_t i = 0; i < t.size(); ++i)
    E[i] = (1 - std::exp(-t[i] / 0.01)) *
           (std::exp(-2 * t[i] / tau) + 30 * std::exp(-2 * t[i] / tau_f));
  const auto fit = relaxation_time(t, E);
  ASSERT_TRUE(fit);
  std::printf("tau = %.6f (exact %.6f), window from t = %.3f, R2 = %.8f\n", fit->tau, tau,
              t[fit->line.first], fit->line.r2);
  EXPECT_NEAR(fit->tau, tau, 0.01 * tau);  // measured 1e-5 relative
  // the window starts once the fast mode is below the 2 % tolerance: 30 e^{−2t(1/τ_f − 1/τ)}
  // = 0.02 at t = 0.16
  EXPECT_GT(t[fit->line.first], 0.15);
  EXPECT_GT(fit->line.r2, 0.999);
  EXPECT_EQ(fit->line.first + fit->line.count, t.size());
}

TEST(RelaxationTime, NoneWithoutDecay) {
  const auto t = linspace(0, 1, 50);
  std::vector<double> grow(t.size()), zero(t.size(), 0.0);
  for (size_t i = 0; i < t.size(); ++i) grow[i] = std::exp(t[i]);
  EXPECT_FALSE(relaxation_time(t, grow));
  EXPECT_FALSE(relaxation_time(t, zero));
}

TEST(WritheConvergence, PiecewiseLinearRiseHasAnExactAnswer) {
  // Wr rises linearly from 0 to 0.5 over t ∈ [0, 1], then stays: |Wr − 0.5| > 0.01 until
  // t = 0.98, which falls between samples (Δt = 0.013)
  std::vector<double> t, w;
  for (int i = 0; i * 0.013 <= 3.0; ++i) {
    t.push_back(i * 0.013);
    w.push_back(0.5 * std::min(t.back(), 1.0));
  }
  EXPECT_NEAR(writhe_convergence_time(t, w, 0.01), 0.98, 1e-12);
  EXPECT_NEAR(writhe_convergence_time(t, w, 0.1), 0.8, 1e-12);
}

TEST(WritheConvergence, IsTheLastExitNotTheFirst) {
  // Wr → 1 − e^{−t/τ}: last exit at τ ln(1/δ); a later excursion of 0.03 below the final value
  // (a transient) around t = 5 moves it to where that excursion re-enters the band
  const double tau = 0.2, delta = 0.01;
  const auto t = linspace(0, 10, 10001);
  std::vector<double> w(t.size()), wb(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    w[i] = 1 - std::exp(-t[i] / tau);
    wb[i] = w[i] - 0.03 * std::max(0.0, 1 - std::abs(t[i] - 5.0) / 0.5);  // tent on [4.5, 5.5]
  }
  EXPECT_NEAR(writhe_convergence_time(t, w, delta), tau * std::log(1 / delta), 1e-5);
  // tent: 0.03 (1 − |t − 5|/0.5) = δ at t = 5 + 0.5 (1 − 1/3)
  EXPECT_NEAR(writhe_convergence_time(t, wb, delta), 5.0 + 0.5 * (2.0 / 3.0), 1e-5);
  // inside the band throughout: the first time
  std::vector<double> flat(t.size(), 0.3);
  EXPECT_EQ(writhe_convergence_time(t, flat, delta), 0.0);
}

TEST(PowerLaw, RecoversTheExponentBehindAnEarlyTransient) {
  const double p = -2.5;
  const auto t = linspace(0, 5, 1001);  // t = 0 and E_K(0) = 0 are skipped
  std::vector<double> E(t.size());
  for (size_t i = 0; i < t.size(); ++i)
    E[i] = t[i] > 0 ? 1e-3 * std::pow(t[i], p) * (1 + 4 * std::exp(-t[i] / 0.05)) : 0.0;
  const auto fit = power_law_exponent(t, E);
  ASSERT_TRUE(fit);
  std::printf("exponent = %.6f (exact %.6f), window from t = %.3f\n", fit->exponent, p,
              t[fit->line.first]);
  EXPECT_NEAR(fit->exponent, p, 0.01 * std::abs(p));  // measured 4e-4 relative
  EXPECT_GT(t[fit->line.first], 0.1);
}

/// E_total falls in two smooth steps (tanh) at t = 1 and t = 4 with a plateau between; the
/// dissipation rate −dE/dt plus a small floor is the kinetic energy, so E_K has a minimum on the
/// plateau near t = 2.5.
struct Staircase {
  std::vector<double> t, kinetic, total;
  explicit Staircase(double floor = 1e-4) : t(linspace(0, 8, 801)) {
    for (double s : t) {
      const double a = std::tanh((s - 1) / 0.2), b = std::tanh((s - 4) / 0.2);
      total.push_back(100 - 20 * (1 + a) - 10 * (1 + b));
      kinetic.push_back(floor + 20 * (1 - a * a) / 0.2 + 10 * (1 - b * b) / 0.2);
    }
  }
};

TEST(Transients, FoundOnAPlateauOfTotalEnergy) {
  const Staircase s;
  const auto tr = transients(s.t, s.kinetic, s.total);
  ASSERT_EQ(tr.size(), 1u);
  // the E_K minimum between two sech² bumps of heights 100 and 50 lies where their tails
  // balance: e^{−2(t−1)/0.2}·400 = e^{−2(4−t)/0.2}·200 → t = 2.5 + 0.05 ln 2
  EXPECT_NEAR(tr[0].time, 2.5 + 0.05 * std::log(2.0), 0.011);
  EXPECT_NEAR(tr[0].total, 60.0, 1e-3);  // the plateau's energy
  EXPECT_LT(tr[0].plateau_start, 2.0);
  EXPECT_GT(tr[0].plateau_end, 3.0);
  EXPECT_LT(tr[0].kinetic, 1e-3);
}

TEST(Transients, NoneWithoutPlateauOrWithoutMinimum) {
  // E_K oscillates (minima with prominence) while E_total falls at a constant rate: no plateau
  const auto t = linspace(0, 8, 801);
  std::vector<double> K(t.size()), E(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    K[i] = 1.0 + 0.9 * std::cos(4 * t[i]);
    E[i] = 100 - 5 * t[i];
  }
  EXPECT_TRUE(transients(t, K, E).empty());
  // a monotone decay has no minimum, whatever the total energy does
  const Staircase s;
  std::vector<double> decay(t.size());
  for (size_t i = 0; i < t.size(); ++i) decay[i] = std::exp(-t[i]);
  EXPECT_TRUE(transients(t, decay, s.total).empty());
  // a shallow dip (E_K rises by less than the factor min_rise) is not a transient
  const Staircase shallow(60.0);  // E_K rises from ≈ 60 to ≈ 110 after the minimum
  EXPECT_TRUE(transients(shallow.t, shallow.kinetic, shallow.total).empty());
}

TEST(Series, SizeMismatchThrows) {
  const std::vector<double> t{0, 1, 2}, y{1, 2};
  EXPECT_THROW(writhe_convergence_time(t, y), std::invalid_argument);
  EXPECT_THROW(relaxation_time(t, y), std::invalid_argument);
  EXPECT_THROW(transients(t, t, y), std::invalid_argument);
}

TEST(RelaxationAfter, FitsEveryRowFromTheStartOnly) {
  // τ = 0.2 before t = 2, τ = 1 after; the fit from t = 2 sees only the slow mode
  std::vector<double> t, e;
  for (int i = 0; i <= 400; ++i) {
    const double x = 0.01 * i;
    t.push_back(x);
    e.push_back(x < 2 ? std::exp(-2 * x / 0.2) : std::exp(-20.0) * std::exp(-2 * (x - 2) / 1.0));
  }
  const auto f = relaxation_time_from(t, e, 2.0);
  ASSERT_TRUE(f);
  EXPECT_NEAR(f->tau, 1.0, 1e-9);
  EXPECT_EQ(f->line.first, 200u);
  EXPECT_NEAR(f->line.r2, 1.0, 1e-12);
  const auto g = relaxation_time_from(t, e, 0.0);  // both modes: neither τ
  ASSERT_TRUE(g);
  EXPECT_LT(g->line.r2, 0.99);
  EXPECT_FALSE(relaxation_time_from(t, e, 3.97));  // 3 rows < 5
  std::vector<double> grow(e.rbegin(), e.rend());
  EXPECT_FALSE(relaxation_time_from(t, grow, 2.0));  // E_K grows: no τ
}

TEST(RelaxationAfter, LocalTauPerWindowAndSettledTime) {
  std::vector<double> t, e;
  for (int i = 0; i < 300; ++i) {
    const double x = 0.01 * i;  // 0 … 2.99
    t.push_back(x);
    e.push_back(std::exp(-2 * x * x));  // d ln E/dt = −4t: τ(t) = 1/(2t)
  }
  const auto w = local_relaxation_times(t, e, 1.0);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_NEAR(w[1].tau, 1 / (2 * 1.495), 1e-3);  // the window's mean slope
  EXPECT_NEAR(w[2].tau, 1 / (2 * 2.495), 1e-3);
  EXPECT_EQ(w[1].points, 100u);
  EXPECT_THROW(local_relaxation_times(t, e, 0.0), std::invalid_argument);
  // times 0.01 i against 0.1-wide windows: edges that rounding puts on either side (this once
  // looped for ever); every sample in one window, 10 windows of 10 samples in the first µs
  const auto narrow = local_relaxation_times(t, e, 0.1);
  std::size_t points = 0;
  for (const auto& x : narrow) points += x.points;
  EXPECT_EQ(points, t.size());
  EXPECT_GE(narrow.size(), 29u);
  const std::vector<double> tc{0, 1, 2, 3, 4};
  EXPECT_EQ(settled_time(tc, std::vector<int>{0, 1, 1, 2, 2}), 3.0);
  EXPECT_EQ(settled_time(tc, std::vector<int>{1, 1, 1, 1, 1}), 0.0);
  EXPECT_EQ(settled_time(tc, std::vector<int>{1, 2, 1, 1, 3}), 4.0);
}

}  // namespace
}  // namespace ibrod::diagnostics
