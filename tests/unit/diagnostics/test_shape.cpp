// Shape analysis (diagnostics/shape.hpp) on constructed curves of a 2000 Å rod: a circle, a
// figure-8 (lemniscate with its lobes tilted apart), a two-ply interwound curve with two terminal
// loops, and toroidal rosettes of 3 and 4 lobes; plus the pieces (crossings of known projections,
// segment distance, contact clusters).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include "diagnostics/shape.hpp"
#include "diagnostics/topology.hpp"

namespace ibrod::diagnostics {
namespace {

constexpr double pi = std::numbers::pi;

/// The closed polygon through `P` resampled at n points evenly spaced in arc length.
std::vector<Vec3> resample(const std::vector<Vec3>& P, int n) {
  std::vector<double> s{0};
  for (std::size_t k = 0; k < P.size(); ++k)
    s.push_back(s.back() + (P[(k + 1) % P.size()] - P[k]).norm());
  std::vector<Vec3> X;
  std::size_t k = 0;
  for (int m = 0; m < n; ++m) {
    const double want = s.back() * m / n;
    while (s[k + 1] < want) ++k;
    const double f = (want - s[k]) / (s[k + 1] - s[k]);
    X.push_back(P[k] + f * (P[(k + 1) % P.size()] - P[k]));
  }
  return X;
}

std::vector<Vec3> sample(int n, double t_end, const std::function<Vec3(double)>& r) {
  std::vector<Vec3> P;
  for (int k = 0; k < 4 * n; ++k) P.push_back(r(t_end * k / (4 * n)));
  return resample(P, n);
}

std::vector<Vec3> circle(int n, double R) {
  return sample(n, 2 * pi, [R](double t) { return Vec3(R * std::cos(t), R * std::sin(t), 0); });
}

/// Lemniscate of Gerono (x = a sin t, y = a sin t cos t), its two lobes (x > 0, x < 0) turned by
/// ±tilt about the x axis, the strands at the crossing 2h apart in z.
std::vector<Vec3> figure8(int n, double a, double tilt, double h) {
  return sample(n, 2 * pi, [=](double t) {
    const double x = a * std::sin(t), y = a * std::sin(t) * std::cos(t);
    const double psi = tilt * std::tanh(x / (0.2 * a));
    return Vec3(x, y * std::cos(psi), y * std::sin(psi) + h * std::cos(t));
  });
}

/// Two plies along z (x = ±rho, |z| ≤ Z) closed by two terminal loops (circular arcs of radius
/// rc > rho), then twisted about z by `half_turns` half turns over the plies (loops turn rigidly).
std::vector<Vec3> interwound(int n, double rho, double rc, double Z, double half_turns) {
  std::vector<Vec3> P;
  const double zc = std::sqrt(rc * rc - rho * rho);
  const double phi0 = std::atan2(-zc, rho);  // angle of (rho, Z) seen from the loop's centre
  const int m = 400;
  for (int k = 0; k < m; ++k) P.emplace_back(rho, 0, -Z + 2 * Z * k / m);  // up
  for (int k = 0; k < m; ++k) {  // top loop, from (rho, Z) round to (−rho, Z)
    const double phi = phi0 + (pi - 2 * phi0) * k / m;
    P.emplace_back(rc * std::cos(phi), 0, Z + zc + rc * std::sin(phi));
  }
  for (int k = 0; k < m; ++k) P.emplace_back(-rho, 0, Z - 2 * Z * k / m);  // down
  for (int k = 0; k < m; ++k) {                                            // bottom loop
    const double phi = phi0 + (pi - 2 * phi0) * k / m;
    P.emplace_back(-rc * std::cos(phi), 0, -Z - zc - rc * std::sin(phi));
  }
  for (Vec3& p : P) {
    const double psi = 0.5 * pi * half_turns * std::clamp(p.z() / Z, -1.0, 1.0);
    p = Vec3(p.x() * std::cos(psi), p.x() * std::sin(psi), p.z());
  }
  return resample(P, n);
}

/// A rosette of `lobes` lobes winding `turns` times about z: radius R + a cos(lobes θ / turns),
/// z = h sin(θ / turns), θ ∈ [0, 2π turns).
std::vector<Vec3> rosette(int n, int lobes, int turns, double R, double a, double h) {
  return sample(n, 2 * pi * turns, [=](double t) {
    const double r = R + a * std::cos(lobes * t / turns);
    return Vec3(r * std::cos(t), r * std::sin(t), h * std::sin(t / turns));
  });
}

ShapeOptions options() {
  ShapeOptions o;
  o.contact_distance_A = 50;
  return o;
}

TEST(Shape, CircleHasNoCrossingsAndIsACircle) {
  const auto X = circle(600, 325);
  const Shape s = analyze_shape(X, options());
  EXPECT_EQ(s.crossings, 0);
  EXPECT_EQ(s.crossings_mode, 0);
  EXPECT_EQ(s.cls, ShapeClass::circle);
  EXPECT_EQ(s.loops, 1);
  EXPECT_EQ(s.lobes, 0);
  EXPECT_EQ(s.interwound_length_A, 0);
  EXPECT_EQ(s.contact_clusters, 0);
  EXPECT_STREQ(shape_class_name(s.cls), "circle");
}

TEST(Shape, Figure8HasOneCrossingAndTwoLoops) {
  const auto X = figure8(600, 500, pi / 4, 15);
  const Shape s = analyze_shape(X, options());
  EXPECT_EQ(s.crossings, 0);  // seen along y, the tilted lobes fold into one loop
  EXPECT_EQ(s.crossings_mode, 1);
  EXPECT_EQ(s.lobes, 2);
  EXPECT_EQ(s.cls, ShapeClass::figure8);
  EXPECT_EQ(s.loops, 2);
  EXPECT_EQ(s.interwound_length_A, 0);
  EXPECT_EQ(s.contact_clusters, 1);  // the crossing: one transversal contact
}

TEST(Shape, InterwoundCurveIsPlectonemicWithTwoTerminalLoops) {
  const double rho = 20, Z = 350;  // plies 40 Å apart, 700 Å long
  const auto X = interwound(600, rho, 70, Z, 3);
  const Shape s = analyze_shape(X, options());
  EXPECT_EQ(s.crossings, 3);  // the nodes: measured 3 in 178 of 200 directions
  EXPECT_EQ(s.crossings_mode, 3);
  EXPECT_EQ(s.cls, ShapeClass::plectonemic);
  EXPECT_EQ(s.loops, 2);
  // the two-ply region is the plies (2Z) less the stretches near the loops whose partner is
  // closer along the rod than 2 d_c: within 10 %
  EXPECT_GT(s.interwound_length_A, 0.9 * (2 * Z - 100));
  EXPECT_LT(s.interwound_length_A, 1.1 * 2 * Z);
  EXPECT_EQ(s.interwound_runs, 2);  // one per ply
}

TEST(Shape, PliesFartherThanTheContactDistanceAreNotTwoPly) {
  ShapeOptions o = options();
  o.contact_distance_A = 30;  // plies 40 Å apart
  const Shape s = analyze_shape(interwound(600, 20, 70, 350, 3), o);
  EXPECT_EQ(s.interwound_length_A, 0);
  EXPECT_NE(s.cls, ShapeClass::plectonemic);
}

TEST(Shape, ThreeLobedRosetteIsToroidal) {
  const auto X = rosette(600, 3, 2, 160, 60, 30);
  const Shape s = analyze_shape(X, options());
  EXPECT_EQ(s.crossings_mode, 3);  // the view from above and most others
  EXPECT_EQ(s.lobes, 3);
  EXPECT_EQ(s.cls, ShapeClass::toroidal);
  EXPECT_EQ(s.loops, 3);
  EXPECT_EQ(s.interwound_length_A, 0);
}

TEST(Shape, FourLobedRosetteIsToroidal) {
  const auto X = rosette(600, 4, 3, 110, 40, 40);
  const Shape s = analyze_shape(X, options());
  EXPECT_EQ(s.crossings, 2);
  EXPECT_EQ(s.crossings_mode, 8);  // from above: 4 (turns − 1)
  EXPECT_EQ(s.lobes, 4);
  EXPECT_EQ(s.cls, ShapeClass::toroidal);
  EXPECT_EQ(s.loops, 4);
  EXPECT_EQ(s.interwound_length_A, 0);
}

TEST(Shape, WavyRingWithoutCrossingsIsACircleNotAToroid) {
  const Shape s = analyze_shape(rosette(600, 3, 1, 300, 60, 0), options());
  EXPECT_EQ(s.lobes, 3);
  EXPECT_EQ(s.crossings_mode, 0);
  EXPECT_EQ(s.cls, ShapeClass::circle);
}

TEST(Shape, CrossingsOfKnownProjections) {
  const auto X = rosette(300, 3, 2, 160, 60, 30);
  EXPECT_EQ(projected_crossings(X, Vec3::UnitZ()), 3);  // the rosette seen from above
  EXPECT_EQ(projected_crossings(circle(100, 50), Vec3::UnitZ()), 0);
  // figure-8 seen from above: one crossing, whatever the tilt of the view within 30°
  const auto F = figure8(400, 500, 0, 15);
  EXPECT_EQ(projected_crossings(F, Vec3(0.3, 0.2, 1)), 1);
  EXPECT_EQ(hemisphere_directions(200).size(), 200u);
  for (const Vec3& u : hemisphere_directions(50)) {
    EXPECT_NEAR(u.norm(), 1, 1e-12);
    EXPECT_GT(u.z(), 0);
  }
}

TEST(Shape, SegmentDistance) {
  // skew perpendicular segments 5 apart; parallel offset; end to end
  EXPECT_NEAR(segment_distance({-1, 0, 0}, {1, 0, 0}, {0, -1, 5}, {0, 1, 5}), 5, 1e-12);
  EXPECT_NEAR(segment_distance({0, 0, 0}, {1, 0, 0}, {0, 3, 0}, {1, 3, 0}), 3, 1e-12);
  EXPECT_NEAR(segment_distance({0, 0, 0}, {1, 0, 0}, {4, 4, 0}, {5, 4, 0}), 5, 1e-12);
  EXPECT_NEAR(segment_distance({0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {3, 0, 0}), 2, 1e-12);
}

TEST(Shape, ContactClustersOfTheFigure8AndTheInterwoundCurve) {
  // the figure-8: one cluster at the crossing; nothing when the strands are farther apart
  EXPECT_EQ(contact_clusters(figure8(600, 500, pi / 4, 15), 50, 100).size(), 1u);
  EXPECT_EQ(contact_clusters(figure8(600, 500, pi / 4, 40), 50, 100).size(), 0u);
  // the interwound curve: one band along the plies
  const auto c = contact_clusters(interwound(600, 20, 70, 350, 3), 50, 100);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_GT(c[0].size(), 100u);
}

TEST(Shape, RejectsTooFewPoints) {
  EXPECT_THROW(analyze_shape(circle(5, 10)), std::invalid_argument);
}

}  // namespace
}  // namespace ibrod::diagnostics
