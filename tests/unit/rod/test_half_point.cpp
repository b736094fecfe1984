// Half-point triad D_{k+½} = √A D_k, A = D_{k+1} D_kᵀ (MODEL §4 step 1).
#include <gtest/gtest.h>

#include <random>

#include "rod_test_util.hpp"

namespace ibrod::rod {
namespace {

using test::random_vec;

// Random rotation with angle up to max_angle (rad), uniform random axis.
Mat3 random_rotation(std::mt19937_64& rng, double max_angle) {
  std::uniform_real_distribution<double> u(0.0, max_angle);
  return rotation(u(rng) * random_vec(rng, 1.0).normalized());
}

TEST(HalfPointTriad, SquareRootOfTheRelativeRotation) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    // Angles up to 0.99 π: the principal root is unique below π.
    const Mat3 Dk = random_rotation(rng, 3.1);
    const Mat3 Dk1 = random_rotation(rng, 0.99 * test::pi) * Dk;
    const Mat3 A = Dk1 * Dk.transpose();
    const Mat3 Dh = half_point_triad(Dk, Dk1);
    const Mat3 S = Dh * Dk.transpose();  // √A
    EXPECT_LT((S * S - A).norm(), 1e-14) << trial;
    EXPECT_LT((S * Dh - Dk1).norm(), 1e-14) << trial;  // √A takes D_{k+½} on to D_{k+1}
    EXPECT_LT((Dh.transpose() * Dh - Mat3::Identity()).norm(), 1e-14);
    EXPECT_NEAR(Dh.determinant(), 1.0, 1e-14);
    // Half the angle about the same axis.
    const Eigen::AngleAxisd full(A), half(S);
    EXPECT_NEAR(half.angle(), 0.5 * full.angle(), 1e-12) << trial;
    EXPECT_LT((half.axis() - full.axis()).norm(), 1e-10) << trial;
  }
}

TEST(HalfPointTriad, SymmetricInTheTwoEnds) {
  // Going forward from D_k by √A and back from D_{k+1} by √A⁻¹ = √(D_k D_{k+1}ᵀ) lands on the
  // same triad: the half point does not prefer either end.
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const Mat3 Dk = random_rotation(rng, 3.1);
    const Mat3 Dk1 = random_rotation(rng, 0.99 * test::pi) * Dk;
    EXPECT_LT((half_point_triad(Dk, Dk1) - half_point_triad(Dk1, Dk)).norm(), 1e-13) << trial;
  }
}

TEST(HalfPointTriad, EqualTriadsAndHalfTurn) {
  std::mt19937_64 rng(3);
  const Mat3 D = random_rotation(rng, 3.0);
  EXPECT_LT((half_point_triad(D, D) - D).norm(), 1e-15);
  // Angle just below π about D¹: the half rotation is π/2 about D¹, not −π/2 (principal root).
  const double phi = test::pi - 1e-9;
  const Mat3 D1 = rotation(phi * D.col(0)) * D;
  const Mat3 expect = rotation(0.5 * phi * D.col(0)) * D;
  EXPECT_LT((half_point_triad(D, D1) - expect).norm(), 1e-12);
}

}  // namespace
}  // namespace ibrod::rod
