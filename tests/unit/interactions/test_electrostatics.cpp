// Debye–Hückel electrostatics (MODEL (2.19–2.22)): F = −∇E, Newton's third law, cell list =
// direct sum, constants, truncation error of the default cutoff.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/units.hpp"
#include "curves.hpp"
#include "interactions/interactions.hpp"

namespace ibrod::interactions {
namespace {

using namespace test;

ElectroParams params(double salt_M, double cutoff_debye) {
  return electro_params(true, kCharge, kDielectric, salt_M, cutoff_debye);
}

std::vector<Vec3> forces(Electrostatics& e, std::span<const Vec3> X, double* E = nullptr) {
  std::vector<Vec3> F(X.size(), Vec3::Zero());
  const double en = e.accumulate(X, F);
  if (E) *E = en;
  return F;
}

std::vector<Vec3> forces_direct(const Electrostatics& e, std::span<const Vec3> X,
                                double* E = nullptr) {
  std::vector<Vec3> F(X.size(), Vec3::Zero());
  const double en = e.accumulate_direct(X, F);
  if (E) *E = en;
  return F;
}

TEST(Electrostatics, Constants) {
  // MODEL §1: κ = 0.329 √Cs; Bjerrum length e²/(4π ε0 εw kT) ≈ 7.2 Å
  EXPECT_NEAR(units::debye_kappa(0.1), 0.10404, 1e-5);
  EXPECT_NEAR(units::bjerrum_length(77.7, 300), 7.17, 0.01);
  // A = q² l_B kT: the pair law's prefactor from the same constants
  const DebyeHuckel law = debye_huckel(kCharge, kDielectric, 0.1);
  EXPECT_NEAR(law.A, kCharge * kCharge * units::bjerrum_length(77.7, 300) * units::kT(300),
              1e-12 * law.A);
  EXPECT_NEAR(law.kappa, 0.329 * std::sqrt(0.1), 1e-15);
}

TEST(Electrostatics, PairLawForceIsMinusDerivative) {
  double worst = 0;
  for (double salt : {0.001, 0.01, 0.1, 1.0}) {
    const DebyeHuckel law = debye_huckel(kCharge, kDielectric, salt);
    for (double d : {3.4, 10.0, 40.0, 150.0}) {
      const double h = 1e-4 / (law.kappa + 1 / d);  // FD error ~ (h (κ + 1/d))²
      const double dEdd = (law.energy(d + h) - law.energy(d - h)) / (2 * h);
      const double rel = std::abs(law.force_over_d(d) * d + dEdd) / std::abs(dEdd);
      worst = std::max(worst, rel);
      EXPECT_LT(rel, 1e-7) << salt << " " << d;
    }
  }
  std::printf("  pair law −dE/dd vs FD: worst %.1e (rel)\n", worst);  // measured 9e-9
  // two points: the sum is the pair law
  const DebyeHuckel law = debye_huckel(kCharge, kDielectric, 0.1);
  ElectroParams p;
  p.law = law;
  Electrostatics e(p, 2);
  std::vector<Vec3> X{Vec3(1, 2, 3), Vec3(4, -2, 15)};
  double E;
  auto F = forces(e, X, &E);
  const double d = (X[0] - X[1]).norm();
  EXPECT_NEAR(E, law.energy(d), 1e-14 * E);
  EXPECT_LT((F[0] - law.force_over_d(d) * (X[0] - X[1])).norm(), 1e-14 * F[0].norm());
  EXPECT_GT(F[0].dot(X[0] - X[1]), 0);  // like charges repel
}

TEST(Electrostatics, PairEvaluatorAgreesWithItsParts) {
  // eval(d²) is what the pair loops use; energy(d) and force_over_d(d) the same law
  const DebyeHuckel law = debye_huckel(kCharge, kDielectric, 0.1);
  for (double d : {3.4, 10.0, 40.0, 150.0}) {
    const DebyeHuckel::Terms t = law.eval(d * d);
    EXPECT_NEAR(t.energy, law.energy(d), 1e-14 * law.energy(d)) << d;
    EXPECT_NEAR(t.force_over_d, law.force_over_d(d), 1e-14 * law.force_over_d(d)) << d;
  }
  // the config's parameters: rc in Debye lengths, none without salt
  const ElectroParams p = electro_params(true, kCharge, kDielectric, 0.1, kDefaultCutoffDebye);
  EXPECT_EQ(p.cutoff, kDefaultCutoffDebye / p.law.kappa);
  EXPECT_EQ(electro_params(true, kCharge, kDielectric, 0.0, kDefaultCutoffDebye).cutoff, 0.0);
}

TEST(Electrostatics, TotalForceIsMinusGradient) {
  // random clouds, with and without a cutoff that cuts through the cloud (the last one on the
  // cell-list path: 150 Å box, rc = 3/κ = 29 Å); FD on (up to) the first 40 points
  struct Case {
    double salt, cutoff_debye;
    int n;
    double box;
    unsigned seed;
    bool cells;
  };
  for (const Case& c : {Case{0.1, 0.0, 40, 60.0, 1u, false}, Case{0.001, 0.0, 40, 60.0, 2u, false},
                        Case{0.01, 0.0, 40, 60.0, 4u, false}, Case{0.1, 3.0, 40, 60.0, 3u, false},
                        Case{0.1, 3.0, 150, 150.0, 9u, true}}) {
    const auto X0 = cloud(c.seed, c.n, c.box, 3.0);
    Electrostatics e(params(c.salt, c.cutoff_debye), c.n);
    const auto F = forces(e, X0);
    EXPECT_EQ(e.used_cell_list(), c.cells);
    auto X = X0;
    double err = 0, fmax = 0;
    const double h = 1e-5;
    for (int i = 0; i < std::min(c.n, 40); ++i)
      for (int a = 0; a < 3; ++a) {
        X[i][a] = X0[i][a] + h;
        const double Ep = e.energy(X);
        X[i][a] = X0[i][a] - h;
        const double Em = e.energy(X);
        X[i][a] = X0[i][a];
        err = std::max(err, std::abs(F[i][a] + (Ep - Em) / (2 * h)));
        fmax = std::max(fmax, std::abs(F[i][a]));
      }
    std::printf("  cloud n = %d, Cs = %g M, rc = %g/κ: F + ∇E %.1e (rel)\n", c.n, c.salt,
                c.cutoff_debye, err / fmax);
    // measured ≤ 8.4e-9 (FD truncation and round-off); bound 1e-6
    EXPECT_LT(err / fmax, 1e-6) << c.salt << " " << c.cutoff_debye;
  }
}

TEST(Electrostatics, NewtonThirdLawAndTorque) {
  double worst_f = 0, worst_t = 0;
  for (const auto& X :
       {cloud(5, 200, 120.0, 3.0), compact_walk(6), circle(kN, kR0, Vec3(300, 300, 300))}) {
    for (double salt : {0.1, 0.001}) {
      Electrostatics e(params(salt, kDefaultCutoffDebye), int(X.size()));
      const auto F = forces(e, X);
      Vec3 sumF = Vec3::Zero(), torque = Vec3::Zero();
      double scaleF = 0, scaleT = 0;
      for (size_t i = 0; i < X.size(); ++i) {
        sumF += F[i];
        torque += X[i].cross(F[i]);
        scaleF += F[i].norm();
        scaleT += X[i].norm() * F[i].norm();
      }
      // pairs act along X_i − X_j with equal and opposite forces: zero to round-off
      // (measured ≤ 8e-16 and 2.5e-16 relative)
      EXPECT_LT(sumF.norm(), 1e-13 * scaleF);
      EXPECT_LT(torque.norm(), 1e-13 * scaleT);
      worst_f = std::max(worst_f, sumF.norm() / scaleF);
      worst_t = std::max(worst_t, torque.norm() / scaleT);
    }
  }
  std::printf("  |ΣF|/Σ|F| %.1e, |ΣX×F|/Σ|X||F| %.1e\n", worst_f, worst_t);
}

TEST(Electrostatics, CellListEqualsDirectSum) {
  struct Case {
    const char* name;
    std::vector<Vec3> X;
    double salt, cutoff_debye;
    bool cells;  // expected path
  };
  const auto ring = circle();
  const auto walk = compact_walk(7);
  const auto plec = plectoneme();
  const Case cases[] = {
      {"ring 0.1 M", ring, 0.1, kDefaultCutoffDebye, true},       // rc = 154 Å: 4 × 4 × 1 cells
      {"ring 0.01 M", ring, 0.01, kDefaultCutoffDebye, false},    // rc = 486 Å: one cell
      {"ring 0.001 M", ring, 0.001, kDefaultCutoffDebye, false},  // rc = 1538 Å > extent
      {"walk 0.1 M", walk, 0.1, kDefaultCutoffDebye, false},      // extent ≈ 200 Å < 2 rc
      {"walk 0.001 M", walk, 0.001, kDefaultCutoffDebye, false},
      {"plectoneme 0.1 M", plec, 0.1, kDefaultCutoffDebye, true},  // 716 Å long: 4 × 1 × 1
      {"plectoneme 0.001 M", plec, 0.001, kDefaultCutoffDebye, false},
      {"walk 0.1 M, rc = 3/κ", walk, 0.1, 3.0, true},  // many 3-D cells of 29 Å
      {"ring 0.1 M, rc = 3/κ", ring, 0.1, 3.0, true},
      {"ring 0.1 M, no cutoff", ring, 0.1, 0.0, false},
  };
  bool first = true;
  double worst_f = 0, worst_e = 0;
  for (const Case& c : cases) {
    Electrostatics e(params(c.salt, c.cutoff_debye), int(c.X.size()));
    double E, Ed;
    // accumulate adds to what is there
    std::vector<Vec3> F(c.X.size(), Vec3(1, -2, 3));
    E = e.accumulate(c.X, F);
    for (auto& f : F) f -= Vec3(1, -2, 3);
    EXPECT_EQ(e.used_cell_list(), c.cells) << c.name;
    const auto Fd = forces_direct(e, c.X, &Ed);
    // measured ≤ 1e-13 in F (of max |F|; the ring's forces nearly cancel), 8e-14 in E: summation
    // order only; bound 1e-10
    EXPECT_LT(max_rel_diff(F, Fd), 1e-10) << c.name;
    EXPECT_NEAR(E, Ed, 1e-10 * std::abs(Ed)) << c.name;
    worst_f = std::max(worst_f, max_rel_diff(F, Fd));
    worst_e = std::max(worst_e, std::abs(E - Ed) / std::abs(Ed));
    if (first) {
      first = false;
      EXPECT_NEAR(e.energy(c.X), Ed, 1e-10 * std::abs(Ed)) << c.name;
      // a later call reuses the scratch and gives the same answer, bit for bit
      double E1, E2;
      const auto F1 = forces(e, c.X, &E1);
      const auto F2 = forces(e, c.X, &E2);
      EXPECT_EQ(max_rel_diff(F2, F1), 0.0) << c.name;
      EXPECT_EQ(E2, E1) << c.name;
    }
  }
  std::printf("  accumulate vs direct oracle: F %.1e, E %.1e (rel)\n", worst_f, worst_e);
}

TEST(Electrostatics, TruncationErrorOfDefaultCutoff) {
  // the ring (forces nearly cancel: the hardest case), a compact 3-D walk, a collapsed supercoil
  const auto ring = circle();
  const auto walk = compact_walk(8);
  const auto plec = plectoneme();
  for (const auto* X : {&ring, &walk, &plec})
    for (double salt : {0.1, 0.01}) {
      Electrostatics cut(params(salt, kDefaultCutoffDebye), kN);
      Electrostatics full(params(salt, 0.0), kN);
      double Ec, Ef;
      const auto Fc = forces(cut, *X, &Ec);
      const auto Ff = forces(full, *X, &Ef);
      const double rel = max_rel_diff(Fc, Ff);
      const char* name = X == &ring ? "ring" : X == &walk ? "walk" : "plectoneme";
      std::printf("  %s Cs = %.2g M: force truncation error %.2e, energy %.3e kT of %.6g kT\n",
                  name, salt, rel, (Ec - Ef) / kT, Ef / kT);
      // measured: ring 6.3e-8 (0.1 M), 6.4e-8 (0.01 M); walk 7.9e-9, 0 (rc > extent);
      // plectoneme 3.2e-9, 7.8e-10; bound 1e-6
      EXPECT_LT(rel, 1e-6) << name << " " << salt;
      // shift N_pairs(d ≤ rc) E(rc) plus the dropped tail: measured ≤ 2.1e-4 kT
      EXPECT_NEAR(Ec, Ef, 1e-3 * kT) << name << " " << salt;
    }
}

TEST(Electrostatics, DisabledDoesNothing) {
  ElectroParams p = params(0.1, kDefaultCutoffDebye);
  p.enabled = false;
  Electrostatics e(p, kN);
  const auto X = circle();
  std::vector<Vec3> F(kN, Vec3::Zero());
  EXPECT_EQ(e.accumulate(X, F), 0.0);
  for (const auto& f : F) EXPECT_EQ(f.norm(), 0.0);
}

}  // namespace
}  // namespace ibrod::interactions
