// Steric repulsion (MODEL (2.17–2.18)): closest points, F = −∇E, no force beyond contact or
// between neighbours along the rod, Σ F = 0, cell list = direct sum, no penetration under load.
#include <gtest/gtest.h>

#include <cstdio>

#include "curves.hpp"
#include "interactions/interactions.hpp"

namespace ibrod::interactions {
namespace {

using namespace test;

constexpr double D = 20.0;
constexpr double g = kDefaultStericStiffness;

/// Distance from x to the segment [Q0, Q1] (exact: clamped projection).
double point_segment(const Vec3& x, const Vec3& Q0, const Vec3& Q1) {
  const Vec3 d = Q1 - Q0;
  const double t =
      d.squaredNorm() > 0 ? std::clamp((x - Q0).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0;
  return (x - Q0 - t * d).norm();
}

/// Brute-force segment distance: s ↦ dist(P(s), Q) is convex, so ternary search finds its
/// minimum (to ~1e-13 in s).
double brute_distance(const Vec3& P0, const Vec3& P1, const Vec3& Q0, const Vec3& Q1) {
  double lo = 0, hi = 1;
  auto f = [&](double s) { return point_segment(P0 + s * (P1 - P0), Q0, Q1); };
  for (int it = 0; it < 200; ++it) {
    const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
    if (f(m1) < f(m2))
      hi = m2;
    else
      lo = m1;
  }
  return std::min({f(0.5 * (lo + hi)), f(0), f(1)});
}

/// Segments of length L crossing at angle phi, centres (offsets a, b along each) d0 apart in z.
std::array<Vec3, 4> crossing(double L, double phi, double d0, double a = 0, double b = 0) {
  const Vec3 u(1, 0, 0), v(std::cos(phi), std::sin(phi), 0);
  const Vec3 cP = Vec3(0, 0, d0 / 2) - a * L * u, cQ = Vec3(0, 0, -d0 / 2) - b * L * v;
  return {cP - 0.5 * L * u, cP + 0.5 * L * u, cQ - 0.5 * L * v, cQ + 0.5 * L * v};
}

/// Random rigid rotation and translation (up to `shift` Å) of a 4-point configuration.
std::array<Vec3, 4> moved(std::array<Vec3, 4> x, std::mt19937_64& rng, double shift = 100) {
  const Mat3 R = rotation(random_vec(rng, pi));
  const Vec3 c = random_vec(rng, shift);
  for (Vec3& p : x) p = R * p + c;
  return x;
}

TEST(Steric, ClosestPointsMatchBruteForce) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(0, 1);
  double worst = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::array<Vec3, 4> x;
    const int kind = trial % 4;
    if (kind == 0) {  // general position
      for (Vec3& p : x) p = random_vec(rng, 10);
    } else if (kind == 1) {  // nearly parallel, overlapping or not
      const Vec3 dir = unit_random(rng);
      const Vec3 tilt = 1e-3 * std::pow(10.0, -6 * U(rng)) * unit_random(rng);
      x[0] = random_vec(rng, 5);
      x[1] = x[0] + 4 * dir;
      x[2] = x[0] + random_vec(rng, 5);
      x[3] = x[2] + (4 * U(rng) + 0.5) * (dir + tilt);
    } else if (kind == 2) {  // exactly parallel (or antiparallel)
      const Vec3 dir = unit_random(rng);
      x[0] = random_vec(rng, 5);
      x[1] = x[0] + 3.4 * dir;
      x[2] = x[0] + random_vec(rng, 5);
      x[3] = x[2] + (U(rng) < 0.5 ? -2.0 : 5.0) * dir;
    } else {  // crossing at random angles and offsets
      x = moved(crossing(3.4, pi * U(rng), 20 * U(rng), 2 * U(rng) - 1, 2 * U(rng) - 1), rng);
    }
    const SegmentContact k = closest_points(x[0], x[1], x[2], x[3]);
    const double ref = brute_distance(x[0], x[1], x[2], x[3]);
    ASSERT_GE(k.s, 0.0);
    ASSERT_LE(k.s, 1.0);
    ASSERT_GE(k.t, 0.0);
    ASSERT_LE(k.t, 1.0);
    EXPECT_NEAR(k.sep.norm(), k.d, 1e-14);
    EXPECT_NEAR(k.d, ref, 1e-9) << "trial " << trial;
    worst = std::max(worst, std::abs(k.d - ref));
  }
  std::printf("  closest distance vs brute force: worst |Δd| = %.1e Å\n", worst);
  // a parallel overlap is split evenly: P = [0, 4] x, Q = [1, 5] x at height 5 → s = (1+4)/2/4
  const SegmentContact k =
      closest_points(Vec3(0, 0, 5), Vec3(4, 0, 5), Vec3(1, 0, 0), Vec3(5, 0, 0));
  EXPECT_NEAR(k.s, 0.625, 1e-15);
  EXPECT_NEAR(k.t, 0.375, 1e-15);
  EXPECT_NEAR(k.d, 5.0, 1e-15);
}

/// max over the 12 coordinates of |f + ∂E/∂x| relative to max |f|; ∂E/∂x by the fourth-order
/// central difference (−E(2h) + 8E(h) − 8E(−h) + E(−2h))/(12h).
double pair_gradient_error(const std::array<Vec3, 4>& x0, double h) {
  std::array<Vec3, 4> f, tmp;
  steric_pair(D, g, x0[0], x0[1], x0[2], x0[3], f);
  double err = 0, fmax = 0;
  for (int p = 0; p < 4; ++p)
    for (int a = 0; a < 3; ++a) {
      auto E = [&](double dx) {
        auto x = x0;
        x[p][a] += dx;
        return steric_pair(D, g, x[0], x[1], x[2], x[3], tmp);
      };
      const double dEdx = (-E(2 * h) + 8 * E(h) - 8 * E(-h) + E(-2 * h)) / (12 * h);
      err = std::max(err, std::abs(f[p][a] + dEdx));
      fmax = std::max(fmax, std::abs(f[p][a]));
    }
  return err / fmax;
}

TEST(Steric, PairForceIsMinusGradient) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> U(0, 1);
  const double L = 3.4;
  double worst_cross = 0, worst_par = 0, worst_end = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // crossing at a random angle, closest points interior, overlap 5–90 % of D
    const auto xc = moved(crossing(L, 0.2 + 2.7 * U(rng), D * (0.1 + 0.85 * U(rng)),
                                   0.8 * U(rng) - 0.4, 0.8 * U(rng) - 0.4),
                          rng);
    worst_cross = std::max(worst_cross, pair_gradient_error(xc, 1e-5));
    // nearly parallel (2e-3 to 1e-1 rad) with the lines' closest points inside both segments.
    // Along them d ≈ d0 + φ²x²/2d0, so a step h that tilts a segment by h/L moves the minimiser
    // by x ≈ h d0/(φ² L); E is smooth (quadratic in h) only while x stays inside the segments
    // (≥ 0.2 L from their ends here), so the FD stencil must keep 2h d0/(φ² L) < 0.2 L:
    // h = 0.02 φ² L²/d0 (5e-8 Å at 2e-3 rad), near the origin so that round-off, ~ε|x|/h
    // relative, stays small at such steps (at 1e-3 rad it reaches 6e-7).
    const double phi = std::pow(10.0, -2.7 + 1.7 * U(rng));
    const double d0 = D * (0.1 + 0.85 * U(rng));
    const auto xp = moved(crossing(L, phi, d0, 0.6 * U(rng) - 0.3, 0.6 * U(rng) - 0.3), rng, 5.0);
    const double ep = pair_gradient_error(xp, std::min(0.02 * phi * phi * L * L / d0, 1e-5));
    worst_par = std::max(worst_par, ep);
    // T-junction: the end of one segment against the middle of the other (s clamped, t interior)
    const auto xt = moved(crossing(L, 0.3 + 2.5 * U(rng), D * (0.1 + 0.85 * U(rng)),
                                   0.6 + 0.3 * U(rng), 0.4 * U(rng) - 0.2),
                          rng);
    worst_end = std::max(worst_end, pair_gradient_error(xt, 1e-5));
  }
  std::printf("  steric F + ∇E (rel): crossing %.1e, nearly parallel %.1e, clamped %.1e\n",
              worst_cross, worst_par, worst_end);
  // measured 2.9e-9, 1.0e-7, 1.5e-9 (FD truncation and round-off); bound 1e-6
  EXPECT_LT(worst_cross, 1e-6);
  EXPECT_LT(worst_par, 1e-6);
  EXPECT_LT(worst_end, 1e-6);
}

TEST(Steric, PairPushesApartAndConservesMomentum) {
  std::mt19937_64 rng(13);
  const auto x = moved(crossing(3.4, 1.0, 12.0, 0.1, -0.2), rng);
  std::array<Vec3, 4> f;
  const double E = steric_pair(D, g, x[0], x[1], x[2], x[3], f);
  const SegmentContact k = closest_points(x[0], x[1], x[2], x[3]);
  EXPECT_NEAR(k.d, 12.0, 1e-12);
  EXPECT_NEAR(E, 0.5 * g * 8.0 * 8.0, 1e-9);
  EXPECT_GT((f[0] + f[1]).dot(k.sep), 0);  // P pushed away from Q
  EXPECT_NEAR(((f[0] + f[1]) - g * 8.0 * k.sep / k.d).norm(), 0, 1e-9);
  EXPECT_LT((f[0] + f[1] + f[2] + f[3]).norm(), 1e-12);
  // torque-free as well: the pair acts along the line joining the contact points
  Vec3 tq = Vec3::Zero();
  for (int p = 0; p < 4; ++p) tq += x[p].cross(f[p]);
  EXPECT_LT(tq.norm(), 1e-9);
  // intersecting segments (d = 0): finite push of g D along the common normal
  const auto xi = crossing(3.4, 1.0, 0.0);
  EXPECT_NEAR(steric_pair(D, g, xi[0], xi[1], xi[2], xi[3], f), 0.5 * g * D * D, 1e-9);
  EXPECT_NEAR((f[0] + f[1]).norm(), g * D, 1e-9);
  EXPECT_TRUE(f[0].allFinite() && f[3].allFinite());
}

TEST(Steric, ZeroBeyondContact) {
  std::array<Vec3, 4> f;
  for (double d0 : {D, D + 1e-9, 25.0, 100.0}) {
    const auto x = crossing(3.4, 0.7, d0);
    EXPECT_EQ(steric_pair(D, g, x[0], x[1], x[2], x[3], f), 0.0) << d0;
    for (const Vec3& v : f) EXPECT_EQ(v.norm(), 0.0);
  }
  const auto x = crossing(3.4, 0.7, D - 1e-6);
  EXPECT_GT(steric_pair(D, g, x[0], x[1], x[2], x[3], f), 0.0);
}

TEST(Steric, NeighboursAlongTheRodAreSkipped) {
  // a ring of 16 points 3.4 Å apart is 17 Å across: its segments overlap geometrically, but
  // every pair is ≤ 8 Δs = 27 Å < 2D apart along the rod
  const auto X = circle(16, 16 * kDs / (2 * pi));
  std::array<Vec3, 4> f;
  EXPECT_GT(steric_pair(D, g, X[0], X[1], X[8], X[9], f), 0.0);
  StericParams p;
  p.stiffness = g;
  Steric st(p, 16);
  std::vector<Vec3> F(16, Vec3::Zero());
  EXPECT_EQ(st.accumulate(X, F), 0.0);
  for (const Vec3& v : F) EXPECT_EQ(v.norm(), 0.0);
  EXPECT_EQ(st.energy(X), 0.0);
  // the threshold itself: with n = 24, segments 12 apart are 12 × 3.4 = 40.8 Å > 2D apart
  const auto Y = circle(24, 24 * kDs / (2 * pi));  // 26 Å across: opposite segments 25.9 Å apart
  const auto Z = circle(24, 13 * kDs / (2 * pi));  // same indices, 14 Å across: they overlap
  Steric st24(p, 24);
  EXPECT_EQ(st24.energy(Y), 0.0);
  EXPECT_GT(st24.energy(Z), 0.0);
  StericParams p33 = p;
  p33.ds = 3.3;  // 12 Δs = 39.6 Å ≤ 2D: the same pairs are now neighbours along the rod
  EXPECT_EQ(Steric(p33, 24).energy(Z), 0.0);
}

TEST(Steric, RodForceIsMinusGradientAndCellListEqualsDirect) {
  // a figure-eight whose strands cross 8 and 16 Å apart, and a collapsed supercoil whose strands
  // wind about each other 18 Å apart (overlapping contacts all along, at ~90°)
  struct Case {
    const char* name;
    std::vector<Vec3> X;
  };
  const Case cases[] = {{"figure-eight 8 Å", figure_eight(240, 150.0, 4.0, 0.5, 14)},
                        {"figure-eight 16 Å", figure_eight(240, 150.0, 8.0, 0.5, 16)},
                        {"plectoneme 18 Å", plectoneme(200, kDs, 9.0, 60.0)}};
  for (const Case& c : cases) {
    const auto& X0 = c.X;
    const int n = int(X0.size());
    StericParams p;
    p.stiffness = g;
    p.ds = mean_spacing(X0);
    Steric st(p, n);
    std::vector<Vec3> F(n, Vec3::Zero()), Fd(n, Vec3::Zero());
    const double E = st.accumulate(X0, F);
    EXPECT_TRUE(st.used_cell_list()) << c.name;
    const double Ed = st.accumulate_direct(X0, Fd);
    ASSERT_GT(Ed, 0.0) << c.name;
    EXPECT_NEAR(E, Ed, 1e-12 * Ed) << c.name;
    EXPECT_NEAR(st.energy(X0), Ed, 1e-12 * Ed) << c.name;
    // measured ≤ 1e-15 (summation order only); bound 1e-12
    EXPECT_LT(max_rel_diff(F, Fd), 1e-12) << c.name;
    Vec3 sum = Vec3::Zero();
    double scale = 0;
    std::vector<int> touched;
    for (int i = 0; i < n; ++i) {
      sum += F[i];
      scale += F[i].norm();
      if (F[i].norm() > 0) touched.push_back(i);
    }
    EXPECT_LT(sum.norm(), 1e-13 * scale) << c.name;
    EXPECT_GT(touched.size(), 4u) << c.name;
    // FD on (up to 12 of) the points that feel a force, and on a few that do not
    std::vector<int> probe;
    for (size_t m = 0; m < touched.size(); m += std::max<size_t>(1, touched.size() / 12))
      probe.push_back(touched[m]);
    for (int i = 0; i < n; i += 80) probe.push_back(i);
    auto X = X0;
    double err = 0, fmax = 0;
    const double step = 1e-6;
    for (int i : probe)
      for (int a = 0; a < 3; ++a) {
        X[i][a] = X0[i][a] + step;
        const double Ep = st.energy(X);
        X[i][a] = X0[i][a] - step;
        const double Em = st.energy(X);
        X[i][a] = X0[i][a];
        err = std::max(err, std::abs(F[i][a] + (Ep - Em) / (2 * step)));
        fmax = std::max(fmax, std::abs(F[i][a]));
      }
    std::printf("  %s: %zu points touched, E = %.4g kT, F + ∇E %.1e, cells − direct %.1e (rel)\n",
                c.name, touched.size(), E / kT, err / fmax, max_rel_diff(F, Fd));
    // measured ≤ 4e-8 relative; bound 1e-6
    EXPECT_LT(err / fmax, 1e-6) << c.name;
  }
}

TEST(Steric, ReferenceRingFeelsNothing) {
  StericParams p;
  p.stiffness = g;
  Steric st(p, kN);
  const auto X = circle();
  std::vector<Vec3> F(kN, Vec3::Zero());
  EXPECT_EQ(st.accumulate(X, F), 0.0);
  EXPECT_TRUE(st.used_cell_list());
  for (const Vec3& v : F) EXPECT_EQ(v.norm(), 0.0);
}

/// Overdamped approach of two segments pushed together with `push` per end point (g Å s⁻²):
/// x += (M Δt) F each step, for `steps` steps. Returns the smallest closest distance seen and the
/// distance after `rest_step` steps.
double driven_min_distance(std::array<Vec3, 4> x, double push, double mobility_dt, int steps,
                           int rest_step, double* rest_d) {
  // push each segment toward the other along the initial line of closest approach
  const SegmentContact k0 = closest_points(x[0], x[1], x[2], x[3]);
  const Vec3 u = k0.sep / k0.d;
  double dmin = k0.d;
  std::array<Vec3, 4> f;
  for (int it = 0; it < steps; ++it) {
    steric_pair(D, g, x[0], x[1], x[2], x[3], f);
    for (int p = 0; p < 4; ++p) x[p] += mobility_dt * (f[p] + (p < 2 ? -push : push) * u);
    const double d = closest_points(x[0], x[1], x[2], x[3]).d;
    dmin = std::min(dmin, d);
    if (it + 1 == rest_step) *rest_d = d;
  }
  return dmin;
}

TEST(Steric, DefaultStiffnessStopsSegmentsPushedTogether) {
  // Mobility of an IB point: Stokes drag of its hydrodynamic radius ≈ 1.3 h ≈ 15 Å (Peskin 4-point
  // kernel, c = h = 11.33 Å): M = 1/(6π μ 15 Å) = 3.6e7 s/g with μ = 1e-10 g Å⁻¹ s⁻¹. Moving each
  // end point independently with M overstates the relative mobility of two segments 20 Å apart
  // (which drag the same fluid, M_rel ≈ 0.5 M) by about 2×, so this is conservative.
  // M Δt = 3.6e-3 Å per g Å s⁻² at Δt = 1e-10 s, 7.2e-3 at 2e-10 s. (5e8 s/g is the drag of a
  // 1 Å sphere, not of an IB point; with it no g both holds 40 g Å s⁻² per segment at < 1 Å of
  // overlap, g > 40, and keeps this explicit update stable, g M Δt < 2 ⇒ g < 40.)
  // The segments cross at their centres and come to rest at d = D − 2 push/g; that balance is
  // unstable (a frictionless segment on the convex capsule of the other slides off, as a bead
  // on a sphere: after ~2000 steps here, from round-off), and they then slip past each other,
  // still without coming closer. In a rod the neighbouring segments carry the load instead.
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> U(0, 1);
  // per point 10 g Å s⁻² (twice the electrostatic push of a strand at 20 Å, 0.1 M) at
  // Δt = 1e-10 s and 15 at 1e-10 s; 10 at 2e-10 s (where the default g is at its stability limit)
  for (auto [mobility_dt, push] :
       {std::pair{1e-10 * 3.6e7, 10.0}, {1e-10 * 3.6e7, 15.0}, {2e-10 * 3.6e7, 10.0}}) {
    double worst = D, rest = 0;
    for (int trial = 0; trial < 20; ++trial) {
      const auto x = moved(crossing(3.4, 0.2 + 2.7 * U(rng), 30.0), rng);  // 30 Å apart
      worst = std::min(worst, driven_min_distance(x, push, mobility_dt, 3000, 800, &rest));
      // at rest the contact carries both end points' push (before the slide-off sets in; the
      // softer default spring approaches slowly, measured within 6e-4 Å at step 800)
      EXPECT_NEAR(rest, D - 2 * push / g, 2e-3);
    }
    // stacked parallel segments (the overlap split evenly) and nearly parallel ones
    for (double phi : {0.0, 1e-3})
      worst = std::min(worst, driven_min_distance(crossing(3.4, phi, 30.0), push, mobility_dt, 3000,
                                                  800, &rest));
    std::printf("  M dt = %.1e, push %g: closest approach %.3f Å = %.4f D (at rest %.3f Å)\n",
                mobility_dt, push, worst, worst / D, D - 2 * push / g);
    // rest distance D − 2 push/g: 0.976 D (push 10) and 0.964 D (push 15) with g = 0.1 kT/Å²
    EXPECT_GT(worst, 0.95 * D);
  }
}

}  // namespace
}  // namespace ibrod::interactions
