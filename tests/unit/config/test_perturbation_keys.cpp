// rod.perturbation_random as config keys: sub-keys set alone, bad ones named, the drawn amplitudes
// added to the deterministic list and recorded in the resolved config.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "config/config.hpp"
#include "core/error.hpp"
#include "rod/perturbation.hpp"

using namespace ibrod;
using ::testing::HasSubstr;

TEST(RandomPerturbation, IsAddedToTheDeterministicListAndRecordedInConfigToml) {
  config::Config c;
  config::apply_toml(c,
                     "[rod]\nperturbation = [1.0]\n"
                     "perturbation_random = { modes = 3, amplitude = 0.25, seed = 11 }\n",
                     "test");
  const auto drawn = rod::draw_perturbation({3, 0.25, 11});
  const auto p = config::to_params(c);
  ASSERT_EQ(p.shapes[0].circle.perturbation.size(), 3u);
  EXPECT_EQ(p.shapes[0].circle.perturbation[0], 1.0 + drawn[0]);
  EXPECT_EQ(p.shapes[0].circle.perturbation[1], drawn[1]);
  EXPECT_EQ(p.shapes[0].circle.perturbation[2], drawn[2]);
  // config.toml round trip: the same ε_m
  config::Config again;
  config::apply_toml(again, config::to_toml(c), "config.toml");
  EXPECT_EQ(again.rod_perturbation_random, c.rod_perturbation_random);
  EXPECT_EQ(config::to_params(again).shapes[0].circle.perturbation,
            p.shapes[0].circle.perturbation);
  EXPECT_THAT(config::to_toml(c),
              HasSubstr("perturbation_random = { amplitude = 0.25, modes = 3, seed = 11 }"));
  // ibrod check shows the drawn values
  EXPECT_THAT(config::describe(c), HasSubstr("-> eps = ["));
}

TEST(RandomPerturbation, SubKeysCanBeSetAloneAndBadOnesAreNamed) {
  config::Config c;
  config::apply_override(c, "rod.perturbation_random={modes=4, amplitude=1, seed=1}");
  config::apply_override(c, "rod.perturbation_random.seed=9");
  EXPECT_EQ(c.rod_perturbation_random, (rod::RandomPerturbation{4, 1.0, 9}));
  auto error_of = [&](const std::string& s) {
    try {
      config::apply_override(c, s);
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
