// Linking number of polygon pairs with known topology, and twist: Lk(X, X + εd1) = Tw + Wr.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "curves.hpp"
#include "diagnostics/topology.hpp"

namespace ibrod::diagnostics {
namespace {

using namespace testing;

TEST(LinkingNumber, HopfLinkIsMinusOneAndFlipsWithOrientation) {
  // A: unit circle in z = 0, counter-clockwise about +z. B: unit circle centred at (1, 0, 0) in
  // y = 0, B(s) = (1 + cos s, 0, sin s); it crosses A's disk at the origin (s = π) moving along
  // −z, against A's right-hand normal: Lk = −1 in the Gauss convention.
  const auto A = circle(100, 1.0);
  const auto B = circle(100, 1.0, Vec3(1, 0, 0), Vec3::UnitX(), Vec3::UnitZ());
  EXPECT_NEAR(linking_number(A, B), -1.0, 1e-12);
  EXPECT_NEAR(linking_number(B, A), -1.0, 1e-12);
  const std::vector<Vec3> Brev(B.rbegin(), B.rend());
  EXPECT_NEAR(linking_number(A, Brev), 1.0, 1e-12);
  // different resolutions of the two components
  EXPECT_NEAR(linking_number(circle(37, 1.0), B), -1.0, 1e-12);
}

TEST(LinkingNumber, UnlinkedCirclesGiveZero) {
  const auto A = circle(120, 1.0);
  const Vec3 e2 = Vec3(0, 1, 1).normalized();
  // side by side, tilted
  EXPECT_NEAR(linking_number(A, circle(90, 1.0, Vec3(2.5, 0.0, 0.3), Vec3::UnitX(), e2)), 0.0,
              1e-12);
  // stacked above A's disk, slightly tilted, never piercing it
  const Vec3 f2 = Vec3(0, 1, 0.1).normalized();
  EXPECT_NEAR(linking_number(A, circle(90, 0.8, Vec3(0.1, 0.0, 0.5), Vec3::UnitX(), f2)), 0.0,
              1e-12);
  // a big circle around a small one, coplanar-ish: not linked either
  EXPECT_NEAR(linking_number(A, circle(90, 3.0, Vec3(0, 0, 0.01), Vec3::UnitX(), f2)), 0.0, 1e-12);
}

// (2, 2q) torus link on the torus with radii R, r: component c at θ = t, φ = q t + cπ.
std::vector<Vec3> torus_strand(int n, int q, int c, double R = 2.0, double r = 0.7) {
  std::vector<Vec3> X(n);
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n, phi = q * t + c * pi;
    X[k] = Vec3((R + r * std::cos(phi)) * std::cos(t), (R + r * std::cos(phi)) * std::sin(t),
                r * std::sin(phi));
  }
  return X;
}

TEST(LinkingNumber, TorusLinkTwoTwoQ) {
  // Both strands turn about the core circle's tangent e_θ from e_R towards e_z, a left-handed
  // turn (e_R × e_z = −e_θ), q times: Lk = −q. The mirror image (z → −z) has Lk = +q.
  for (int q = 1; q <= 4; ++q) {
    const auto A = torus_strand(80 * q, q, 0), B = torus_strand(80 * q, q, 1);
    EXPECT_NEAR(linking_number(A, B), -q, 1e-11) << "q = " << q;
    auto Am = A, Bm = B;
    for (auto& x : Am) x.z() = -x.z();
    for (auto& x : Bm) x.z() = -x.z();
    EXPECT_NEAR(linking_number(Am, Bm), q, 1e-11) << "q = " << q;
  }
}

TEST(Twist, CircleRibbonWithMTurns) {
  // d1 turns m times right-handedly about the tangent: d1 = cos φ e_R + sin φ (e_θ × e_R),
  // φ = 2πm k/n. Wr = 0, so Tw = Lk = m, exactly for the polygon.
  const int n = 200;
  const auto X = circle(n, 1.0);
  for (int m : {-3, 0, 1, 5}) {
    std::vector<Vec3> d1(n), d1_tilted(n);
    for (int k = 0; k < n; ++k) {
      const double th = 2 * pi * k / n, phi = 2 * pi * m * k / n;
      const Vec3 eR(std::cos(th), std::sin(th), 0), et(-std::sin(th), std::cos(th), 0);
      d1[k] = std::cos(phi) * eR + std::sin(phi) * et.cross(eR);
      d1_tilted[k] = 1.7 * (d1[k] + 0.4 * et);  // not ⟂ to the chord, not unit: projected
    }
    EXPECT_NEAR(twist(X, d1), m, 1e-12);
    EXPECT_NEAR(twist(X, d1_tilted), m, 1e-12);
    std::vector<Vec3> Y(n);
    for (int k = 0; k < n; ++k) Y[k] = X[k] + 1e-3 * d1[k];
    EXPECT_NEAR(linking_number(X, Y), m, 1e-10);
  }
}

// A closed ribbon on a smooth random curve: frame transported along the central-difference
// vertex tangents (a different transport from the one twist() uses), turned by
// φ_k = (2πm − Φ) k/n + ψ_k with Φ that transport's holonomy (so the frame closes) and ψ a random
// smooth periodic angle; then tilted along the tangent and rescaled, so d1 is neither unit nor ⟂.
std::vector<Vec3> random_ribbon(const std::vector<Vec3>& X, int m, std::mt19937_64& rng) {
  const int n = int(X.size());
  std::vector<Vec3> T(n), P(n + 1);
  for (int k = 0; k < n; ++k) T[k] = (X[(k + 1) % n] - X[(k + n - 1) % n]).normalized();
  auto transport = [](const Vec3& a, const Vec3& b, const Vec3& v) {  // minimal rotation a → b
    return Eigen::Quaterniond::FromTwoVectors(a, b) * v;
  };
  P[0] = T[0].unitOrthogonal();
  for (int k = 0; k < n; ++k) {
    Vec3 p = transport(T[k], T[(k + 1) % n], P[k]);
    const Vec3& tn = T[(k + 1) % n];
    P[k + 1] = (p - p.dot(tn) * tn).normalized();
  }
  const double holonomy = std::atan2(T[0].dot(P[0].cross(P[n])), P[0].dot(P[n]));
  std::uniform_real_distribution<double> U(0.0, 2 * pi);
  const double c1 = 1.0, c2 = 0.5, c3 = 0.3, p1 = U(rng), p2 = U(rng), p3 = U(rng);
  std::vector<Vec3> d1(n);
  for (int k = 0; k < n; ++k) {
    const double x = 2 * pi * k / n;
    const double phi = (2 * pi * m - holonomy) * k / n + c1 * std::sin(x + p1) +
                       c2 * std::sin(2 * x + p2) + c3 * std::sin(3 * x + p3);
    const Vec3 d = std::cos(phi) * P[k] + std::sin(phi) * T[k].cross(P[k]);
    d1[k] = (1.0 + 0.3 * std::cos(x + p2)) * (d + 0.2 * std::sin(2 * x + p3) * T[k]);
  }
  return d1;
}

TEST(Twist, TwistPlusWritheIsTheRibbonsLinkingNumber) {
  const int n = 300;
  double worst_int = 0, worst_sum = 0;
  for (int seed = 1; seed <= 5; ++seed) {
    std::mt19937_64 rng(100 + seed);
    const auto X = random_fourier_curve(rng, 3).sample(n);
    const double eps = 1e-3 * mean_spacing(X);
    ASSERT_GT(closest_approach(X, 10), 100 * eps)
        << "seed " << seed << ": curve nearly touches itself";
    const double wr = writhe(X);
    double lk0 = 0, tw0 = 0;
    for (int m : {0, -2, 1, 3}) {
      std::mt19937_64 frame_rng(seed);  // the same smooth angle ψ for every m
      const auto d1 = random_ribbon(X, m, frame_rng);
      std::vector<Vec3> Y(n);
      for (int k = 0; k < n; ++k) Y[k] = X[k] + eps * d1[k];
      const double tw = twist(X, d1), lk = linking_number(X, Y);
      worst_int = std::max(worst_int, std::abs(lk - std::round(lk)));
      worst_sum = std::max(worst_sum, std::abs(tw + wr - lk));
      // measured 1.5e-13 for both
      EXPECT_NEAR(lk, std::round(lk), 1e-8) << "seed " << seed << " m " << m;
      EXPECT_NEAR(tw + wr, lk, 1e-8) << "seed " << seed << " m " << m;
      if (m == 0) {
        lk0 = lk;
        tw0 = tw;
      } else {
        EXPECT_NEAR(lk - lk0, m, 1e-8) << "seed " << seed;
        EXPECT_NEAR(tw - tw0, m, 1e-10) << "seed " << seed;
      }
    }
  }
  std::printf("ribbons: max |Lk − round(Lk)| = %.1e, max |Tw + Wr − Lk| = %.1e\n", worst_int,
              worst_sum);
}

TEST(Twist, SizeMismatchThrows) {
  const auto X = circle(10, 1.0);
  const std::vector<Vec3> d1(9, Vec3::UnitZ());
  EXPECT_THROW(twist(X, d1), std::invalid_argument);
}

}  // namespace
}  // namespace ibrod::diagnostics
