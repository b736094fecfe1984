// The smoothed delta function on its own: Peskin's 4-point φ and δ_c (MODEL (2.14)–(2.16)).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "ib/kernel.hpp"

namespace ibrod::ib {
namespace {

constexpr double kH = 725.0 / 64;  // the reference grid spacing, Å

TEST(Phi4, ClosedFormValues) {
  // MODEL (2.14) by hand at r = 0, ½, 1, 3/2, 2 and outside the support
  EXPECT_DOUBLE_EQ(phi4(0.0), 0.5);
  EXPECT_DOUBLE_EQ(phi4(0.5), (2.0 + std::sqrt(2.0)) / 8);
  EXPECT_DOUBLE_EQ(phi4(1.0), 0.25);
  EXPECT_DOUBLE_EQ(phi4(1.5), (2.0 - std::sqrt(2.0)) / 8);
  EXPECT_EQ(phi4(2.0), 0.0);
  EXPECT_EQ(phi4(2.5), 0.0);
  EXPECT_EQ(phi4(-7.0), 0.0);
  // even, and continuous at |r| = 1 where the branches meet
  for (double r : {0.1, 0.7, 1.3, 1.9}) EXPECT_EQ(phi4(-r), phi4(r));
  EXPECT_NEAR(phi4(1.0 - 1e-12), phi4(1.0 + 1e-12), 1e-11);
}

TEST(Phi4, SumRules) {
  // Σ_j φ(r − j) = 1, Σ_j (r − j) φ(r − j) = 0, Σ_j φ(r − j)² = 3/8 for every r (Peskin 2002)
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> uni(-50.0, 50.0);
  double err0 = 0, err1 = 0, err2 = 0;
  for (int t = 0; t < 1000; ++t) {
    const double r = uni(rng);
    double s0 = 0, s1 = 0, s2 = 0;
    for (int j = int(std::floor(r)) - 3; j <= int(std::floor(r)) + 3; ++j) {
      const double p = phi4(r - j);
      s0 += p;
      s1 += (r - j) * p;
      s2 += p * p;
    }
    err0 = std::max(err0, std::abs(s0 - 1.0));
    err1 = std::max(err1, std::abs(s1));
    err2 = std::max(err2, std::abs(s2 - 0.375));
  }
  // measured 2e-16, 2e-16, 1e-16; bound 1e-14
  EXPECT_LT(err0, 1e-14);
  EXPECT_LT(err1, 1e-14);
  EXPECT_LT(err2, 1e-14);
}

TEST(Delta, SeparableAndScaled) {
  const double c = 2 * kH;
  const Vec3 x(3.0, -17.5, 9.25);
  EXPECT_DOUBLE_EQ(delta(x, c), phi4(x[0] / c) * phi4(x[1] / c) * phi4(x[2] / c) / (c * c * c));
  EXPECT_EQ(delta(Vec3(2 * c, 0, 0), c), 0.0);
  // peak value φ(0)³/c³, Å⁻³
  EXPECT_DOUBLE_EQ(delta(Vec3::Zero(), c), 0.125 / (c * c * c));
}

// MODEL (2.15)–(2.16): Σ_j δ_c(jh − X) h³ = 1 and Σ_j (jh − X) δ_c(jh − X) h³ = 0 for any X, when
// c is an integer multiple of h. Sums over the unbounded lattice (no periodic wrap); X ranges over
// a few hundred Å like the unwrapped rod positions.
TEST(Delta, MomentsOnLattice) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> uni(-600.0, 900.0);
  for (int m : {1, 2}) {
    const double c = m * kH;
    double err0 = 0, err1 = 0;
    for (int t = 0; t < 100; ++t) {
      const Vec3 X(uni(rng), uni(rng), uni(rng));
      const int r = 2 * m + 1;
      const int i0 = int(std::floor(X[0] / kH)), j0 = int(std::floor(X[1] / kH)),
                k0 = int(std::floor(X[2] / kH));
      double s0 = 0;
      Vec3 s1 = Vec3::Zero();
      for (int i = i0 - r; i <= i0 + r; ++i)
        for (int j = j0 - r; j <= j0 + r; ++j)
          for (int k = k0 - r; k <= k0 + r; ++k) {
            const Vec3 d = Vec3(i * kH, j * kH, k * kH) - X;
            const double w = delta(d, c) * kH * kH * kH;
            s0 += w;
            s1 += d * w;
          }
      err0 = std::max(err0, std::abs(s0 - 1.0));
      err1 = std::max(err1, s1.norm() / c);
    }
    // measured 2e-15 (sum) and 6e-16 (first moment / c); bound 1e-13
    EXPECT_LT(err0, 1e-13) << "m = " << m;
    EXPECT_LT(err1, 1e-13) << "m = " << m;
  }
}

}  // namespace
}  // namespace ibrod::ib
