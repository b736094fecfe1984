// End to end: the real `ibrod` binary on generated configs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "helpers.hpp"

namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace {

struct Result {
  int status;
  std::string output;
};

Result sh(const std::string& args) {
  const std::string cmd = std::string(IBROD_BINARY) + " " + args + " 2>&1";
  std::FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("ibrod_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string small_config_toml() {
  ibrod::config::Config c = ibrod::test::small_config(2);
  c.time_t_end_us = 0.05;
  return ibrod::test::small_config_toml(c);
}

}  // namespace

TEST(Cli, RunWritesEveryOutputFile) {
  const fs::path d = fresh_dir("run");
  std::ofstream(d / "in.toml") << small_config_toml();
  const auto r = sh("run " + (d / "in.toml").string() + " -o " + (d / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("ms/step"));
  EXPECT_THAT(r.output, HasSubstr("ETA"));
  // a line before the first step, with the initial state's values (Lk = ΔLk = 2, Wr = 0), then
  // one at the first output step (step 100) with the measured ms/step
  const auto first = r.output.find("step 0/500  t = 0.0000 us  Wr = +0.0000  Lk = +2.0000");
  EXPECT_NE(first, std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(starting)", first), std::string::npos) << r.output;
  const auto at100 = r.output.find("step 100/500");
  EXPECT_NE(at100, std::string::npos) << r.output;
  EXPECT_LT(first, at100);
  EXPECT_NE(r.output.find("ms/step", at100), std::string::npos) << r.output;
  const fs::path out = d / "out";
  // config.toml is the resolved config: every key, including defaults, with our overrides
  const std::string cfg = read_file(out / "config.toml");
  EXPECT_THAT(cfg, HasSubstr("base_pairs = 100"));
  EXPECT_THAT(cfg, HasSubstr("twist_modulus_erg_cm"));
  // timeseries: header and one row per output step (0, 100, 200, 300, 400, 500)
  std::ifstream ts(out / "timeseries.csv");
  std::string line;
  std::getline(ts, line);
  EXPECT_EQ(line.rfind("step,time_us,E_bend_kT,E_twist_kT,E_stretch_kT,E_electro_kT,", 0), 0u);
  for (const char* col : {"E_steric_kT", "E_kinetic_kT", "E_total_kT", "writhe", "twist", "link",
                          "closest_approach_A", "bp_spacing_A"})
    EXPECT_THAT(line, HasSubstr(col));
  int rows = 0;
  while (std::getline(ts, line)) ++rows;
  EXPECT_EQ(rows, 6);
  // final state: header + 100 rows of 12 numbers
  std::ifstream fsn(out / "final_state.csv");
  std::getline(fsn, line);
  EXPECT_EQ(line, "x_A,y_A,z_A,d1x,d1y,d1z,d2x,d2y,d2z,d3x,d3y,d3z");
  rows = 0;
  while (std::getline(fsn, line)) {
    ++rows;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 11);
  }
  EXPECT_EQ(rows, 100);
  const std::string summary = read_file(out / "summary.json");
  for (const char* kv : {R"("steps"\s*:\s*500)", R"("stop_reason"\s*:\s*"end_time")",
                         R"("wall_time_s"\s*:\s*[0-9.e+-]+)", R"("ms_per_step"\s*:\s*[0-9.e+-]+)",
                         R"("link"\s*:\s*2\.0000)", R"("link_drift"\s*:)"})
    EXPECT_TRUE(std::regex_search(summary, std::regex(kv))) << kv << "\n" << summary;
  fs::remove_all(d);
}

TEST(Cli, ExistingOutputIsNotOverwrittenWithoutTheFlag) {
  const fs::path d = fresh_dir("overwrite");
  std::ofstream(d / "in.toml") << small_config_toml();
  fs::create_directories(d / "out");
  std::ofstream(d / "out" / "precious.txt") << "keep me";
  auto r = sh("run " + (d / "in.toml").string() + " -o " + (d / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("--overwrite"));
  EXPECT_EQ(read_file(d / "out" / "precious.txt"), "keep me");
  fs::remove_all(d);
}

TEST(Cli, BadConfigsExitNonZeroNamingTheKey) {
  const fs::path d = fresh_dir("bad");
  const std::pair<std::string, std::string> cases[] = {
      {"[grid]\nnn = 3\n", "grid.nn"},
      {"[grid]\nkernel_width = 1.5\n", "grid.kernel_width"},
      {"[solvent]\nviscosity_poise = -0.01\n", "solvent.viscosity_poise"},
      {"[rod]\nexcess_link = 2.5\n", "rod.excess_link"},
      {"[rod]\nbase_pairs = 0\n", "rod.base_pairs"},
      {"[rod]\nbase_pairs = -3\n", "rod.base_pairs"},
      {"[time]\ndt_ns = \"fast\"\n", "time.dt_ns"},
      {"[grid\nn = 3\n", "TOML"},
  };
  int i = 0;
  for (const auto& [text, key] : cases) {
    const fs::path f = d / ("bad" + std::to_string(i++) + ".toml");
    std::ofstream(f) << text;
    const auto r = sh("run " + f.string() + " -o " + (d / "out").string());
    EXPECT_EQ(r.status, 2) << text << r.output;
    EXPECT_THAT(r.output, HasSubstr(key)) << text;
    EXPECT_FALSE(fs::exists(d / "out" / "timeseries.csv"));
  }
  const auto r = sh("check --set grid.n=abc");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.output, HasSubstr("grid.n"));
  EXPECT_EQ(sh("run " + (d / "missing.toml").string()).status, 2);
  fs::remove_all(d);
}

TEST(Cli, CheckPrintsDerivedQuantities) {
  const auto r = sh("check --set solvent.salt_M=0.1");
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* s : {"grid.n = 64", "Debye length 1/κ          = 9.6", "Bjerrum length",
                        "time steps", "memory estimate", "ring radius r0            = 324.68"})
    EXPECT_THAT(r.output, HasSubstr(s));
}

TEST(Cli, VersionNamesTheVersionCommitBuildAndMpi) {
  const Result r = sh("--version");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(std::regex_search(
      r.output, std::regex(R"(^ibrod \d+\.\d+\.\d+ \(git \w+, \w+ build, MPI (yes|no)\))")))
      << r.output;
}

TEST(Cli, CheckWarnsOfAGridCoarserThanTheHardCoreAndAnUndersizedBox) {
  const Result coarse = sh("check --set grid.n=16");  // h = 725/16 = 45 Å > D = 20 Å
  EXPECT_EQ(coarse.status, 0) << coarse.output;
  EXPECT_THAT(coarse.output, HasSubstr("warning: the grid spacing h = 45.3125 Å"));
  const Result small_box =
      sh("check --set solvent.salt_M=0.001");  // 1/κ ≈ 96 Å: 3/κ > 725 − 649 − 20
  EXPECT_EQ(small_box.status, 0) << small_box.output;
  EXPECT_THAT(small_box.output, HasSubstr("periodic images"));
  const Result fine = sh("check");  // the reference: no warning
  EXPECT_EQ(fine.status, 0);
  EXPECT_THAT(fine.output, ::testing::Not(HasSubstr("warning")));
}
