// A corpus of malformed inputs to `ibrod run`: each one makes it exit with status 2 and a
// message that names the problem (the key, the TOML syntax error, or why CONFIG cannot be read),
// within a time limit, without a crash and without writing output (the asan preset runs this
// under AddressSanitizer + UBSan). The test prints the table issue 13 asks for:
//   inputs tried / clean errors naming the key / crashes / hangs / accepted nonsense
// and fails on any crash, hang, accepted input or error that does not name its key.
#include <sys/stat.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>

#include "bounded_run.hpp"

using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

std::string repeat(const std::string& s, int k) {
  std::string out;
  for (int i = 0; i < k; ++i) out += s;
  return out;
}

struct Case {
  std::string toml;
  std::string names;  ///< a substring the error message must contain
};

const std::vector<Case> kHandWritten = {
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
    // issue 13 item 5: derived counts (steps, rows, frames) that overflow or are absurd
    {"[time]\nt_end_us = 1e308\n", "time.t_end_us"},
    {"[time]\ndt_ns = 1e-308\n", "time.dt_ns"},
    {"[time]\ndt_ns = 1e7\n", "time.dt_ns"},
    {"[time]\ndt_ns = 1e-7\n", "time.dt_ns"},
    {"[time]\ndt_ns = 1e-6\nt_end_us = 1e12\n", "time.t_end_us"},
    {"[time]\ndt_ns = 0.001\nt_end_us = 1e10\n", "time.t_end_us"},
    {"[time]\nt_end_us = 1e8\n[output]\nframe_every_steps = 1\n", "output.frame_every_steps"},
    {"[time]\nt_end_us = 1e6\n[output]\nevery_steps = 1\nframe_every_steps = 1\n",
     "output.frame_every_steps"},
    {"[time]\nt_end_us = 1e7\n[output]\nfluid_vti = true\nevery_steps = 10\n",
     "output.frame_every_steps"},
    {"[output]\nevery_steps = 1e30\n", "output.every_steps"},
    {"[output]\ncheckpoint_every_steps = -9223372036854775808\n", "output.checkpoint_every_steps"},
    // item 6: a link the discretization cannot represent (twist per segment past π/2)
    {"[rod]\nexcess_link = 500\nshear_modulus_dyn = 5e-4\n", "rod.excess_link"},
    {"[rod]\nexcess_link = 151\n", "rod.excess_link"},
    {"[rod]\nexcess_link = -151\n", "rod.excess_link"},
    {"[rod]\nbase_pairs = 100\nexcess_link = 26\n", "rod.excess_link"},
    {"[rod]\nbase_pairs = 8\nexcess_link = 3\n", "rod.excess_link"},
    {"[rod]\nintrinsic_twist_per_A = 0.5\n", "rod.intrinsic_twist_per_A"},
    {"[rod]\nintrinsic_twist_per_A = -1e308\n", "rod.intrinsic_twist_per_A"},
    {"[grid]\nbox_A = 5000\n[rod]\nrise_A = 10\nintrinsic_twist_per_A = 0.2\n",
     "rod.intrinsic_twist_per_A"},
    // item 8: values that passed `check` and blew up at step 0
    {"[grid]\nbox_A = 1e308\n", "grid.box_A"},
    {"[grid]\nbox_A = 1e11\n", "grid.box_A"},
    {"[rod]\nbend_modulus_erg_cm = 1e308\n", "rod.bend_modulus_erg_cm"},
    {"[rod]\nbend_modulus_erg_cm = 1e-300\n", "rod.bend_modulus_erg_cm"},
    {"[rod]\ntwist_modulus_erg_cm = 1e308\n", "rod.twist_modulus_erg_cm"},
    {"[rod]\nshear_modulus_dyn = 1e-300\n", "rod.shear_modulus_dyn"},
    {"[rod]\nstretch_modulus_dyn = 1e300\n", "rod.stretch_modulus_dyn"},
    {"[rod]\nrise_A = 1e-300\n", "rod.rise_A"},
    {"[rod]\nrise_A = 1e300\n", "rod.rise_A"},
    {"[electrostatics]\ncharge_e = 1e308\n", "electrostatics.charge_e"},
    {"[electrostatics]\ndielectric = 1e-300\n", "electrostatics.dielectric"},
    {"[electrostatics]\ncutoff_debye = 1e300\n", "electrostatics.cutoff_debye"},
    {"[solvent]\nviscosity_poise = 1e-300\n", "solvent.viscosity_poise"},
    {"[solvent]\ndensity_g_cm3 = 1e300\n", "solvent.density_g_cm3"},
    {"[solvent]\ntemperature_K = 1e-300\n", "solvent.temperature_K"},
    {"[steric]\nstiffness = 1e308\n", "steric.stiffness"},
    {"[time]\nstop_kinetic_kT = 1e300\n", "time.stop_kinetic_kT"},
    // item 9: the key at fault is the one named; huge and odd values are echoed capped
    {"[steric]\ndiameter_A = 100\n", "steric.diameter_A"},
    {"[steric]\ndiameter_A = 1e300\n", "steric.diameter_A"},
    {"[grid]\nbox_A = 600\n", "grid.box_A"},
    {"[grid]\nn = \"" + std::string(1 << 20, '9') + "\"\n", "grid.n"},
    {"[grid]\n" + std::string(1 << 20, 'k') + " = 1\n", "unknown key 'grid.kkk"},
    {"[rod]\nperturbation = [" + repeat("100.5, ", 20000) + "]\n", "rod.perturbation"},
    {"[grid]\nn = \"a\\u0001b\"\n", "grid.n"},
    {"[grid]\nn = \"\\n\"\n", "grid.n"},
    {"[grid.n]\nx = 1\n", "grid.n = x = 1 is invalid"},  // a table where a number belongs
    {"[rod]\nperturbation_random = { modes = 2, colour = 1 }\n", "rod.perturbation_random.colour"},
    {"[rod]\nperturbation_random = 3\n", "rod.perturbation_random"},
    {"[rod]\nperturbation_random = { modes = -1 }\n", "rod.perturbation_random.modes"},
    {"[rod]\nperturbation_random = { amplitude = 1e308 }\n", "rod.perturbation_random.amplitude"},
    {"[rod]\nperturbation_random = { seed = -1 }\n", "rod.perturbation_random.seed"},
    // issue 26 T3-18: 100 000 [[rods]] tables took minutes (quadratic); refused at once
    {"[rod]\nbase_pairs = 8\nexcess_link = 0\n" + repeat("[[rods]]\n", 100000), "at most 1000"},
};

// Every scalar key with values none of them accepts: huge, non-finite, and of the wrong type.
std::vector<Case> generated() {
  const char* numeric[] = {"grid.n",
                           "grid.box_A",
                           "grid.kernel_width",
                           "time.dt_ns",
                           "time.t_end_us",
                           "time.stop_kinetic_kT",
                           "rod.base_pairs",
                           "rod.excess_link",
                           "rod.rise_A",
                           "rod.bend_modulus_erg_cm",
                           "rod.twist_modulus_erg_cm",
                           "rod.shear_modulus_dyn",
                           "rod.stretch_modulus_dyn",
                           "rod.intrinsic_twist_per_A",
                           "solvent.salt_M",
                           "solvent.viscosity_poise",
                           "solvent.density_g_cm3",
                           "solvent.temperature_K",
                           "electrostatics.charge_e",
                           "electrostatics.dielectric",
                           "electrostatics.cutoff_debye",
                           "steric.diameter_A",
                           "steric.stiffness",
                           "output.every_steps",
                           "output.frame_every_steps",
                           "output.checkpoint_every_steps",
                           "run.threads",
                           "time.max_displacement_A",
                           "time.energy_tolerance_kT",
                           "time.dt_min_ns",
                           "time.implicit_mobility_scale",
                           "time.implicit_overlap_scale",
                           "time.implicit_jacobian_every",
                           "time.implicit_krylov_iterations",
                           "time.implicit_krylov_tol",
                           "time.implicit_krylov_error_share"};
  const char* boolean[] = {"solvent.advection", "electrostatics.enabled", "steric.enabled",
                           "output.fluid_vti",  "output.fluid_velocity",  "run.fftw_measure"};
  std::vector<Case> out;
  auto add = [&](const std::string& key, const std::string& value) {
    const auto dot = key.find('.');
    std::string toml = "[";
    toml.append(key, 0, dot).append("]\n").append(key, dot + 1).append(" = ").append(value);
    out.push_back({toml + "\n", key});
  };
  for (const char* k : numeric)
    for (const char* v : {"1e308", "-1e308", "nan", "-inf", "\"1\"", "[1]", "true"}) add(k, v);
  for (const char* k : boolean)
    for (const char* v : {"1", "\"true\"", "[true]"}) add(k, v);
  return out;
}

// How one input ended.
enum class Outcome { clean, unnamed, crash, hang, accepted };

struct Tally {
  int tried = 0, clean = 0, unnamed = 0, crashes = 0, hangs = 0, accepted = 0;
  void add(Outcome o) {
    ++tried;
    (o == Outcome::clean     ? clean
     : o == Outcome::unnamed ? unnamed
     : o == Outcome::crash   ? crashes
     : o == Outcome::hang    ? hangs
                             : accepted)++;
  }
};

// Runs `ibrod args` (with `-o out` for run) and classifies the result; failures are reported
// with `what`.
Outcome classify(const std::vector<std::string>& args, const std::string& names,
                 const fs::path& out, const fs::path& log, const std::string& what,
                 long as_limit = 0) {
  const BoundedExit e = run_bounded(args, log, 20, as_limit);
  const bool started = fs::exists(out / "config.toml") || fs::exists(out / "timeseries.csv");
  Outcome o;
  if (e.hung)
    o = started ? Outcome::accepted : Outcome::hang;
  else if (e.signal != 0 || (e.code != 0 && e.code != 2) ||
           e.output.find("Sanitizer") != std::string::npos ||
           e.output.find("runtime error") != std::string::npos)
    o = Outcome::crash;
  else if (e.code == 0 || started)
    o = Outcome::accepted;
  else if (e.output.find("ibrod: error: ") != std::string::npos &&
           e.output.find(names) != std::string::npos)
    o = Outcome::clean;
  else
    o = Outcome::unnamed;
  EXPECT_EQ(o, Outcome::clean) << what << "\nexit " << e.code << " signal " << e.signal
                               << (e.hung ? " (hung)" : "") << "\n"
                               << e.output.substr(0, 2000);
  // echoed values are capped: a 1 MB value never makes a 1 MB message
  EXPECT_LT(e.output.size(), 4000u) << what.substr(0, 200);
  return o;
}

}  // namespace

TEST(ConfigCorpus, EveryMalformedInputExitsWithAMessageNamingTheProblem) {
  std::vector<Case> corpus = kHandWritten;
  for (Case& c : generated()) corpus.push_back(std::move(c));
  const fs::path d = fresh_dir("corpus");
  Tally t;
  int i = 0;
  for (const Case& c : corpus) {
    const fs::path f = d / ("bad" + std::to_string(i++) + ".toml");
    std::ofstream(f) << c.toml;
    const fs::path out = d / ("out" + std::to_string(i));
    t.add(classify({"run", f.string(), "-o", out.string()}, c.names, out, d / "log",
                   c.toml.substr(0, 300)));
    fs::remove(f);
  }
  // CONFIG that is no readable regular file, and --set values, on the command line
  const fs::path fifo = d / "fifo.toml", dir = d / "dir.toml", ro = d / "ro.toml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  fs::create_directories(dir);
  const long gib = 1L << 30;
  const struct {
    std::vector<std::string> args;
    std::string names;
    long as_limit = 0;
  } cli[] = {
      {{dir.string()}, "it is a directory"},
      {{""}, "the path is empty"},
      {{fifo.string()}, "not a regular file"},
      {{"/dev/null"}, "not a regular file"},
      {{"/dev/zero"}, "not a regular file"},
      {{(d / "missing.toml").string()}, "does not exist"},
      {{(d / "missing" / "x.toml").string()}, "does not exist"},
      {{"--set", "grid.n.x=1"}, "unknown key 'grid.n.x'"},
      {{"--set", "grid.box_A.y=1"}, "unknown key 'grid.box_A.y'"},
      {{"--set", "grid.n=16\nrod.base_pairs=8"}, "control characters"},
      {{"--set", "grid.n=16\n"}, "control characters"},
      {{"--set", "grid.n=\t16"}, "control characters"},
      {{"--set", "grid.n=16\x1b[2J"}, "control characters"},
      {{"--set", "rod.excess_link=6\r"}, "control characters"},
      {{"--set", "grid.n=" + std::string(100000, '1')}, "grid.n"},
      {{"--set", "steric.diameter_A=100"}, "steric.diameter_A = 100 is invalid"},
      {{"--set", "time.t_end_us=1e308"}, "time.t_end_us"},
      {{"--set", "time.dt_ns=1e-308"}, "time.dt_ns"},
      {{"--set", "rod.excess_link=500", "--set", "rod.shear_modulus_dyn=5e-4"}, "rod.excess_link"},
      {{"--set", "rod.intrinsic_twist_per_A=1e308"}, "rod.intrinsic_twist_per_A"},
      {{"--set", "grid.box_A=1e308"}, "grid.box_A"},
      {{"--set", "electrostatics.charge_e=1e308"}, "electrostatics.charge_e"},
      // issue 26 T3-1, T3-2: per-link files that are no regular file, refused before they are
      // opened (a FIFO blocked for ever, /dev/zero filled the memory, a directory read as empty)
      {{"--set", "rod.moduli_file=\"" + fifo.string() + "\""}, "not a regular file"},
      {{"--set", "rod.intrinsic_file=\"" + fifo.string() + "\""}, "not a regular file"},
      {{"--set", "rod.moduli_file=\"/dev/zero\""}, "rod.moduli_file", gib},
      {{"--set", "rod.intrinsic_file=\"/dev/zero\""}, "rod.intrinsic_file", gib},
      {{"--set", "rod.moduli_file=\"" + dir.string() + "\""}, "it is a directory"},
      {{"--set", "rod.intrinsic_file=\"" + dir.string() + "\""}, "it is a directory"},
      // item 7: more memory than this process may allocate, refused before any is
      {{"--set", "grid.n=1024"}, "grid.n = 1024", 4 * gib},
      {{"--set", "grid.n=512"}, "grid.n = 512", 2 * gib},
      {{"--set", "grid.n=8", "--set", "grid.box_A=4e6", "--set", "rod.base_pairs=1000000"},
       "rod.base_pairs",
       gib / 4},
  };
  for (const auto& c : cli) {
    if (c.as_limit > 0 && kAddressSanitizer) continue;  // no RLIMIT_AS under ASan (run_helpers)
    const fs::path out = d / ("cli" + std::to_string(i++));
    std::vector<std::string> args{"run"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    args.insert(args.end(), {"-o", out.string()});
    std::string what;
    for (const auto& a : args) what += a.substr(0, 100) + " ";
    t.add(classify(args, c.names, out, d / "log", what, c.as_limit));
  }
  // an unreadable file: only without root, who reads any file
  if (::geteuid() != 0) {
    std::ofstream(ro) << "[grid]\nn = 16\n";
    fs::permissions(ro, fs::perms::none);
    t.add(classify({"run", ro.string(), "-o", (d / "ro").string()}, "Permission denied", d / "ro",
                   d / "log", "unreadable CONFIG"));
  }
  std::printf(
      "config corpus: %d inputs tried / %d clean errors naming the key / %d crashes / "
      "%d hangs / %d accepted nonsense (%d errors not naming the key)\n",
      t.tried, t.clean, t.crashes, t.hangs, t.accepted, t.unnamed);
  EXPECT_GE(t.tried, 200);
  EXPECT_EQ(t.clean, t.tried);
  fs::remove_all(d);
}

TEST(ConfigCorpus, BadCommandLinesExitWithStatus2) {
  const fs::path d = fresh_dir("cli");
  const std::vector<std::vector<std::string>> cases = {
      {"run", "--set", "grid.n"},                     // no value
      {"run", "--set", "grid.n=abc"},                 // not TOML
      {"run", "--set", "nosuch.key=1"},               // unknown key
      {"run", (d / "missing.toml").string()},         // no such file
      {"run", "--resume", d.string(), "-o", "x"},     // --resume takes its own directory
      {"run", "--force"},                             // --force needs --resume
      {"run", "--resume", (d / "nothing").string()},  // no run there
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
