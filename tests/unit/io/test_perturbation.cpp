// Random twist perturbations (rod.perturbation_random, io/perturbation.hpp): reproducible from the
// seed, uniform on [−A, A), added to the deterministic list, recorded in the resolved config.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.hpp"
#include "io/config.hpp"
#include "io/npy.hpp"
#include "io/perturbation.hpp"

using namespace ibrod;
using ::testing::HasSubstr;

TEST(RandomPerturbation, TheSameSeedGivesTheSameAmplitudesAndOthersDiffer) {
  const io::RandomPerturbation a{8, 0.5, 42}, b{8, 0.5, 42}, c{8, 0.5, 43};
  const auto ea = io::draw_perturbation(a), eb = io::draw_perturbation(b),
             ec = io::draw_perturbation(c);
  ASSERT_EQ(ea.size(), 8u);
  EXPECT_EQ(ea, eb);  // bit for bit
  int same = 0;
  for (int m = 0; m < 8; ++m) same += ea[m] == ec[m];
  EXPECT_EQ(same, 0);
  // the first M of M + 1 modes are the same draws (mode m does not depend on M)
  const auto longer = io::draw_perturbation({9, 0.5, 42});
  for (int m = 0; m < 8; ++m) EXPECT_EQ(longer[m], ea[m]);
}

TEST(RandomPerturbation, IsUniformOnMinusAToA) {
  // 20000 draws of A = 2: all in [−2, 2), mean ≈ 0 (σ/√N = 1.15/141 ≈ 0.008), variance A²/3
  const auto e = io::draw_perturbation({20000, 2.0, 7});
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
  EXPECT_EQ(io::draw_perturbation({10000, 1.0, 5489}).back(), 2.0 * u - 1.0);
}

TEST(RandomPerturbation, IsAddedToTheDeterministicListAndRecordedInConfigToml) {
  io::Config c;
  io::apply_toml(c,
                 "[rod]\nperturbation = [1.0]\n"
                 "perturbation_random = { modes = 3, amplitude = 0.25, seed = 11 }\n",
                 "test");
  const auto drawn = io::draw_perturbation({3, 0.25, 11});
  const auto p = io::to_params(c);
  ASSERT_EQ(p.circle.perturbation.size(), 3u);
  EXPECT_EQ(p.circle.perturbation[0], 1.0 + drawn[0]);
  EXPECT_EQ(p.circle.perturbation[1], drawn[1]);
  EXPECT_EQ(p.circle.perturbation[2], drawn[2]);
  // config.toml round trip: the same ε_m
  io::Config again;
  io::apply_toml(again, io::to_toml(c), "config.toml");
  EXPECT_EQ(again.rod_perturbation_random, c.rod_perturbation_random);
  EXPECT_EQ(io::to_params(again).circle.perturbation, p.circle.perturbation);
  EXPECT_THAT(io::to_toml(c), HasSubstr("perturbation_random = { amplitude = 0.25, modes = 3, seed = 11 }"));
  // ibrod check shows the drawn values
  EXPECT_THAT(io::describe(c), HasSubstr("-> eps = ["));
}

TEST(RandomPerturbation, SubKeysCanBeSetAloneAndBadOnesAreNamed) {
  io::Config c;
  io::apply_override(c, "rod.perturbation_random={modes=4, amplitude=1, seed=1}");
  io::apply_override(c, "rod.perturbation_random.seed=9");
  EXPECT_EQ(c.rod_perturbation_random, (io::RandomPerturbation{4, 1.0, 9}));
  auto error_of = [&](const std::string& s) {
    try {
      io::apply_override(c, s);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_THAT(error_of("rod.perturbation_random.sed=3"),
              HasSubstr("unknown key 'rod.perturbation_random.sed'"));
  EXPECT_THAT(error_of("rod.perturbation_random.amplitude=-1"),
              HasSubstr("rod.perturbation_random.amplitude = -1"));
  EXPECT_THAT(error_of("rod.perturbation_random=3"), HasSubstr("rod.perturbation_random = 3"));
  EXPECT_THAT(error_of("rod.perturbation_random.seed=-2"), HasSubstr("seed"));
}

TEST(VelocityNpy, RoundTripsInAngstromPerNanosecond) {
  const int n = 4;
  std::vector<double> u(3 * 64);
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = 1e9 * (double(i) - 20.5);  // Å/s
  const auto path = std::filesystem::temp_directory_path() / "ibrod_test_velocity.npy";
  io::write_velocity_npy(path, n, u.data(), u.data() + 64, u.data() + 128);
  int got_n = 0;
  const auto v = io::read_velocity_npy(path, got_n);
  EXPECT_EQ(got_n, n);
  ASSERT_EQ(v.size(), u.size());
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_DOUBLE_EQ(v[i], double(i) - 20.5);
  // the data start at a multiple of 64 bytes (NPY 1.0 alignment)
  EXPECT_EQ(std::filesystem::file_size(path) % 64, (u.size() * 8) % 64);
  std::filesystem::remove(path);
}
