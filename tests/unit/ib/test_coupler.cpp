// Spreading and interpolation (MODEL §3 Coupling, §4): against a slow direct oracle written from
// the definitions, adjointness, conservation, exactness on linear fields, Peskin's translation
// invariance, periodicity, and race-freedom of the parallel spread.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "core/error.hpp"
#include "ib/coupler.hpp"

namespace ibrod::ib {
namespace {

constexpr double kH = 725.0 / 64;  // the reference grid spacing, Å

GridSpec make_grid(int n) { return GridSpec{n, n * kH}; }

struct Field {
  explicit Field(const GridSpec& g)
      : c{std::vector<double>(g.size()), std::vector<double>(g.size()),
          std::vector<double>(g.size())} {}
  std::array<std::vector<double>, 3> c;
  std::array<double*, 3> ptr() { return {c[0].data(), c[1].data(), c[2].data()}; }
  std::array<const double*, 3> cptr() const { return {c[0].data(), c[1].data(), c[2].data()}; }
  Vec3 at(std::size_t j) const { return {c[0][j], c[1][j], c[2][j]}; }
  double max_abs() const {
    double r = 0;
    for (const auto& v : c)
      for (double x : v) r = std::max(r, std::abs(x));
    return r;
  }
};

Vec3 random_vec(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> uni(lo, hi);
  return {uni(rng), uni(rng), uni(rng)};
}

// Random unwrapped positions in [−2L, 3L)³, plus points on and next to the periodic seam and on
// grid nodes, where the index arithmetic is most fragile.
std::vector<Vec3> test_points(std::mt19937_64& rng, const GridSpec& g, int nrandom) {
  const double L = g.L, h = g.h();
  std::vector<Vec3> X = {{0.0, 0.0, 0.0},
                         {-1e-13, L - 1e-12, 0.5 * h},
                         {L, -L, 2 * L},
                         {L - 0.01 * h, 0.01 * h, -0.01 * h},
                         {3 * h, 5 * h - 1e-9, -7 * h},
                         {-2 * L + 0.3 * h, 3 * L - 0.2 * h, 0.999999 * L}};
  for (int t = 0; t < nrandom; ++t) X.push_back(random_vec(rng, -2 * L, 3 * L));
  return X;
}

Field random_field(std::mt19937_64& rng, const GridSpec& g) {
  Field u(g);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (auto& v : u.c)
    for (double& x : v) x = uni(rng);
  return u;
}

// Central-difference curl on the periodic grid, straight from its definition.
Field curl_h(const Field& a, const GridSpec& g) {
  Field r(g);
  const int n = g.n;
  const double s = 0.5 / g.h();
  auto D = [&](int comp, int dir, int i, int j, int k) {
    int p[3] = {i, j, k}, q[3] = {i, j, k};
    p[dir] = g.wrap(p[dir] + 1);
    q[dir] = g.wrap(q[dir] - 1);
    return (a.c[comp][g.index(p[0], p[1], p[2])] - a.c[comp][g.index(q[0], q[1], q[2])]) * s;
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const std::size_t id = g.index(i, j, k);
        r.c[0][id] = D(2, 1, i, j, k) - D(1, 2, i, j, k);
        r.c[1][id] = D(0, 2, i, j, k) - D(2, 0, i, j, k);
        r.c[2][id] = D(1, 0, i, j, k) - D(0, 1, i, j, k);
      }
  return r;
}

// δ_c(x − X) on the periodic grid through the minimum image (unique: the support 2c < L/2).
double periodic_delta(const GridSpec& g, double c, int i, int j, int k, const Vec3& X) {
  Vec3 d = Vec3(i, j, k) * g.h() - X;
  for (int a = 0; a < 3; ++a) d[a] -= g.L * std::round(d[a] / g.L);
  return delta(d, c);
}

// The oracle: f = Σ F δ_c + ½ curl_h(Σ T δ_c), evaluated everywhere with delta().
Field oracle_spread(const GridSpec& g, int m, const std::vector<Vec3>& X,
                    const std::vector<Vec3>& F, const std::vector<Vec3>& T) {
  Field f(g), a(g);
  const int n = g.n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (std::size_t p = 0; p < X.size(); ++p) {
          const double d = periodic_delta(g, m * g.h(), i, j, k, X[p]);
          for (int x = 0; x < 3; ++x) {
            f.c[x][g.index(i, j, k)] += F[p][x] * d;
            a.c[x][g.index(i, j, k)] += T[p][x] * d;
          }
        }
  const Field ca = curl_h(a, g);
  for (int x = 0; x < 3; ++x)
    for (std::size_t id = 0; id < g.size(); ++id) f.c[x][id] += 0.5 * ca.c[x][id];
  return f;
}

// The oracle: U = Σ u δ_c h³, W = ½ Σ (curl_h u) δ_c h³.
void oracle_interpolate(const GridSpec& g, int m, const std::vector<Vec3>& X, const Field& u,
                        std::vector<Vec3>& U, std::vector<Vec3>& W) {
  const Field cu = curl_h(u, g);
  const double h3 = g.h() * g.h() * g.h();
  U.assign(X.size(), Vec3::Zero());
  W.assign(X.size(), Vec3::Zero());
  for (std::size_t p = 0; p < X.size(); ++p)
    for (int i = 0; i < g.n; ++i)
      for (int j = 0; j < g.n; ++j)
        for (int k = 0; k < g.n; ++k) {
          const double d = periodic_delta(g, m * g.h(), i, j, k, X[p]) * h3;
          U[p] += u.at(g.index(i, j, k)) * d;
          W[p] += 0.5 * cu.at(g.index(i, j, k)) * d;
        }
}

double dot(const Field& a, const Field& b, const GridSpec& g) {  // Σ_x a·b h³
  double s = 0;
  for (int x = 0; x < 3; ++x)
    for (std::size_t id = 0; id < g.size(); ++id) s += a.c[x][id] * b.c[x][id];
  return s * g.h() * g.h() * g.h();
}

TEST(Coupler, RejectsBadKernelWidthAndGrid) {
  EXPECT_THROW(Coupler(make_grid(16), 0), std::invalid_argument);
  EXPECT_THROW(Coupler(make_grid(16), -1), std::invalid_argument);
  EXPECT_THROW(Coupler(make_grid(64), Coupler::kMaxKernelWidth + 1), std::invalid_argument);
  EXPECT_THROW(Coupler(make_grid(16), 4), std::invalid_argument);  // 4m + 2 = 18 > 16
  EXPECT_NO_THROW(Coupler(make_grid(14), 3));                      // 4m + 2 = 14 = n
  EXPECT_THROW(Coupler(GridSpec{16, 0.0}, 1), std::invalid_argument);
  const Coupler c(make_grid(32), 2);
  EXPECT_EQ(c.stencil(), 10);
  EXPECT_DOUBLE_EQ(c.c(), 2 * kH);
}

TEST(Coupler, RejectsMismatchedSizesAndBadPositions) {
  const GridSpec g = make_grid(16);
  const Coupler cp(g, 1);
  Field f(g);
  std::vector<Vec3> X(3, Vec3::Zero()), F(2, Vec3::Zero()), U(3);
  EXPECT_THROW(cp.spread(X, F, {}, f.ptr()), std::invalid_argument);
  F.resize(3);
  const std::span<const Vec3> two_torques = std::span<const Vec3>(F).first(2);
  EXPECT_THROW(cp.spread(X, F, two_torques, f.ptr()), std::invalid_argument);
  EXPECT_THROW(cp.interpolate(X, f.cptr(), std::span<Vec3>(U).first(2), {}), std::invalid_argument);
  EXPECT_THROW(cp.interpolate(X, f.cptr(), U, std::span<Vec3>(U).first(1)), std::invalid_argument);
  X[1][2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(cp.spread(X, F, {}, f.ptr()), RunError);
  EXPECT_THROW(cp.interpolate(X, f.cptr(), U, {}), RunError);
  X[1][2] = 1e300;
  EXPECT_THROW(cp.spread(X, F, {}, f.ptr()), RunError);
  EXPECT_EQ(f.max_abs(), 0.0);  // nothing was spread before the throw
}

// The fast stencil loops reproduce the definitions in the header, evaluated directly.
TEST(Coupler, MatchesDirectOracle) {
  for (int m : {1, 2, 3}) {
    const GridSpec g = make_grid(16);
    const Coupler cp(g, m);
    std::mt19937_64 rng(10 + m);
    const std::vector<Vec3> X = test_points(rng, g, 2);
    std::vector<Vec3> F, T;
    for (std::size_t p = 0; p < X.size(); ++p) {
      F.push_back(random_vec(rng, -1, 1));
      T.push_back(random_vec(rng, -10, 10));
    }
    Field f(g);
    cp.spread(X, F, T, f.ptr());
    const Field fo = oracle_spread(g, m, X, F, T);
    double err = 0;
    for (int x = 0; x < 3; ++x)
      for (std::size_t id = 0; id < g.size(); ++id)
        err = std::max(err, std::abs(f.c[x][id] - fo.c[x][id]));
    // measured 2e-15 relative; bound 1e-12
    EXPECT_LT(err, 1e-12 * fo.max_abs()) << "m = " << m;

    const Field u = random_field(rng, g);
    std::vector<Vec3> U(X.size()), W(X.size()), Uo, Wo;
    cp.interpolate(X, u.cptr(), U, W);
    oracle_interpolate(g, m, X, u, Uo, Wo);
    for (std::size_t p = 0; p < X.size(); ++p) {
      // |U| ~ 0.2 Å s⁻¹: measured 1e-15 (U) and 4e-16 (W h); bound 1e-13
      EXPECT_LT((U[p] - Uo[p]).norm(), 1e-13) << "m = " << m << ", point " << p;
      EXPECT_LT((W[p] - Wo[p]).norm() * g.h(), 1e-13) << "m = " << m << ", point " << p;
    }
  }
}

// MODEL §4: Σ_x f·u h³ = Σ_k (F_k·U_k + T_k·W_k), forces and torques separately and together.
TEST(Coupler, SpreadAndInterpolateAreAdjoint) {
  for (int m : {1, 2, 3}) {
    for (int n : {16, 24}) {
      const GridSpec g = make_grid(n);
      const Coupler cp(g, m);
      std::mt19937_64 rng(100 * m + n);
      const std::vector<Vec3> X = test_points(rng, g, 30);
      std::vector<Vec3> F, T, Z(X.size(), Vec3::Zero());
      for (std::size_t p = 0; p < X.size(); ++p) {
        F.push_back(random_vec(rng, -1e-3, 1e-3));  // g Å s⁻²
        T.push_back(random_vec(rng, -1e-1, 1e-1));  // g Å² s⁻²
      }
      const Field u = random_field(rng, g);
      std::vector<Vec3> U(X.size()), W(X.size());
      cp.interpolate(X, u.cptr(), U, W);
      struct Case {
        const char* name;
        bool force, torque;
      };
      for (const Case cs :
           {Case{"forces", true, false}, Case{"torques", false, true}, Case{"both", true, true}}) {
        Field f(g);
        const std::span<const Vec3> torques =
            cs.torque ? std::span<const Vec3>(T) : std::span<const Vec3>();
        cp.spread(X, cs.force ? F : Z, torques, f.ptr());
        const double lhs = dot(f, u, g);
        double rhs = 0;
        for (std::size_t p = 0; p < X.size(); ++p) {
          if (cs.force) rhs += F[p].dot(U[p]);
          if (cs.torque) rhs += T[p].dot(W[p]);
        }
        // measured ≤ 6e-14 relative (lhs itself is a sum with cancellation); bound 1e-12
        EXPECT_LT(std::abs(lhs - rhs), 1e-12 * std::abs(lhs))
            << cs.name << ", m = " << m << ", n = " << n << ": " << lhs << " vs " << rhs;
      }
    }
  }
}

// Σ_x f h³ = Σ_k F_k: the kernel sums to one (2.15) and the curl of the spread torque telescopes.
TEST(Coupler, ConservesTotalForce) {
  for (int m : {1, 2}) {
    const GridSpec g = make_grid(24);
    const Coupler cp(g, m);
    std::mt19937_64 rng(20 + m);
    const std::vector<Vec3> X = test_points(rng, g, 20);
    std::vector<Vec3> F, T, Z(X.size(), Vec3::Zero());
    Vec3 total = Vec3::Zero();
    double scale = 0;
    for (std::size_t p = 0; p < X.size(); ++p) {
      F.push_back(random_vec(rng, -1, 1));
      T.push_back(random_vec(rng, -1, 1) * 50.0);  // a torque ~ force × 50 Å
      total += F.back();
      scale += F.back().norm();
    }
    const double h3 = g.h() * g.h() * g.h();
    auto integral = [&](const Field& f) {
      Vec3 s = Vec3::Zero();
      for (std::size_t id = 0; id < g.size(); ++id) s += f.at(id) * h3;
      return s;
    };
    Field fboth(g), ftorque(g);
    cp.spread(X, F, T, fboth.ptr());
    cp.spread(X, Z, T, ftorque.ptr());
    // measured 2e-16 and 3e-16 relative to Σ|F|; bound 1e-13
    EXPECT_LT((integral(fboth) - total).norm(), 1e-13 * scale) << "m = " << m;
    EXPECT_LT(integral(ftorque).norm(), 1e-13 * scale) << "m = " << m;
  }
}

// On a field linear in x the interpolation is exact: U = U0 + ω × (X − X0), W = ω. This pins the
// ½ and the sign of the curl (the angular velocity of a rigid rotation is ω).
TEST(Coupler, ExactOnConstantAndLinearFields) {
  for (int m : {1, 2}) {
    const GridSpec g = make_grid(32);
    const Coupler cp(g, m);
    const double L = g.L, h = g.h(), c = cp.c();
    std::mt19937_64 rng(30 + m);
    const Vec3 U0 = random_vec(rng, -1, 1), omega = random_vec(rng, -1, 1) / L,
               X0 = random_vec(rng, 0, L);
    // Linear on the whole unwrapped box [0, L)³ (it jumps across the seam); the points keep 4c
    // from the seam so no stencil crosses it.
    Field u(g), u0(g);
    for (int i = 0; i < g.n; ++i)
      for (int j = 0; j < g.n; ++j)
        for (int k = 0; k < g.n; ++k) {
          const std::size_t id = g.index(i, j, k);
          const Vec3 v = U0 + omega.cross(Vec3(i, j, k) * h - X0);
          for (int x = 0; x < 3; ++x) {
            u.c[x][id] = v[x];
            u0.c[x][id] = U0[x];
          }
        }
    std::vector<Vec3> X;
    for (int t = 0; t < 20; ++t) X.push_back(random_vec(rng, 4 * c, L - 4 * c - h));
    X.push_back(Vec3(4 * c, 4 * c, 4 * c));  // on a grid node
    std::vector<Vec3> U(X.size(), Vec3::Constant(7.0)), W(X.size(), Vec3::Constant(7.0));
    cp.interpolate(X, u0.cptr(), U, W);  // also checks that U, W are overwritten
    for (std::size_t p = 0; p < X.size(); ++p) {
      // measured 6e-16 (U) and 9e-17 (W h), relative to |U0|; bound 1e-13
      EXPECT_LT((U[p] - U0).norm(), 1e-13 * U0.norm()) << "m = " << m << ", point " << p;
      EXPECT_LT(W[p].norm() * h, 1e-13 * U0.norm()) << "m = " << m << ", point " << p;
    }
    cp.interpolate(X, u.cptr(), U, W);
    for (std::size_t p = 0; p < X.size(); ++p) {
      const Vec3 expect = U0 + omega.cross(X[p] - X0);
      // measured 5e-16 relative to |U0| + |ω| L, and 6e-15 relative to |ω|; bound 1e-13
      EXPECT_LT((U[p] - expect).norm(), 1e-13 * (U0.norm() + omega.norm() * L))
          << "m = " << m << ", point " << p;
      EXPECT_LT((W[p] - omega).norm(), 1e-13 * omega.norm()) << "m = " << m << ", point " << p;
    }
  }
}

// IB translation invariance. Spreading a unit force and interpolating at the same point gives
// the self-weight Σ_x w² h³; Peskin's Σφ² = 3/8 makes it exactly (3/(8c))³ for every X and m.
// Spreading a unit torque and interpolating W gives ¼ Σ_x |g × e_z|² h³; for m = 1 this is exact
// too (the 4-point φ also has φ₀φ₂ + φ₁φ₃ = 1/16, so Σ dφ² is constant), for m = 2 only nearly.
// For two points a fixed distance apart, Σ_x w₁w₂ h³ is only approximately invariant.
TEST(Coupler, SelfWeightIsTranslationInvariant) {
  for (int m : {1, 2}) {
    const GridSpec g = make_grid(24);
    const Coupler cp(g, m);
    const double h = g.h(), c = cp.c();
    const Vec3 base(0.37 * g.L, 0.51 * g.L, 0.62 * g.L), step(h, 0.7 * h, 0.3 * h);
    const Vec3 sep(1.0 * h, 0.5 * h, 0.0);  // pair separation
    const std::vector<Vec3> ex = {Vec3::UnitX()}, ez = {Vec3::UnitZ()};
    const std::vector<Vec3> zero = {Vec3::Zero()};
    double self_err = 0;
    double pmin = 1e300, pmax = -1e300, rmin = 1e300, rmax = -1e300;
    for (int t = 0; t <= 40; ++t) {  // X moves across one cell, diagonally
      const std::vector<Vec3> X = {base + step * (t / 40.0)};
      const std::vector<Vec3> X2 = {X[0] + sep};
      std::vector<Vec3> U(1), W(1);
      Field f(g);
      cp.spread(X, ex, {}, f.ptr());
      cp.interpolate(X, f.cptr(), U, {});
      self_err = std::max(self_err, std::abs(U[0][0] / std::pow(0.375 / c, 3) - 1.0));
      cp.interpolate(X2, f.cptr(), U, {});
      pmin = std::min(pmin, U[0][0]);
      pmax = std::max(pmax, U[0][0]);
      Field ft(g);
      cp.spread(X, zero, ez, ft.ptr());
      cp.interpolate(X, ft.cptr(), U, W);
      rmin = std::min(rmin, W[0][2]);
      rmax = std::max(rmax, W[0][2]);
    }
    // measured 2e-15; bound 1e-13
    EXPECT_LT(self_err, 1e-13) << "m = " << m;
    // (max − min)/max over the cell: rotational measured 2e-15 (m = 1, exact) and 0.36% (m = 2),
    // bounds 1e-13 and 1%; pair at separation (h, h/2, 0) measured 5.3% (m = 1) and 0.45%
    // (m = 2), bounds 8% and 1% (the wider kernel is smoother)
    EXPECT_LT((rmax - rmin) / rmax, m == 1 ? 1e-13 : 0.01) << "m = " << m;
    EXPECT_LT((pmax - pmin) / pmax, m == 1 ? 0.08 : 0.01) << "m = " << m;
  }
}

// A point and its periodic images spread the same field (to the round-off of X + L).
TEST(Coupler, PeriodicImagesSpreadIdentically) {
  for (int m : {1, 2}) {
    const GridSpec g = make_grid(16);
    const Coupler cp(g, m);
    std::mt19937_64 rng(40 + m);
    const Vec3 X = random_vec(rng, 0, g.L), F = random_vec(rng, -1, 1),
               T = random_vec(rng, -10, 10);
    Field f0(g);
    cp.spread(std::vector<Vec3>{X}, std::vector<Vec3>{F}, std::vector<Vec3>{T}, f0.ptr());
    for (const Vec3& shift : {Vec3(g.L, 0, 0), Vec3(0, -2 * g.L, 0), Vec3(3 * g.L, g.L, -g.L)}) {
      Field f1(g);
      cp.spread(std::vector<Vec3>{X + shift}, std::vector<Vec3>{F}, std::vector<Vec3>{T}, f1.ptr());
      double err = 0;
      for (int x = 0; x < 3; ++x)
        for (std::size_t id = 0; id < g.size(); ++id)
          err = std::max(err, std::abs(f1.c[x][id] - f0.c[x][id]));
      // measured 1.4e-15 relative; bound 1e-13
      EXPECT_LT(err, 1e-13 * f0.max_abs()) << "m = " << m << ", shift " << shift.transpose();
    }
  }
}

// The parallel spread is race-free and deterministic: with many overlapping stencils, including
// ones across the periodic seam and the slab boundaries, every thread count gives bitwise the same
// field, which also equals spreading the points one call at a time.
TEST(Coupler, ParallelSpreadIsRaceFreeAndDeterministic) {
  for (int m : {1, 2}) {
    const GridSpec g = make_grid(32);
    const Coupler cp(g, m);
    std::mt19937_64 rng(50 + m);
    std::vector<Vec3> X, F, T;
    for (int p = 0; p < 200; ++p) {
      // half in a small cluster straddling the x seam, half anywhere
      X.push_back(p % 2 ? random_vec(rng, -2 * g.h(), 2 * g.h()) : random_vec(rng, -g.L, 2 * g.L));
      F.push_back(random_vec(rng, -1, 1));
      T.push_back(random_vec(rng, -10, 10));
    }
    Field serial(g);
    for (std::size_t p = 0; p < X.size(); ++p)
      cp.spread(std::span(X).subspan(p, 1), std::span(F).subspan(p, 1), std::span(T).subspan(p, 1),
                serial.ptr());
    const int saved = omp_get_max_threads();
    Field first(g);
    // A race shows only sometimes, so each thread count is repeated (an injected race, all slabs
    // in one pass, failed 9 of 10 runs on a busy 2-core machine).
    for (int threads : {1, 2, 4}) {
      omp_set_num_threads(threads);
      Field f(g);
      for (int rep = 0; rep < (threads == 1 ? 1 : 6); ++rep) {
        std::fill(f.c[0].begin(), f.c[0].end(), 0.0);
        std::fill(f.c[1].begin(), f.c[1].end(), 0.0);
        std::fill(f.c[2].begin(), f.c[2].end(), 0.0);
        cp.spread(X, F, T, f.ptr());
        if (threads == 1) first = f;
        for (int x = 0; x < 3; ++x)
          ASSERT_EQ(f.c[x], first.c[x]) << threads << " threads, m = " << m << ", repeat " << rep;
      }
      double err = 0;
      for (int x = 0; x < 3; ++x)
        for (std::size_t id = 0; id < g.size(); ++id)
          err = std::max(err, std::abs(f.c[x][id] - serial.c[x][id]));
      // only the summation order differs; measured 2e-16 relative; bound 1e-12
      EXPECT_LT(err, 1e-12 * serial.max_abs()) << threads << " threads, m = " << m;
    }
    omp_set_num_threads(saved);
  }
}

// Optional arguments: no torques is the same as zero torques; W empty leaves U unchanged.
TEST(Coupler, OptionalTorquesAndAngularVelocity) {
  const GridSpec g = make_grid(16);
  const Coupler cp(g, 1);
  std::mt19937_64 rng(60);
  const std::vector<Vec3> X = test_points(rng, g, 10);
  std::vector<Vec3> F, Z(X.size(), Vec3::Zero());
  for (std::size_t p = 0; p < X.size(); ++p) F.push_back(random_vec(rng, -1, 1));
  Field a(g), b(g);
  cp.spread(X, F, {}, a.ptr());
  cp.spread(X, F, Z, b.ptr());
  for (int x = 0; x < 3; ++x) EXPECT_EQ(a.c[x], b.c[x]);
  std::vector<Vec3> U1(X.size()), U2(X.size()), W(X.size());
  cp.interpolate(X, a.cptr(), U1, {});
  cp.interpolate(X, a.cptr(), U2, W);
  for (std::size_t p = 0; p < X.size(); ++p) EXPECT_EQ(U1[p], U2[p]);
}

}  // namespace
}  // namespace ibrod::ib
