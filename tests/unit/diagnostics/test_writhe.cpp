// Writhe of closed polygons: the exact segment-pair solid angle against Klenin & Langowski's
// published formula, planar curves, symmetries, an independent quadrature of the Gauss integral,
// and Fuller's theorem.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "curves.hpp"
#include "diagnostics/topology.hpp"

namespace ibrod::diagnostics {
namespace {

using namespace testing;

Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::Quaterniond q(N(rng), N(rng), N(rng), N(rng));
  return q.normalized().toRotationMatrix();
}

std::vector<Vec3> transformed(const std::vector<Vec3>& X, const Mat3& R, const Vec3& shift,
                              double scale = 1.0) {
  std::vector<Vec3> Y(X.size());
  for (size_t k = 0; k < X.size(); ++k) Y[k] = scale * (R * X[k]) + shift;
  return Y;
}

TEST(SegmentPairSolidAngle, MatchesKleninLangowskiAndQuadrature) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  double worst_kl = 0, worst_quad = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 p1(U(rng), U(rng), U(rng)), p2(U(rng), U(rng), U(rng));
    const Vec3 shift(3 * U(rng), 3 * U(rng), 3 * U(rng));
    const Vec3 p3 = Vec3(U(rng), U(rng), U(rng)) + shift, p4 = Vec3(U(rng), U(rng), U(rng)) + shift;
    const double om = segment_pair_solid_angle(p1, p2, p3, p4);
    worst_kl = std::max(worst_kl, std::abs(om - solid_angle_kl1b(p1, p2, p3, p4)));
    // symmetric in the two segments; odd under reversing one of them
    EXPECT_NEAR(segment_pair_solid_angle(p3, p4, p1, p2), om, 1e-13);
    EXPECT_NEAR(segment_pair_solid_angle(p2, p1, p3, p4), -om, 1e-13);
    if (trial < 20) {  // midpoint rule of ∫∫ (dr₁×dr₂)·(r₁−r₂)/|r₁−r₂|³, M² points
      if ((p3 - p1).norm() < 1.5 || (p4 - p2).norm() < 1.5) continue;  // keep the rule accurate
      const int M = 200;
      const Vec3 s = p2 - p1, u = p4 - p3, sxu = s.cross(u);
      double q = 0;
      for (int a = 0; a < M; ++a)
        for (int b = 0; b < M; ++b) {
          const Vec3 x = (p1 + (a + 0.5) / M * s) - (p3 + (b + 0.5) / M * u);
          q += sxu.dot(x) / std::pow(x.norm(), 3);
        }
      q /= double(M) * M;
      worst_quad = std::max(worst_quad, std::abs(om - q));
    }
  }
  EXPECT_LT(worst_kl, 1e-12);   // measured 2.2e-14
  EXPECT_LT(worst_quad, 1e-5);  // measured 1.0e-6 (midpoint rule, M = 200)
  std::printf("segment pair vs K&L 1b: %.1e, vs quadrature: %.1e\n", worst_kl, worst_quad);
}

TEST(Writhe, PlanarCurvesHaveZeroWrithe) {
  std::mt19937_64 rng(11);
  const Mat3 R = random_rotation(rng);
  const Vec3 shift(3.0, -2.0, 5.0);
  // a circle (n = 600, radius 170 Å: a 1000-bp minicircle) in a general plane
  const auto C = transformed(circle(600, 170.0), R, shift);
  EXPECT_LT(std::abs(writhe(C)), 1e-12);  // measured 1.5e-17
  // a random star-shaped polygon (simple: radii random, angles increasing) in a general plane
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<Vec3> S(300);
  for (int k = 0; k < 300; ++k) {
    const double th = 2 * pi * (k + 0.8 * U(rng)) / 300, r = 1.0 + 0.6 * U(rng);
    S[k] = Vec3(r * std::cos(th), r * std::sin(th), 0.0);
  }
  const double wr_star = writhe(transformed(S, R, shift, 10.0));
  EXPECT_LT(std::abs(wr_star), 1e-12);  // measured 1.3e-14 (K&L 1b's asin form: 1.4e-7)
  std::printf("planar: Wr(circle) = %.1e, Wr(star) = %.1e; K&L 1b on the star: %.1e\n", writhe(C),
              wr_star, writhe_kl1b(transformed(S, R, shift, 10.0)));
}

TEST(Writhe, MatchesKleninLangowskiOnRandomCurves) {
  for (int seed = 1; seed <= 4; ++seed) {
    std::mt19937_64 rng(seed);
    const auto X = random_fourier_curve(rng, 4).sample(120);
    const double wr = writhe(X);
    // measured 1.2e-12: K&L's asin terms lose digits on nearly coplanar quadruples
    EXPECT_NEAR(wr, writhe_kl1b(X), 1e-10) << "seed " << seed;
  }
}

TEST(Writhe, SymmetriesOfTheGaussIntegral) {
  std::mt19937_64 rng(5);
  const auto X = random_fourier_curve(rng, 4).sample(250);
  const double wr = writhe(X);
  ASSERT_GT(std::abs(wr), 0.05);  // a chiral curve, or the checks below say nothing
  // mirror image: sign flips
  std::vector<Vec3> M = X;
  for (auto& x : M) x.x() = -x.x();
  EXPECT_NEAR(writhe(M), -wr, 1e-12);
  // reversed orientation: unchanged
  std::vector<Vec3> Rev(X.rbegin(), X.rend());
  EXPECT_NEAR(writhe(Rev), wr, 1e-12);
  // a different first vertex: unchanged
  std::vector<Vec3> Sh = X;
  std::rotate(Sh.begin(), Sh.begin() + 77, Sh.end());
  EXPECT_NEAR(writhe(Sh), wr, 1e-12);
  // rotation, translation, scaling: unchanged
  EXPECT_NEAR(writhe(transformed(X, random_rotation(rng), Vec3(40, -7, 3), 30.0)), wr, 1e-12);
}

TEST(Writhe, ImproperSymmetryForcesZero) {
  // The "tennis-ball seam" r(t) = (cos t + a cos 3t, sin t − a sin 3t, b sin 2t) has
  // r(t + π/2) = S r(t), S = (x, y, z) ↦ (−y, x, −z) a rotoreflection (det −1). An improper
  // symmetry flips Wr, so Wr = 0; with n divisible by 4 the polygon has the symmetry too.
  const double a = 0.3, b = 0.8;
  std::vector<Vec3> X(400);
  for (int k = 0; k < 400; ++k) {
    const double t = 2 * pi * k / 400;
    X[k] = Vec3(std::cos(t) + a * std::cos(3 * t), std::sin(t) - a * std::sin(3 * t),
                b * std::sin(2 * t));
  }
  EXPECT_LT(std::abs(writhe(X)), 1e-12);
  // break the symmetry slightly: no longer zero (the check can fail)
  X[3].z() += 0.05;
  EXPECT_GT(std::abs(writhe(X)), 1e-5);
}

// Trefoil (2,3) torus knot, a smooth chiral curve with |Wr| ≈ 3.
SmoothCurve trefoil() {
  SmoothCurve C;
  C.r = [](double t) {
    return Vec3((2 + std::cos(3 * t)) * std::cos(2 * t), (2 + std::cos(3 * t)) * std::sin(2 * t),
                std::sin(3 * t));
  };
  C.dr = [](double t) {
    const double c3 = std::cos(3 * t), s3 = std::sin(3 * t), c2 = std::cos(2 * t),
                 s2 = std::sin(2 * t);
    return Vec3(-3 * s3 * c2 - 2 * (2 + c3) * s2, -3 * s3 * s2 + 2 * (2 + c3) * c2, 3 * c3);
  };
  return C;
}

TEST(Writhe, ConvergesToTheGaussIntegralOfTheSmoothCurve) {
  // An independent algorithm: the midpoint rule of the Gauss double integral with the analytic
  // tangent (error O(N⁻²)), Richardson-extrapolated from N and 2N. The inscribed polygon's writhe
  // must approach it at second order.
  const SmoothCurve C = trefoil();
  const double q1 = writhe_gauss_quadrature(C, 1200), q2 = writhe_gauss_quadrature(C, 2400);
  const double wr_smooth = (4 * q2 - q1) / 3;
  const double e1 = std::abs(writhe(C.sample(300)) - wr_smooth);
  const double e2 = std::abs(writhe(C.sample(600)) - wr_smooth);
  std::printf(
      "trefoil: Wr(smooth) ≈ %.9f (quadrature N=2400: %.9f); polygon error n=300: %.2e, "
      "n=600: %.2e, ratio %.2f\n",
      wr_smooth, q2, e1, e2, e1 / e2);
  EXPECT_GT(std::abs(wr_smooth), 2.0);
  EXPECT_LT(e2, 3e-4);             // measured 1.7e-4 (the quadrature's own error: ~6e-7)
  EXPECT_NEAR(e1 / e2, 4.0, 0.3);  // second order; measured 4.00
}

TEST(Writhe, FullersTheoremModTwo) {
  // Fuller, PNAS 75 (1978) 3557: Wr ≡ A/2π − 1 (mod 2), A the area enclosed (counter-clockwise
  // positive) by the tangent indicatrix. For a polygon the indicatrix is the geodesic polygon of
  // the edge tangents (the limit of rounding the corners), and the relation is exact.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> N(0.0, 1.0);
  std::vector<std::vector<Vec3>> curves = {trefoil().sample(300)};
  for (int seed = 20; seed < 24; ++seed) {
    std::mt19937_64 r(seed);
    curves.push_back(random_fourier_curve(r, 3).sample(300));
  }
  for (const auto& X : curves) {
    const int n = int(X.size());
    std::vector<Vec3> t(n);
    for (int k = 0; k < n; ++k) t[k] = (X[(k + 1) % n] - X[k]).normalized();
    const Vec3 pole = Vec3(N(rng), N(rng), N(rng)).normalized();
    const double A = spherical_polygon_area(t, pole);
    const double wr = writhe(X);
    // measured 4e-14
    EXPECT_LT(std::abs(mod_centered(wr - (A / (2 * pi) - 1), 2.0)), 1e-11) << "Wr = " << wr;
  }
}

}  // namespace
}  // namespace ibrod::diagnostics
