// Config: defaults are MODEL §1's reference table, conversions to internal units, and every kind
// of bad input is a ConfigError naming the key.
#include <cmath>
#include <sstream>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "config/config.hpp"
#include "core/error.hpp"

using namespace ibrod;
using ::testing::HasSubstr;

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Config, DefaultsAreTheReferenceTableInInternalUnits) {
  const config::Config c;
  config::validate(c);
  const auto p = config::to_params(c);
  EXPECT_EQ(p.stepper.grid.n, 64);
  EXPECT_DOUBLE_EQ(p.stepper.grid.L, 725.0);
  EXPECT_DOUBLE_EQ(p.stepper.fluid.dt, 1e-10);
  EXPECT_NEAR(p.stepper.fluid.density, 1e-24, 1e-38);
  EXPECT_NEAR(p.stepper.fluid.viscosity, 1e-10, 1e-24);
  EXPECT_NEAR(p.stepper.rods[0].a[0], 1.3e5, 1e-9);
  EXPECT_NEAR(p.stepper.rods[0].a[2], 1.82e5, 1e-9);
  EXPECT_NEAR(p.stepper.rods[0].b[0], 5e3, 1e-10);
  EXPECT_NEAR(p.stepper.rods[0].b[2], 5e3, 1e-10);
  EXPECT_EQ(p.stepper.rods[0].n, 600);
  EXPECT_DOUBLE_EQ(p.stepper.rods[0].ds, 3.4);
  EXPECT_NEAR(p.kT, 414.2, 0.05);
  EXPECT_NEAR(p.stepper.electro.law.kappa, 0.10404, 1e-5);  // MODEL §1: 0.329 √0.1
  EXPECT_EQ(p.shapes[0].circle.excess_link, 6);
  ASSERT_EQ(p.shapes[0].circle.perturbation.size(), 1u);
  EXPECT_EQ(p.shapes[0].circle.perturbation[0], 1.0);
  EXPECT_NEAR(p.stop_kinetic, 1e-12 * p.kT, 1e-20);
}

TEST(Config, OverridesAreTyped) {
  config::Config c;
  config::apply_override(c, "grid.n=32");
  config::apply_override(c, "rod.perturbation=[0.5, 0, 0.25]");
  config::apply_override(c, "electrostatics.enabled=false");
  config::apply_override(c, "rod.excess_link=2.0");  // an integral float is an integer
  EXPECT_EQ(c.grid_n, 32);
  EXPECT_EQ(c.rod_perturbation, (std::vector<double>{0.5, 0.0, 0.25}));
  EXPECT_FALSE(c.electrostatics_enabled);
  EXPECT_EQ(c.rod_excess_link, 2);
}

TEST(Config, BadValuesNameTheKeyTheValueAndWhatIsAllowed) {
  config::Config c;
  auto msg = error_of([&] { config::apply_override(c, "grid.kernel_width=1.5"); });
  EXPECT_THAT(msg, HasSubstr("grid.kernel_width"));
  EXPECT_THAT(msg, HasSubstr("1.5"));
  EXPECT_THAT(msg, HasSubstr("integer"));
  msg = error_of([&] { config::apply_override(c, "solvent.viscosity_poise=-0.01"); });
  EXPECT_THAT(msg, HasSubstr("solvent.viscosity_poise"));
  EXPECT_THAT(msg, HasSubstr(">= 1e-22"));  // 20 decades below the reference 0.01 poise
  msg = error_of([&] { config::apply_override(c, "rod.excess_link=2.5"); });
  EXPECT_THAT(msg, HasSubstr("rod.excess_link"));
  msg = error_of([&] { config::apply_override(c, "rod.base_pairs=0"); });
  EXPECT_THAT(msg, HasSubstr("rod.base_pairs"));
  msg = error_of([&] { config::apply_override(c, "rod.base_pairs=-5"); });
  EXPECT_THAT(msg, HasSubstr("rod.base_pairs"));
  msg = error_of([&] { config::apply_override(c, "grid.n=\"big\""); });
  EXPECT_THAT(msg, HasSubstr("grid.n"));
  msg = error_of([&] { config::apply_override(c, "steric.enabled=1"); });
  EXPECT_THAT(msg, HasSubstr("true or false"));
  msg = error_of([&] { config::apply_override(c, "rod.perturbation=[1, \"x\"]"); });
  EXPECT_THAT(msg, HasSubstr("rod.perturbation"));
  msg = error_of([&] { config::apply_override(c, "time.dt_ns=nan"); });
  EXPECT_THAT(msg, HasSubstr("time.dt_ns"));
}

TEST(Config, UnknownKeysAndSectionsAreErrors) {
  config::Config c;
  auto msg = error_of([&] { config::apply_override(c, "grid.nn=64"); });
  EXPECT_THAT(msg, HasSubstr("unknown key 'grid.nn'"));
  EXPECT_THAT(msg, HasSubstr("kernel_width"));  // lists the keys that exist
  msg = error_of([&] { config::apply_toml(c, "[gird]\nn = 64\n", "t.toml"); });
  EXPECT_THAT(msg, HasSubstr("gird.n"));
  msg = error_of([&] { config::apply_toml(c, "n = 64\n", "t.toml"); });
  EXPECT_THAT(msg, HasSubstr("must be a section"));
  msg = error_of([&] { config::apply_override(c, "novalue"); });
  EXPECT_THAT(msg, HasSubstr("section.key=value"));
}

TEST(Config, BrokenTomlReportsTheLine) {
  config::Config c;
  const auto msg =
      error_of([&] { config::apply_toml(c, "[grid]\nn = 64\nbox_A = = 3\n", "bad.toml"); });
  EXPECT_THAT(msg, HasSubstr("bad.toml:3"));
  EXPECT_THAT(msg, HasSubstr("TOML"));
}

TEST(Config, CrossKeyValidation) {
  config::Config c;
  c.grid_n = 63;
  EXPECT_THAT(error_of([&] { config::validate(c); }), HasSubstr("grid.n"));
  c = config::Config{};
  c.grid_box_A = 500;  // the 649 Å ring does not fit
  EXPECT_THAT(error_of([&] { config::validate(c); }), HasSubstr("grid.box_A"));
  c = config::Config{};
  c.grid_n = 16;
  c.grid_kernel_width = 4;  // 18 stencil points > 16
  EXPECT_THAT(error_of([&] { config::validate(c); }), HasSubstr("grid.kernel_width"));
  c = config::Config{};
  c.rod_base_pairs = 10;
  c.rod_excess_link = 1000;  // |sin β| > 1
  c.grid_box_A = 100;
  EXPECT_THAT(error_of([&] { config::validate(c); }), HasSubstr("rod.excess_link"));
}

TEST(Config, ResolvedTomlRoundTrips) {
  config::Config c;
  config::apply_override(c, "grid.n=32");
  config::apply_override(c, "rod.perturbation=[0.5, 0.25]");
  config::apply_override(c, "solvent.salt_M=0.01");
  config::apply_override(c, "output.every_steps=7");
  config::Config d;
  config::apply_toml(d, config::to_toml(c), "resolved");
  EXPECT_EQ(config::describe(c), config::describe(d));
  EXPECT_NE(config::describe(c), config::describe(config::Config{}));
}

// config.toml: every key on its own line with a comment that gives its unit (the unit its name's
// suffix promises), and numbers in their shortest form that reads back as the same double.
TEST(Config, ResolvedTomlHasAUnitCommentPerKeyAndShortestRoundTripNumbers) {
  config::Config c;
  config::apply_override(c, "electrostatics.charge_e=0.48");        // 0.47999999999999998 in full
  config::apply_override(c, "solvent.salt_M=0.30000000000000004");  // 0.1 + 0.2
  config::apply_override(c, "time.t_end_us=0.3333333333333333");
  config::apply_override(c, "rod.perturbation=[1, 0.1]");
  const std::string text = config::to_toml(c);
  EXPECT_THAT(text, HasSubstr("charge_e = 0.48 "));
  EXPECT_THAT(text, HasSubstr("salt_M = 0.30000000000000004 "));
  EXPECT_THAT(text, HasSubstr("t_end_us = 0.3333333333333333 "));
  EXPECT_THAT(text, HasSubstr("box_A = 725.0 "));  // a float stays a float
  EXPECT_THAT(text, HasSubstr("perturbation = [1.0, 0.1] "));
  config::Config d;
  config::apply_toml(d, text, "config.toml");
  EXPECT_EQ(d.electrostatics_charge_e, c.electrostatics_charge_e);  // bit for bit
  EXPECT_EQ(d.solvent_salt_M, c.solvent_salt_M);
  EXPECT_EQ(d.time_t_end_us, c.time_t_end_us);
  EXPECT_EQ(d.steric_stiffness_kT_A2, c.steric_stiffness_kT_A2);
  EXPECT_EQ(config::to_toml(d), text);
  // units promised by a key's suffix, as its comment must state them
  const std::vector<std::pair<std::string, std::string>> unit_of = {
      {"_per_A", "rad/Å"}, {"_A", "Å"},         {"_ns", "ns"},         {"_us", "µs"},
      {"_kT", "kT"},       {"_M", "mol/L"},     {"_K", "K"},           {"_rad", "rad"},
      {"_poise", "poise"}, {"_g_cm3", "g/cm³"}, {"_erg_cm", "erg·cm"}, {"_dyn", "dyn"},
      {"_e", ", e"}};
  std::istringstream in(text);
  std::string line;
  int keys = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == '[') continue;
    ++keys;
    const auto eq = line.find(" = "), hash = line.find(" # ");
    ASSERT_NE(eq, std::string::npos) << line;
    ASSERT_NE(hash, std::string::npos) << "no comment: " << line;
    EXPECT_GT(line.size(), hash + 6) << "empty comment: " << line;
    const std::string key = line.substr(0, eq), comment = line.substr(hash);
    for (const auto& [suffix, unit] : unit_of)
      if (key.size() > suffix.size() &&
          key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0) {
        EXPECT_THAT(comment, HasSubstr(unit)) << key;
        break;
      }
  }
  EXPECT_GT(keys, 40);
}

// check warns when Δt is above the scheme's measured stability limit (0.22 ns explicit, 20× that
// implicit, at the reference grid; ∝ c² with the kernel width c), naming the key, value and limit.
TEST(Config, CheckWarnsOfATimeStepAboveTheMeasuredStabilityLimit) {
  const auto dt_warning = [](const std::vector<std::string>& sets) {
    config::Config c;
    for (const auto& s : sets) config::apply_override(c, s);
    for (const std::string& w : config::check_warnings(c))
      if (w.find("time.dt_ns") != std::string::npos) return w;
    return std::string();
  };
  EXPECT_EQ(dt_warning({}), "");  // the reference, 0.1 ns
  EXPECT_EQ(dt_warning({"time.dt_ns=0.22"}), "");
  const std::string w = dt_warning({"time.dt_ns=0.3"});
  EXPECT_THAT(w, HasSubstr("time.dt_ns = 0.3 ns exceeds 0.22 ns")) << w;
  EXPECT_THAT(w, HasSubstr("explicit"));
  EXPECT_THAT(w, HasSubstr("time.scheme = \"implicit\""));
  EXPECT_EQ(dt_warning({"time.scheme=implicit", "time.dt_ns=4.4"}), "");
  EXPECT_THAT(dt_warning({"time.scheme=implicit", "time.dt_ns=6"}),
              HasSubstr("time.dt_ns = 6 ns exceeds 4.4 ns"));
  // a coarser grid (c = 725/32 Å, twice the reference): measured stable at 0.9 ns, not at 1.3
  EXPECT_EQ(dt_warning({"grid.n=32", "time.dt_ns=0.85"}), "");
  EXPECT_THAT(dt_warning({"grid.n=32", "time.dt_ns=1.3"}), HasSubstr("exceeds 0.88 ns"));
  // a kernel twice as wide on the reference grid is the same c
  EXPECT_EQ(dt_warning({"grid.kernel_width=2", "time.dt_ns=0.85"}), "");
}

TEST(Config, ABareWordInSetIsAStringAndAWrongTypeStillNamesTheKey) {
  config::Config c;
  config::apply_override(c, "time.scheme=implicit");
  EXPECT_EQ(c.time_scheme, "implicit");
  try {
    config::apply_override(c, "grid.n=sixteen");
    FAIL() << "grid.n=sixteen accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("grid.n"), std::string::npos) << e.what();
  }
}

// check warns of the two measured rules of a thermal run (docs/thermal.md, "Which suspect it
// was"): the drift left out (solvent.thermal_drift = false), and a step above a quarter of the
// explicit limit (the stiff modes hot by O(Δt)); neither without solvent.thermal.
TEST(Config, CheckWarnsOfAThermalRunWithoutTheDriftOrWithTooLargeAStep) {
  const auto warning = [](const std::vector<std::string>& sets, const std::string& key) {
    config::Config c;
    for (const auto& s : sets) config::apply_override(c, s);
    for (const std::string& w : config::check_warnings(c))
      if (w.find(key) != std::string::npos) return w;
    return std::string();
  };
  // the thermal ring of docs/thermal.md: 16³, 200 Å box, explicit limit 0.22 (12.5/(725/64))² ns
  const std::vector<std::string> ring{"grid.n=16", "grid.box_A=200", "rod.base_pairs=100",
                                      "solvent.thermal=true"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> v = ring;
    v.insert(v.end(), extra.begin(), extra.end());
    return v;
  };
  EXPECT_EQ(warning(with({"time.dt_ns=0.05"}), "thermal_drift"), "");
  const std::string d = warning(with({"time.dt_ns=0.05", "solvent.thermal_drift=false"}),
                                "solvent.thermal_drift = false");
  EXPECT_THAT(d, HasSubstr("biased")) << d;
  EXPECT_THAT(d, HasSubstr("set solvent.thermal_drift = true")) << d;
  EXPECT_EQ(warning({"solvent.thermal_drift=false"}, "thermal_drift"), "");  // no noise, no drift
  const double limit = 0.22 * std::pow(12.5 / (725.0 / 64), 2);              // 0.268 ns
  EXPECT_EQ(warning(with({"time.dt_ns=0.05"}), "quarter"), "");              // 0.19 of the limit
  const std::string s = warning(with({"time.dt_ns=0.1"}), "quarter");        // 0.37 of the limit
  EXPECT_THAT(s, HasSubstr("time.dt_ns = 0.1 ns is more than a quarter")) << s;
  EXPECT_THAT(s, HasSubstr("use time.dt_ns <= 0.066 ns")) << s;
  EXPECT_NEAR(0.25 * limit, 0.067, 0.001);
  EXPECT_EQ(warning({"grid.n=16", "grid.box_A=200", "time.dt_ns=0.1"}, "quarter"), "");
}
