// Thermal runs end to end (docs/thermal.md): the same seed gives bitwise the same trajectory (on
// another thread count the same to round-off: the noise is thread-independent bit for bit, but
// the pair forces add their per-thread buffers in thread order), a run extended from its
// checkpoint ends bitwise where the uninterrupted one does, another seed or no noise ends
// elsewhere, summary.json names the temperature and seed, the equilibrium rule is off; the same
// for the implicit scheme, and its combinations without noise refused naming the keys. 16³, 100
// points, 300 steps: about a second a run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "helpers.hpp"
#include "run_helpers.hpp"

using namespace ibrod;
using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

std::string thermal_config(int seed, bool thermal, int threads) {
  config::Config c = small_config(2);
  c.time_t_end_us = 0.03;  // 300 steps
  c.output_every_steps = 20;
  c.output_checkpoint_every_steps = 50;
  c.solvent_thermal = thermal;
  c.run_seed = seed;
  c.run_threads = threads;
  c.time_stop_kinetic_kT = 1e20;  // would stop at once without noise's rule being off
  return small_config_toml(c);
}

fs::path run_config(const fs::path& root, const std::string& name, const std::string& toml,
                    std::vector<std::string> extra = {}) {
  std::ofstream(root / (name + ".toml")) << toml;
  std::vector<std::string> args{"run", (root / (name + ".toml")).string(), "-o",
                                (root / name).string()};
  args.insert(args.end(), extra.begin(), extra.end());
  const Exit e = run_ibrod(args, root / (name + ".log"));
  EXPECT_EQ(e.code, 0) << e.output;
  return root / name;
}

// The numbers of a CSV file after its header line.
std::vector<double> csv_numbers(const fs::path& p) {
  std::string t = read_file(p);
  t = t.substr(t.find('\n') + 1);
  for (char& ch : t)
    if (ch == ',') ch = ' ';
  std::istringstream is(t);
  std::vector<double> v;
  for (double x; is >> x;) v.push_back(x);
  return v;
}

}  // namespace

TEST(ThermalRun, SameSeedSameBitsAcrossAResumeAndRoundOffAcrossThreads) {
  const fs::path root = fresh_dir("thermal_run");
  const fs::path a = run_config(root, "A", thermal_config(5, true, 1));
  const fs::path a2 = run_config(root, "A2", thermal_config(5, true, 1));
  EXPECT_EQ(read_file(a / "timeseries.csv"), read_file(a2 / "timeseries.csv"));
  EXPECT_EQ(read_file(a / "final_state.csv"), read_file(a2 / "final_state.csv"));
  const fs::path b = run_config(root, "B", thermal_config(5, true, 2));
  const std::vector<double> fa = csv_numbers(a / "final_state.csv"),
                            fb = csv_numbers(b / "final_state.csv");
  ASSERT_EQ(fa.size(), fb.size());
  ASSERT_EQ(fa.size(), 100u * 12u);
  double worst = 0;
  for (std::size_t i = 0; i < fa.size(); ++i) worst = std::max(worst, std::abs(fa[i] - fb[i]));
  EXPECT_LT(worst, 1e-6) << "1 and 2 threads: positions (Å) and triads differ beyond round-off";
  const std::string summary = read_file(a / "summary.json");
  EXPECT_THAT(summary, HasSubstr("\"thermal\": true"));
  EXPECT_THAT(summary, HasSubstr("\"temperature_K\": 300"));
  EXPECT_THAT(summary, HasSubstr("\"seed\": 5"));
  // E_K < 1e20 kT always holds: the run reaches t_end only because the equilibrium rule is off
  EXPECT_THAT(summary, HasSubstr("\"stop_reason\": \"end_time\""));

  // half the time, then extended from the checkpoint to the full time: the same final state
  const fs::path c =
      run_config(root, "C", thermal_config(5, true, 2), {"--set", "time.t_end_us=0.015"});
  const Exit e =
      run_ibrod({"run", "--resume", c.string(), "--set", "time.t_end_us=0.03"}, root / "C2.log");
  ASSERT_EQ(e.code, 0) << e.output;
  EXPECT_EQ(read_file(b / "final_state.csv"), read_file(c / "final_state.csv"));

  // another seed, or no noise: another trajectory
  const fs::path d = run_config(root, "D", thermal_config(6, true, 1));
  const fs::path z =
      run_config(root, "Z", thermal_config(5, false, 1), {"--set", "time.stop_kinetic_kT=0"});
  EXPECT_NE(read_file(a / "final_state.csv"), read_file(d / "final_state.csv"));
  EXPECT_NE(read_file(a / "final_state.csv"), read_file(z / "final_state.csv"));
  EXPECT_THAT(read_file(z / "summary.json"), HasSubstr("\"thermal\": false"));
  fs::remove_all(root);
}

// The implicit scheme with noise (issue 28, docs/thermal.md "The implicit step with noise"):
// the overlap M_loc, order 1, a fixed Δt. 100 steps of 0.25 ns: the same seed gives the same
// bits, half the run extended from its checkpoint (K and M_loc refreshed there in both runs)
// ends bitwise where the uninterrupted one does, and so does one stopped between checkpoints
// (the checkpoint keeps the held filter's state), another seed elsewhere. About a second a run.
std::string implicit_thermal_config(int seed) {
  config::Config c = small_config(2);
  c.time_scheme = "implicit";
  c.time_implicit_local_mobility = "overlap";
  c.time_dt_ns = 0.25;
  c.time_t_end_us = 0.025;  // 100 steps
  c.output_every_steps = 10;
  c.output_checkpoint_every_steps = 50;
  c.solvent_thermal = true;
  c.run_seed = seed;
  c.run_threads = 1;
  return small_config_toml(c);
}

TEST(ThermalRun, ImplicitSameSeedSameBitsAcrossAResume) {
  const fs::path root = fresh_dir("thermal_implicit_run");
  const fs::path a = run_config(root, "A", implicit_thermal_config(5));
  const fs::path a2 = run_config(root, "A2", implicit_thermal_config(5));
  EXPECT_EQ(read_file(a / "final_state.csv"), read_file(a2 / "final_state.csv"));
  EXPECT_EQ(read_file(a / "timeseries.csv"), read_file(a2 / "timeseries.csv"));
  // a fixed Δt: 100 steps to 0.025 µs, no step judged (the energy rises under noise)
  const std::string summary = read_file(a / "summary.json");
  EXPECT_THAT(summary, HasSubstr("\"thermal\": true"));
  EXPECT_THAT(summary, HasSubstr("\"stop_reason\": \"end_time\""));
  EXPECT_THAT(read_file(a / "timeseries.csv"), HasSubstr("\n100,0.02"));
  const fs::path c =
      run_config(root, "C", implicit_thermal_config(5), {"--set", "time.t_end_us=0.0125"});
  const Exit e =
      run_ibrod({"run", "--resume", c.string(), "--set", "time.t_end_us=0.025"}, root / "C2.log");
  ASSERT_EQ(e.code, 0) << e.output;
  EXPECT_EQ(read_file(a / "final_state.csv"), read_file(c / "final_state.csv"));
  // stopped between checkpoints (step 37, as a signal stops a run: its checkpoint is written
  // there, off the schedule of 50): the checkpoint keeps the state the held filter was made at,
  // so the resumed run still ends on A's bits (with the filter made afresh there it did not)
  const fs::path g =
      run_config(root, "G", implicit_thermal_config(5), {"--set", "time.t_end_us=0.00925"});
  const Exit eg =
      run_ibrod({"run", "--resume", g.string(), "--set", "time.t_end_us=0.025"}, root / "G2.log");
  ASSERT_EQ(eg.code, 0) << eg.output;
  EXPECT_EQ(read_file(a / "final_state.csv"), read_file(g / "final_state.csv"));
  EXPECT_EQ(read_file(a / "timeseries.csv"), read_file(g / "timeseries.csv"));
  const fs::path d = run_config(root, "D", implicit_thermal_config(6));
  EXPECT_NE(read_file(a / "final_state.csv"), read_file(d / "final_state.csv"));
  // the noise moves the ring: the final state is not the deterministic one
  const fs::path z =
      run_config(root, "Z", implicit_thermal_config(5), {"--set", "solvent.thermal=false"});
  EXPECT_NE(read_file(a / "final_state.csv"), read_file(z / "final_state.csv"));
  fs::remove_all(root);
}

TEST(ThermalRun, ImplicitNoiseOutsideTheOverlapFirstOrderStepIsRefusedNamingTheKeys) {
  const fs::path root = fresh_dir("thermal_implicit");
  std::ofstream(root / "in.toml") << thermal_config(5, true, 1);
  const std::string in = (root / "in.toml").string();
  // the diagonal local mobility (the default "self")
  Exit e = run_ibrod({"check", in, "--set", "time.scheme=implicit"}, root / "check.log");
  EXPECT_NE(e.code, 0);
  EXPECT_THAT(e.output, HasSubstr("time.implicit_local_mobility"));
  EXPECT_THAT(e.output, HasSubstr("\"overlap\""));
  EXPECT_THAT(e.output, HasSubstr("solvent.thermal"));
  // the two-stage step
  e = run_ibrod({"check", in, "--set", "time.scheme=implicit", "--set",
                 "time.implicit_local_mobility=overlap", "--set", "time.implicit_order=2"},
                root / "check2.log");
  EXPECT_NE(e.code, 0);
  EXPECT_THAT(e.output, HasSubstr("time.implicit_order"));
  // GMRES
  e = run_ibrod(
      {"check", in, "--set", "time.scheme=implicit", "--set",
       "time.implicit_local_mobility=overlap", "--set", "time.implicit_krylov_iterations=3"},
      root / "check3.log");
  EXPECT_NE(e.code, 0);
  EXPECT_THAT(e.output, HasSubstr("time.implicit_krylov_iterations"));
  // the supported combination passes
  e = run_ibrod({"check", in, "--set", "time.scheme=implicit", "--set",
                 "time.implicit_local_mobility=overlap"},
                root / "check4.log");
  EXPECT_EQ(e.code, 0) << e.output;
  fs::remove_all(root);
}
