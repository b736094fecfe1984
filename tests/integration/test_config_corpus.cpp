// A corpus of malformed configurations: each one makes `ibrod run` exit with status 2 and a
// message that names the problem (the key, or the TOML syntax error), writes no output, and does
// not crash (the asan preset runs this under AddressSanitizer + UBSan).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "run_helpers.hpp"

using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

struct Case {
  const char* toml;
  const char* names;  ///< a substring the error message must contain
};

const Case kCorpus[] = {
    // broken TOML
    {"[grid\nn = 16\n", "TOML syntax error"},
    {"[grid]\nn = \n", "TOML syntax error"},
    {"[grid]\nn = 16\nn = 32\n", "TOML syntax error"},
    {"grid.n == 16\n", "TOML syntax error"},
    {"[grid]\nbox_A = 200 Å\n", "TOML syntax error"},
    {"[time]\ndt_ns = 0.1ns\n", "TOML syntax error"},
    {"[rod]\nperturbation = [1.0, \n", "TOML syntax error"},
    {"[grid]\nn = \"16\n", "TOML syntax error"},
    {"[grid]\nn = 1_6_\n", "TOML syntax error"},
    {"[grid]\n[grid]\n", "TOML syntax error"},
    {"[output]\nevery_steps = 99999999999999999999\n", "TOML syntax error"},
    {"[grid]\nn = 0x\n", "TOML syntax error"},
    // not a section, unknown sections and keys (a unit missing from the name counts)
    {"[[grid]]\nn = 16\n", "'grid' must be a section"},
    {"n = 16\n", "'n' must be a section"},
    {"[grid]\nnn = 3\n", "grid.nn"},
    {"[gird]\nn = 16\n", "gird.n"},
    {"[time]\ndt = 0.1\n", "time.dt"},
    {"[rod]\nbasepairs = 600\n", "rod.basepairs"},
    {"[output]\nframe_every = 10\n", "output.frame_every"},
    {"[grid.sub]\nx = 1\n", "grid.sub"},
    {"[solvent]\nsalt_mM = 100\n", "solvent.salt_mM"},
    {"[grid]\n\"\" = 1\n", "unknown key 'grid.'"},
    // wrong types
    {"[grid]\nn = 16.5\n", "grid.n"},
    {"[grid]\nn = \"sixteen\"\n", "grid.n"},
    {"[grid]\nn = true\n", "grid.n"},
    {"[grid]\nbox_A = \"200\"\n", "grid.box_A"},
    {"[grid]\nbox_A = [200]\n", "grid.box_A"},
    {"[time]\ndt_ns = \"fast\"\n", "time.dt_ns"},
    {"[time]\nt_end_us = 1979-05-27\n", "time.t_end_us"},
    {"[solvent]\nadvection = 1\n", "solvent.advection"},
    {"[steric]\nenabled = \"yes\"\n", "steric.enabled"},
    {"[rod]\nperturbation = 1.0\n", "rod.perturbation"},
    {"[rod]\nperturbation = [\"a\"]\n", "rod.perturbation"},
    {"[rod]\nexcess_link = 2.5\n", "rod.excess_link"},
    {"[output]\nevery_steps = 10.5\n", "output.every_steps"},
    {"[output]\nfluid_vti = \"false\"\n", "output.fluid_vti"},
    {"[run]\nthreads = 1.5\n", "run.threads"},
    {"[run]\nfftw_measure = {}\n", "run.fftw_measure"},
    // out of range
    {"[grid]\nn = 15\n", "grid.n"},
    {"[grid]\nn = 4\n", "grid.n"},
    {"[grid]\nn = 100000\n", "grid.n"},
    {"[grid]\nn = 9223372036854775807\n", "grid.n"},
    {"[grid]\nbox_A = -200\n", "grid.box_A"},
    {"[grid]\nbox_A = 0\n", "grid.box_A"},
    {"[grid]\nbox_A = nan\n", "grid.box_A"},
    {"[grid]\nbox_A = inf\n", "grid.box_A"},
    {"[grid]\nkernel_width = 0\n", "grid.kernel_width"},
    {"[grid]\nn = 16\nkernel_width = 4\n", "grid.kernel_width"},
    {"[time]\ndt_ns = 0\n", "time.dt_ns"},
    {"[time]\ndt_ns = -0.1\n", "time.dt_ns"},
    {"[time]\nt_end_us = 0.00001\n", "time.t_end_us"},
    {"[time]\nstop_kinetic_kT = -1\n", "time.stop_kinetic_kT"},
    {"[rod]\nbase_pairs = 0\n", "rod.base_pairs"},
    {"[rod]\nbase_pairs = -3\n", "rod.base_pairs"},
    {"[rod]\nbase_pairs = 5000\n", "grid.box_A"},
    {"[rod]\nrise_A = 0\n", "rod.rise_A"},
    {"[rod]\nexcess_link = 100000\n", "rod.excess_link"},
    {"[rod]\nbase_pairs = 20\nexcess_link = 4\n", "rod.excess_link"},  // no twisted circle
    {"[rod]\nbend_modulus_erg_cm = -1e-19\n", "rod.bend_modulus_erg_cm"},
    {"[rod]\nperturbation = [1000.0]\n", "rod.perturbation"},
    {"[solvent]\nsalt_M = -0.1\n", "solvent.salt_M"},
    {"[solvent]\nviscosity_poise = 0\n", "solvent.viscosity_poise"},
    {"[solvent]\ntemperature_K = -300\n", "solvent.temperature_K"},
    {"[solvent]\ntemperature_K = 0\n", "solvent.temperature_K"},
    {"[electrostatics]\ndielectric = 0\n", "electrostatics.dielectric"},
    {"[electrostatics]\ncharge_e = -0.48\n", "electrostatics.charge_e"},
    {"[steric]\ndiameter_A = 0\n", "steric.diameter_A"},
    {"[steric]\nstiffness = -5\n", "steric.stiffness"},
    {"[output]\nevery_steps = 0\n", "output.every_steps"},
    {"[output]\nframe_every_steps = -2\n", "output.frame_every_steps"},
    {"[output]\ncheckpoint_every_steps = -1\n", "output.checkpoint_every_steps"},
    {"[run]\nthreads = -1\n", "run.threads"},
    {"[run]\nthreads = 100000\n", "run.threads"},
    // plausible unit mix-ups: metres for Å, mM for M
    {"[grid]\nbox_A = 7.25e-8\n", "grid.box_A"},
    {"[solvent]\nsalt_M = 100\n", "solvent.salt_M"},
};

}  // namespace

TEST(ConfigCorpus, EveryMalformedConfigExitsWithAMessageNamingTheProblem) {
  static_assert(std::size(kCorpus) >= 50);
  const fs::path d = fresh_dir("corpus");
  int i = 0;
  for (const Case& c : kCorpus) {
    const fs::path f = d / ("bad" + std::to_string(i++) + ".toml");
    std::ofstream(f) << c.toml;
    const fs::path out = d / ("out" + std::to_string(i));
    const Exit e = run_ibrod({"run", f.string(), "-o", out.string()}, d / "log");
    EXPECT_EQ(e.code, 2) << c.toml << "\n" << e.output;
    EXPECT_THAT(e.output, HasSubstr("ibrod: error: ")) << c.toml;
    EXPECT_THAT(e.output, HasSubstr(c.names)) << c.toml;
    // no sanitizer report, no crash, no output written
    EXPECT_THAT(e.output, ::testing::Not(HasSubstr("Sanitizer"))) << c.toml;
    EXPECT_THAT(e.output, ::testing::Not(HasSubstr("runtime error"))) << c.toml;
    EXPECT_FALSE(fs::exists(out / "timeseries.csv")) << c.toml;
  }
  fs::remove_all(d);
}

TEST(ConfigCorpus, BadCommandLinesExitWithStatus2) {
  const fs::path d = fresh_dir("cli");
  const std::vector<std::vector<std::string>> cases = {
      {"run", "--set", "grid.n"},                        // no value
      {"run", "--set", "grid.n=abc"},                    // not TOML
      {"run", "--set", "nosuch.key=1"},                  // unknown key
      {"run", (d / "missing.toml").string()},            // no such file
      {"run", "--resume", d.string(), "-o", "x"},        // --resume takes its own directory
      {"run", "--force"},                                // --force needs --resume
      {"run", "--resume", (d / "nothing").string()},     // no run there
      {"run", "--fftw-wisdom", (d / "none").string(), "-o", (d / "o").string()},
      {"frobnicate"},
  };
  for (const auto& args : cases) {
    const Exit e = run_ibrod(args, d / "log");
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    EXPECT_EQ(e.code, 2) << joined << "\n" << e.output;
    EXPECT_FALSE(e.output.empty()) << joined;
  }
  fs::remove_all(d);
}
