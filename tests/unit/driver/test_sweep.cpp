// Sweep files (driver/sweep_file.hpp): the product of lists, stable point names, base configs, and
// every kind of bad sweep file is a ConfigError naming the key.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "config/config.hpp"
#include "core/error.hpp"
#include "driver/sweep_runner.hpp"

using namespace ibrod;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

const char* kTiny =
    "[grid]\nn = 16\nbox_A = 200.0\n[rod]\nbase_pairs = 100\n[time]\nt_end_us = 0.02\n"
    "[run]\nfftw_measure = false\n";

driver::Sweep parse(const std::string& text, const fs::path& dir = fs::temp_directory_path()) {
  return driver::parse_sweep(text, "test.toml", dir);
}

std::string error_of(const std::string& text, const fs::path& dir = fs::temp_directory_path()) {
  try {
    parse(text, dir);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Sweep, IsTheProductWithTheFirstKeySlowestAndStableNames) {
  const auto sw = parse(std::string(kTiny) +
                        "[sweep]\n\"rod.excess_link\" = [1, 2, 3]\nsolvent.salt_M = [0.01, 0.1]\n");
  ASSERT_EQ(sw.axes.size(), 2u);
  ASSERT_EQ(sw.points.size(), 6u);
  const char* names[] = {"dlk=1_salt_M=0.01", "dlk=1_salt_M=0.1",  "dlk=2_salt_M=0.01",
                         "dlk=2_salt_M=0.1",  "dlk=3_salt_M=0.01", "dlk=3_salt_M=0.1"};
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(sw.points[i].name, names[i]);
    EXPECT_EQ(sw.points[i].index, std::size_t(i));
  }
  EXPECT_EQ(sw.points[3].config.rod_excess_link, 2);
  EXPECT_EQ(sw.points[3].config.solvent_salt_M, 0.1);
  EXPECT_EQ(sw.points[3].config.grid_n, 16);  // the file's own sections are the base
  // the same file gives the same names (stable across runs); points.csv lists them
  EXPECT_EQ(parse(std::string(kTiny) + "[sweep]\n\"rod.excess_link\" = [1, 2, 3]\n"
                                       "solvent.salt_M = [0.01, 0.1]\n")
                .points[5]
                .name,
            "dlk=3_salt_M=0.1");
  EXPECT_THAT(driver::points_csv(sw), HasSubstr("index,name,rod.excess_link,solvent.salt_M\n"
                                                "0,dlk=1_salt_M=0.01,1,0.01\n"));
}

TEST(Sweep, NamesAreSanitisedShortenedAndRenamable) {
  EXPECT_EQ(driver::sanitize_name("a/b c*d"), "a-b-c-d");
  EXPECT_EQ(driver::sanitize_name("..x"), "_..x");
  EXPECT_EQ(driver::sanitize_name(""), "_");
  const std::string longer(300, 'x');
  EXPECT_EQ(driver::sanitize_name(longer).size(), 197u);
  EXPECT_EQ(driver::sanitize_name(longer), driver::sanitize_name(longer));
  EXPECT_NE(driver::sanitize_name(longer), driver::sanitize_name(longer + "y"));

  const auto sw = parse(std::string(kTiny) +
                        "[names]\n\"solvent.salt_M\" = \"cs\"\n"
                        "[sweep]\nsolvent.salt_M = [1e-5]\n\"rod.perturbation\" = [[1.0, 0.5]]\n"
                        "\"rod.perturbation_random.seed\" = [7]\n");
  EXPECT_EQ(sw.points.at(0).name, "cs=1e-05_perturbation=1,0.5_seed=7");
  EXPECT_EQ(sw.points[0].config.rod_perturbation_random.seed, 7u);
  EXPECT_EQ(sw.points[0].config.rod_perturbation, (std::vector<double>{1.0, 0.5}));
}

TEST(Sweep, ABaseFileIsReadRelativeToTheSweepFileAndOverridden) {
  const fs::path dir = fs::temp_directory_path() / "ibrod_test_sweep_base";
  fs::create_directories(dir);
  std::ofstream(dir / "base.toml") << kTiny << "[solvent]\nsalt_M = 0.05\n";
  const auto sw = parse(
      "base = \"base.toml\"\n[time]\nt_end_us = 0.03\n"
      "[sweep]\nrod.excess_link = [4]\n",
      dir);
  ASSERT_EQ(sw.points.size(), 1u);
  EXPECT_EQ(sw.points[0].config.solvent_salt_M, 0.05);
  EXPECT_EQ(sw.points[0].config.time_t_end_us, 0.03);
  EXPECT_EQ(sw.points[0].config.grid_n, 16);
  EXPECT_THAT(error_of("base = \"missing.toml\"\n[sweep]\nrod.excess_link = [4]\n", dir),
              HasSubstr("base = \"missing.toml\""));
  fs::remove_all(dir);
}

TEST(Sweep, BadSweepFilesAreRejectedNamingTheKey) {
  const std::string t = kTiny;
  EXPECT_THAT(error_of(t + "[sweep]\nrod.excess_lnk = [1, 2]\n"),
              HasSubstr("unknown key 'rod.excess_lnk'"));
  EXPECT_THAT(error_of(t + "[sweep]\n\"rod.excess_link\" = 3\n"),
              HasSubstr("[sweep] rod.excess_link = 3 is invalid: expected a list"));
  EXPECT_THAT(error_of(t + "[sweep]\n\"rod.excess_link\" = []\n"),
              HasSubstr("[sweep] rod.excess_link is an empty list"));
  EXPECT_THAT(error_of(t + "[sweep]\nsolvent.salt_M = [0.1, -1.0]\n"),
              HasSubstr("[sweep] solvent.salt_M = -1.0"));
  EXPECT_THAT(error_of(t + "[sweep]\nsolvent.salt_M = [0.1, -1.0]\n"),
              HasSubstr("is invalid: expected a number >= 0"));
  EXPECT_THAT(error_of(t + "[sweep]\nrod.excess_link = [1, 1]\n"), HasSubstr("same name 'dlk=1'"));
  EXPECT_THAT(error_of(t), HasSubstr("no [sweep] table"));
  EXPECT_THAT(error_of("jobs = 3\n" + t + "[sweep]\nrod.excess_link = [1]\n"),
              HasSubstr("unknown top-level key 'jobs'"));
  EXPECT_THAT(error_of(t + "[names]\n\"rod.x\" = \"x\"\n[sweep]\nrod.excess_link = [1]\n"),
              HasSubstr("[names] \"rod.x\""));
  EXPECT_THAT(error_of(t + "[sweep]\nrod.excess_link = [1\n"), HasSubstr("TOML syntax error"));
  // a cross-key check fails for one point: named by the point
  EXPECT_THAT(error_of(t + "[sweep]\nrod.base_pairs = [100, 400]\n"),
              HasSubstr("point base_pairs=400: config: grid.box_A"));
  // a bad key in the base sections
  EXPECT_THAT(error_of(t + "[steric]\nfoo = 1\n[sweep]\nrod.excess_link = [1]\n"),
              HasSubstr("unknown key 'steric.foo'"));
}

// T3-7 (issue 26): docs/config.md says a sweep can vary rods.K.key like any key; it could not
// ("'rods' is a value"). K from 0, K = the number of tables appends one, as --set.
TEST(Sweep, AKeyOfARodsTableIsSweptLikeAnyKey) {
  const std::string rods = "[[rods]]\nexcess_link = 0\n[[rods]]\noffset_A = [0, 0, 60]\n";
  const auto sw = parse(std::string(kTiny) + rods +
                        "[sweep]\n\"rods.1.excess_link\" = [0, 1]\n\"rods.2.offset_A\" = "
                        "[[0, 0, -60]]\n");
  ASSERT_EQ(sw.points.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const config::Config& c = sw.points[i].config;
    ASSERT_EQ(config::rod_configs(c).size(), 3u);
    EXPECT_EQ(config::rod_config(c, 0).rod_excess_link, 0);
    EXPECT_EQ(config::rod_config(c, 1).rod_excess_link, int(i));
    EXPECT_EQ(config::rod_config(c, 1).rod_offset_A[2], 60.0);
    EXPECT_EQ(config::rod_config(c, 2).rod_offset_A[2], -60.0);
  }
  EXPECT_EQ(sw.points[1].name, "excess_link=1_offset_A=0,0,-60");
  // a table number past the end, or a bad value, names the key
  EXPECT_THAT(error_of(std::string(kTiny) + rods + "[sweep]\n\"rods.5.excess_link\" = [1]\n"),
              HasSubstr("rods.5.excess_link"));
  EXPECT_THAT(error_of(std::string(kTiny) + rods + "[sweep]\n\"rods.1.excess_link\" = [1.5]\n"),
              HasSubstr("rods.1.excess_link"));
}

TEST(Sweep, PointStatesFollowTheRunFiles) {
  const fs::path d = fs::temp_directory_path() / "ibrod_test_sweep_state";
  fs::remove_all(d);
  EXPECT_EQ(driver::point_state(d), driver::PointState::fresh);
  fs::create_directories(d);
  EXPECT_EQ(driver::point_state(d), driver::PointState::fresh);
  std::ofstream(d / "config.toml") << "x";
  EXPECT_EQ(driver::point_state(d), driver::PointState::no_checkpoint);
  std::ofstream(d / "checkpoint.bin") << "x";
  EXPECT_EQ(driver::point_state(d), driver::PointState::interrupted);
  std::ofstream(d / "summary.json") << "{\"stop_reason\": \"interrupted\"}";
  EXPECT_EQ(driver::point_state(d), driver::PointState::interrupted);
  std::ofstream(d / "summary.json") << "{\"stop_reason\": \"end_time\"}";
  EXPECT_EQ(driver::point_state(d), driver::PointState::finished);
  std::ofstream(d / "summary.json") << "{\"stop_reason\": \"equilibrium\"}";
  EXPECT_EQ(driver::point_state(d), driver::PointState::finished);
  std::ofstream(d / "summary.json") << "{\"stop_reason\": \"blow_up\"}";
  EXPECT_EQ(driver::point_state(d), driver::PointState::failed);
  fs::remove_all(d);
}

TEST(Sweep, TheReferenceExampleIsTheEighteenReferenceRuns) {
  const auto sw =
      driver::load_sweep(fs::path(IBROD_SOURCE_DIR) / "examples" / "sweep_reference.toml");
  ASSERT_EQ(sw.points.size(), 18u);
  // each point's config equals examples/reference/dlkN_csC.toml
  for (const auto& pt : sw.points) {
    char name[64];
    std::snprintf(name, sizeof name, "dlk%d_cs%g.toml", pt.config.rod_excess_link,
                  pt.config.solvent_salt_M);
    const auto ref = config::load_config(
        (fs::path(IBROD_SOURCE_DIR) / "examples" / "reference" / name).string());
    EXPECT_EQ(config::to_toml(pt.config), config::to_toml(ref)) << pt.name;
  }
}

// examples/sweep_perturbations.toml and docs/example_report/sampling/sweep.toml sample random
// perturbations at one (ΔLk, Cs): their points differ only in the seed (what `ibrod report`
// groups as a sampling, python/ibrod_study.py).
TEST(Sweep, TheSamplingExamplesDifferOnlyInTheSeed) {
  for (const fs::path& f : {fs::path("examples") / "sweep_perturbations.toml",
                            fs::path("docs") / "example_report" / "sampling" / "sweep.toml"}) {
    const auto sw = driver::load_sweep(fs::path(IBROD_SOURCE_DIR) / f);
    ASSERT_GE(sw.points.size(), 6u) << f;
    std::set<std::uint64_t> seeds;
    config::Config first = sw.points.front().config;
    first.rod_perturbation_random.seed = 0;
    for (const auto& pt : sw.points) {
      EXPECT_GT(pt.config.rod_perturbation_random.modes, 0) << f;
      EXPECT_GT(pt.config.rod_perturbation_random.amplitude, 0) << f;
      EXPECT_TRUE(pt.config.rod_perturbation.empty()) << f;
      EXPECT_EQ(pt.config.time_scheme, "implicit") << f;
      seeds.insert(pt.config.rod_perturbation_random.seed);
      config::Config c = pt.config;
      c.rod_perturbation_random.seed = 0;
      EXPECT_EQ(config::to_toml(c), config::to_toml(first)) << f << " " << pt.name;
    }
    EXPECT_EQ(seeds.size(), sw.points.size()) << f;
  }
}

// examples/sweep_circle_stability.toml: the unperturbed circle over ΔLk at low salt, with the
// stability test on (the report's verdict comes from it).
TEST(Sweep, TheCircleStabilityExampleIsTheUnperturbedCircleAtLowSalt) {
  const auto sw =
      driver::load_sweep(fs::path(IBROD_SOURCE_DIR) / "examples" / "sweep_circle_stability.toml");
  std::set<int> dlks;
  for (const auto& pt : sw.points) {
    EXPECT_TRUE(pt.config.rod_perturbation.empty()) << pt.name;
    EXPECT_EQ(pt.config.rod_perturbation_random.modes, 0) << pt.name;
    EXPECT_TRUE(pt.config.time_stability_test) << pt.name;
    EXPECT_LE(pt.config.solvent_salt_M, 0.01) << pt.name;
    dlks.insert(pt.config.rod_excess_link);
  }
  EXPECT_GE(dlks.size(), 3u);
}
