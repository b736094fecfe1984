// Random twist perturbations (rod.perturbation_random, rod/perturbation.hpp): reproducible from the
// seed, uniform on [−A, A).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "rod/perturbation.hpp"

using namespace ibrod;

TEST(RandomPerturbation, TheSameSeedGivesTheSameAmplitudesAndOthersDiffer) {
  const rod::RandomPerturbation a{8, 0.5, 42}, b{8, 0.5, 42}, c{8, 0.5, 43};
  const auto ea = rod::draw_perturbation(a), eb = rod::draw_perturbation(b),
             ec = rod::draw_perturbation(c);
  ASSERT_EQ(ea.size(), 8u);
  EXPECT_EQ(ea, eb);  // bit for bit
  int same = 0;
  for (int m = 0; m < 8; ++m) same += ea[m] == ec[m];
  EXPECT_EQ(same, 0);
  // the first M of M + 1 modes are the same draws (mode m does not depend on M)
  const auto longer = rod::draw_perturbation({9, 0.5, 42});
  for (int m = 0; m < 8; ++m) EXPECT_EQ(longer[m], ea[m]);
}

TEST(RandomPerturbation, IsUniformOnMinusAToA) {
  // 20000 draws of A = 2: all in [−2, 2), mean ≈ 0 (σ/√N = 1.15/141 ≈ 0.008), variance A²/3
  const auto e = rod::draw_perturbation({20000, 2.0, 7});
  double mean = 0, var = 0;
  for (double v : e) {
    ASSERT_GE(v, -2.0);
    ASSERT_LT(v, 2.0);
    mean += v;
  }
  mean /= double(e.size());
  for (double v : e) var += (v - mean) * (v - mean);
  var /= double(e.size());
  EXPECT_NEAR(mean, 0.0, 0.04);
  EXPECT_NEAR(var, 4.0 / 3.0, 0.05);
}

TEST(RandomPerturbation, TheRecipeIsPinnedByTheStandard) {
  // the documented recipe: u = (x >> 11) 2⁻⁵³, ε = A (2u − 1), x the next mt19937_64(seed) output.
  // The C++ standard fixes the 10000th output of mt19937_64(5489): 9981545732273789042.
  const double u = double(9981545732273789042ull >> 11) * 0x1.0p-53;
  EXPECT_EQ(rod::draw_perturbation({10000, 1.0, 5489}).back(), 2.0 * u - 1.0);
}
