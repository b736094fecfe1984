// A blown-up rod (positions diverging) must give a clear error or a correct result, never a
// crash: regression for an int overflow of the cell count at a huge bounding box.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "interactions/interactions.hpp"

namespace ibrod::interactions {
namespace {

TEST(Blowup, HugeExtentUsesACoarseCellListAndMatchesTheDirectSum) {
  ElectroParams p;
  p.law = debye_huckel(0.48, 77.7, 0.1);
  p.cutoff = kDefaultCutoffDebye / p.law.kappa;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-1e12, 1e12);
  std::vector<Vec3> X(600), F(600, Vec3::Zero()), G(600, Vec3::Zero());
  for (auto& x : X) x = Vec3(U(rng), U(rng), U(rng));
  X[1] = X[0] + Vec3(5, 0, 0);  // one close pair among far-flung points
  Electrostatics e(p, 600);
  const double E = e.accumulate(X, F);
  const double Ed = e.accumulate_direct(X, G);
  EXPECT_NEAR(E, Ed, 1e-10 * std::abs(Ed));
  EXPECT_GT(E, 0);
  for (int i = 0; i < 600; ++i) EXPECT_LE((F[i] - G[i]).norm(), 1e-10 * (G[i].norm() + 1e-300));
}

TEST(Blowup, NonFinitePositionsAreARunErrorNamingTheCause) {
  ElectroParams p;
  p.law = debye_huckel(0.48, 77.7, 0.1);
  p.cutoff = kDefaultCutoffDebye / p.law.kappa;
  std::vector<Vec3> X(100), F(100, Vec3::Zero());
  for (int i = 0; i < 100; ++i) X[i] = Vec3(3.4 * i, 0, 0);
  X[50].x() = NAN;
  Electrostatics e(p, 100);
  try {
    e.accumulate(X, F);
    FAIL() << "no error for a NaN position";
  } catch (const RunError& err) {
    EXPECT_NE(std::string(err.what()).find("time.dt_ns"), std::string::npos) << err.what();
  }
}

}  // namespace
}  // namespace ibrod::interactions
