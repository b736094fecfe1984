// The stability-aware stop ([study], sim/stability.hpp): a state the kinetic-energy rule calls an
// equilibrium is tested by perturbing a copy. The twisted circle above the Michell threshold
// (ΔLk = 3 for a1 = 1.3e-19, a3 = 1.82e-19 erg·cm: threshold √3 a1/a3 ≈ 1.2) with no perturbation
// sits on an unstable equilibrium; below it (ΔLk = 1) the circle is stable. With several rods
// (issue 25) every rod is kicked: two uncharged rings side by side, one of them above the
// threshold, are found unstable and that one buckles; two below it stop as a verified equilibrium.
// The implicit scheme (issue 24) comes to rest in a state with contacts and stops there.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <span>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "helpers.hpp"
#include "io/csv.hpp"
#include "run_helpers.hpp"

using namespace ibrod;
using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

// small_config with the equilibrium rule at stop_kT, a probe of probe_us, rows every 100 steps
// (rows in simulated time for the implicit scheme: set output_every_us), no frames or periodic
// checkpoints, one thread; the dynamic test (the default, "auto", takes the Hessian at this size:
// its tests are below)
config::Config stop_rule_config(int excess_link, double stop_kT, double probe_us) {
  config::Config c = small_config(excess_link);
  c.time_stability_method = "dynamic";
  c.time_stop_kinetic_kT = stop_kT;
  c.time_stability_probe_us = probe_us;
  c.output_every_steps = 100;
  c.output_frame_every_steps = 0;
  c.output_checkpoint_every_steps = 0;
  c.run_threads = 1;
  return c;
}

// 16³, 100 points, no perturbation, a loose stop rule (E_K < 1e-8 kT fires after ~200 steps),
// a 0.2 µs probe
fs::path circle_config(const fs::path& d, int excess_link) {
  config::Config c = stop_rule_config(excess_link, 1e-8, 0.2);
  c.rod_perturbation = {0.0};
  c.time_t_end_us = 0.5;
  return write_config(d, c, "dlk" + std::to_string(excess_link) + ".toml");
}

double final_writhe(const fs::path& out) {
  const io::CsvTable t = io::read_csv_table(out / "timeseries.csv");
  return t.column("writhe").back();
}

// Two rings of circle_config (100 points, r0 = 54 Å) stacked on a common axis 50 Å apart,
// uncharged (so that only the fluid couples them and the pair comes to rest), with ΔLk = dlk0
// and dlk1; the stop rule and probe of circle_config.
fs::path two_rings_config(const fs::path& d, int dlk0, int dlk1) {
  config::Config c = stop_rule_config(dlk0, 1e-8, 0.2);
  c.rod_perturbation = {0.0};
  c.electrostatics_enabled = false;
  c.time_t_end_us = 0.5;
  config::apply_override(c, "rods.0.offset_A=[0, 0, -25]");
  config::apply_override(c, "rods.1.offset_A=[0, 0, 25]");
  config::apply_override(c, "rods.1.excess_link=" + std::to_string(dlk1));
  return write_config(d, c, "rings" + std::to_string(dlk0) + std::to_string(dlk1) + ".toml");
}

}  // namespace

TEST(StabilityTest, AnUnstableCircleIsNotCalledAnEquilibriumAndBuckles) {
  const fs::path d = fresh_dir("stability_unstable");
  const fs::path cfg = circle_config(d, 3);
  // without the test: the run stops on the unstable circle
  const Exit off = run_ibrod(
      {"run", cfg.string(), "-o", (d / "off").string(), "--set", "time.stability_test=false"},
      d / "off.log");
  ASSERT_EQ(off.code, 0) << off.output;
  EXPECT_THAT(read_file(d / "off" / "summary.json"), HasSubstr("\"stop_reason\": \"equilibrium\""));
  EXPECT_LT(std::abs(final_writhe(d / "off")), 1e-3);
  // with it: found unstable, the run goes on and buckles
  const Exit on = run_ibrod({"run", cfg.string(), "-o", (d / "on").string()}, d / "on.log");
  ASSERT_EQ(on.code, 0) << on.output;
  EXPECT_THAT(on.output, HasSubstr("not an equilibrium"));
  const std::string summary = read_file(d / "on" / "summary.json");
  EXPECT_THAT(summary, HasSubstr("\"stable\": false"));
  // the evidence: the kicked copy came below the unperturbed continuation by more than the
  // tolerance (1e-6 kT) at some time of the probe, and the lowest difference is the decision's
  const auto first = nlohmann::json::parse(summary)["stability_tests"][0];
  EXPECT_LT(first["E_difference_min_kT"].get<double>(), -1e-6) << first.dump();
  EXPECT_LE(first["E_difference_min_kT"].get<double>(),
            first["E_total_after_kT"].get<double>() -
                first["E_total_continuation_kT"].get<double>() + 1e-9);
  EXPECT_EQ(first["kick_A"].get<double>(), 1.0);
  EXPECT_THAT(summary, ::testing::Not(HasSubstr("\"stop_reason\": \"equilibrium\"")));
  EXPECT_GT(final_writhe(d / "on"), 0.5);
  EXPECT_NEAR(io::read_csv_table(d / "on" / "timeseries.csv").column("link").back(), 3.0, 1e-3);
  fs::remove_all(d);
}

TEST(StabilityTest, AStableCircleStopsAsAVerifiedEquilibriumAtTheTestedState) {
  const fs::path d = fresh_dir("stability_stable");
  const fs::path cfg = circle_config(d, 1);
  const Exit e = run_ibrod({"run", cfg.string(), "-o", (d / "out").string()}, d / "out.log");
  ASSERT_EQ(e.code, 0) << e.output;
  const std::string summary = read_file(d / "out" / "summary.json");
  EXPECT_THAT(summary, HasSubstr("\"stop_reason\": \"equilibrium\""));
  EXPECT_THAT(summary, HasSubstr("\"equilibrium_verified\": true"));
  EXPECT_THAT(summary, HasSubstr("\"stable\": true"));
  // the kick's energy relaxed from above: never below the continuation by the tolerance, and
  // the state tested is the one put back (its energy is the last row's)
  const auto first = nlohmann::json::parse(summary)["stability_tests"][0];
  EXPECT_GE(first["E_difference_min_kT"].get<double>(), -1e-6) << first.dump();
  EXPECT_GT(first["E_total_after_kT"].get<double>(),
            first["E_total_continuation_kT"].get<double>() - 1e-6);
  // the state put back is the one tested: the last row is the stop step's
  const io::CsvTable t = io::read_csv_table(d / "out" / "timeseries.csv");
  EXPECT_LT(t.column("step").back(), 1000);
  EXPECT_LT(std::abs(final_writhe(d / "out")), 1e-3);
  EXPECT_NEAR(t.column("E_total_kT").back(), first["E_total_before_kT"].get<double>(), 1e-6);
  fs::remove_all(d);
}

TEST(StabilityTest, SeveralRodsAreEachKickedAndTheUnstableOneBuckles) {
  const fs::path d = fresh_dir("stability_rods");
  // ring 1 above the threshold (ΔLk = 3), ring 0 below it (ΔLk = 1): only a kick of ring 1 (not
  // the first rod's alone, nor one of all points as one curve) finds the unstable mode
  const Exit on = run_ibrod({"run", two_rings_config(d, 1, 3).string(), "-o", (d / "on").string()},
                            d / "on.log");
  ASSERT_EQ(on.code, 0) << on.output;
  EXPECT_THAT(on.output, HasSubstr("not an equilibrium"));
  const std::string summary = read_file(d / "on" / "summary.json");
  EXPECT_THAT(summary, HasSubstr("\"stable\": false"));
  EXPECT_THAT(summary, ::testing::Not(HasSubstr("\"stop_reason\": \"equilibrium\"")));
  const io::CsvTable rods = io::read_csv_table(d / "on" / "rods.csv");
  EXPECT_LT(std::abs(rods.column("writhe_0").back()), 0.05);  // the stable ring stays a circle
  EXPECT_GT(std::abs(rods.column("writhe_1").back()), 0.5);   // the unstable one buckles
  EXPECT_NEAR(rods.column("link_0").back(), 1.0, 1e-3);
  EXPECT_NEAR(rods.column("link_1").back(), 3.0, 1e-3);

  // both below the threshold: a verified equilibrium at the tested state
  const Exit st = run_ibrod(
      {"run", two_rings_config(d, 1, 1).string(), "-o", (d / "stable").string()}, d / "st.log");
  ASSERT_EQ(st.code, 0) << st.output;
  const std::string s2 = read_file(d / "stable" / "summary.json");
  EXPECT_THAT(s2, HasSubstr("\"stop_reason\": \"equilibrium\""));
  EXPECT_THAT(s2, HasSubstr("\"equilibrium_verified\": true"));
  const auto first = nlohmann::json::parse(s2)["stability_tests"][0];
  EXPECT_GE(first["E_difference_min_kT"].get<double>(), -1e-6) << first.dump();
  EXPECT_GT(first["E_total_after_kT"].get<double>(),
            first["E_total_continuation_kT"].get<double>() - 1e-6);
  fs::remove_all(d);
}

// Issue 24: the implicit scheme (ROS2, the kernel-overlap local mobility, the 4.4 ns cap) comes to
// rest in a state with contacts: the small ring with ΔLk = 4 and ε1 = 1 collapses into a toroid
// whose strands touch (closest approach below the hard-core diameter, steric energy > 0); its E_K
// keeps falling (no floor) until the rule fires (here at 1e-7 kT, ~5 µs), and the kicked copy
// relaxes back: a verified equilibrium. Measured: stops at 5.4 µs after 1355 steps, closest
// approach 19.1 Å, E_steric 1.37 kT, the kick +1.08 kT above the continuation at the end.
TEST(StabilityTest, AnImplicitRunComesToRestInAContactStateAsAVerifiedEquilibrium) {
  const fs::path d = fresh_dir("stability_implicit_contact");
  config::Config c = stop_rule_config(4, 1e-7, 0.5);
  c.time_scheme = "implicit";
  c.time_implicit_order = 2;
  c.time_implicit_local_mobility = "overlap";
  c.time_dt_ns = 4.4;
  c.time_t_end_us = 10;
  c.output_every_us = 0.1;
  const fs::path cfg = write_config(d, c, "contact.toml");
  const Exit e = run_ibrod({"run", cfg.string(), "-o", (d / "out").string()}, d / "out.log");
  ASSERT_EQ(e.code, 0) << e.output;
  const std::string summary = read_file(d / "out" / "summary.json");
  EXPECT_THAT(summary, HasSubstr("\"stop_reason\": \"equilibrium\""));
  EXPECT_THAT(summary, HasSubstr("\"equilibrium_verified\": true"));
  EXPECT_THAT(summary, HasSubstr("\"stable\": true"));
  const io::CsvTable t = io::read_csv_table(d / "out" / "timeseries.csv");
  EXPECT_LT(t.column("time_us").back(), 9.9);  // the rule fired before t_end
  EXPECT_GT(t.column("writhe").back(), 1.5);   // collapsed
  EXPECT_GT(t.column("E_steric_kT").back(), 0.0);
  EXPECT_LT(t.column("closest_approach_A").back(), c.steric_diameter_A);
  EXPECT_NEAR(t.column("link").back(), 4.0, 1e-3);
  // a gradient flow: E_total never rises from one row to the next
  const std::span<const double> E = t.column("E_total_kT");
  for (std::size_t i = 1; i < E.size(); ++i) EXPECT_LE(E[i], E[i - 1] + 1e-6) << "row " << i;
  fs::remove_all(d);
}

// The Hessian method (time.stability_method = "hessian", sim/stability.hpp): the twisted circle
// above the threshold has a negative eigenvalue (a pair: the m = 2 writhing mode's two phases)
// once the rigid-body modes and the triads' uniform spin (7 zero modes) are projected out; the
// run goes on from the circle kicked along it and buckles. Below the threshold the lowest
// eigenvalue is positive and the run stops as a verified equilibrium at the tested state.
TEST(StabilityHessian, TheUnstableCircleHasANegativeModeAndTheStableOneNone) {
  const fs::path d = fresh_dir("stability_hessian");
  const std::vector<std::string> hessian{"--set", "time.stability_method=\"hessian\""};
  auto run = [&](int dlk, const std::string& name) {
    std::vector<std::string> args{"run", circle_config(d, dlk).string(), "-o", (d / name).string()};
    args.insert(args.end(), hessian.begin(), hessian.end());
    const Exit e = run_ibrod(args, d / (name + ".log"));
    EXPECT_EQ(e.code, 0) << e.output;
    return nlohmann::json::parse(read_file(d / name / "summary.json"));
  };
  const auto up = run(3, "dlk3");
  ASSERT_FALSE(up["stability_tests"].empty());
  const auto t3 = up["stability_tests"][0];
  EXPECT_EQ(t3["method"], "hessian");
  EXPECT_FALSE(t3["stable"].get<bool>()) << t3.dump();
  EXPECT_EQ(t3["zero_modes"].get<int>(), 7);
  EXPECT_EQ(t3["slithering_modes"].get<int>(), 0);  // a circle's is a rotation plus the spin
  EXPECT_GE(t3["negative_modes"].get<int>(), 2) << t3.dump();
  const auto ev3 = t3["lowest_eigenvalues_kT_per_A2"].get<std::vector<double>>();
  ASSERT_GE(ev3.size(), 2u);
  EXPECT_LT(ev3[0], 0);
  EXPECT_NEAR(ev3[1], ev3[0], 0.05 * std::abs(ev3[0]));  // the pair of phases
  EXPECT_LT(t3["E_difference_min_kT"].get<double>(), -1e-6);
  EXPECT_LT(t3["hessian_asymmetry"].get<double>(), 1e-2);
  EXPECT_NE(up["stop_reason"], "equilibrium");
  EXPECT_GT(final_writhe(d / "dlk3"), 0.5);
  // after k unstable verdicts in a row the next waits 2^(k−1) probe times (0.2 µs)
  const auto& tests = up["stability_tests"];
  for (std::size_t k = 1; k < tests.size(); ++k)
    EXPECT_GE(tests[k]["time_us"].get<double>() - tests[k - 1]["time_us"].get<double>(),
              0.2 * std::ldexp(1.0, int(k) - 1) - 1e-9)
        << tests.dump();

  const auto down = run(1, "dlk1");
  EXPECT_EQ(down["stop_reason"], "equilibrium");
  EXPECT_TRUE(down["equilibrium_verified"].get<bool>());
  const auto t1 = down["stability_tests"][0];
  EXPECT_TRUE(t1["stable"].get<bool>()) << t1.dump();
  EXPECT_EQ(t1["negative_modes"].get<int>(), 0);
  EXPECT_GT(t1["lowest_eigenvalues_kT_per_A2"][0].get<double>(), 0) << t1.dump();
  const io::CsvTable t = io::read_csv_table(d / "dlk1" / "timeseries.csv");
  EXPECT_NEAR(t.column("E_total_kT").back(), t1["E_total_before_kT"].get<double>(), 1e-9);
  fs::remove_all(d);
}

// A toroid at rest with its strands in contact (the implicit contact run above): no negative
// mode through the hard core; a verified equilibrium.
TEST(StabilityHessian, AContactStateAtRestHasNoNegativeMode) {
  const fs::path d = fresh_dir("stability_hessian_contact");
  config::Config c = stop_rule_config(4, 1e-7, 0.5);
  c.time_scheme = "implicit";
  c.time_implicit_order = 2;
  c.time_implicit_local_mobility = "overlap";
  c.time_dt_ns = 4.4;
  c.time_t_end_us = 10;
  c.output_every_us = 0.1;
  c.time_stability_method = "hessian";
  const fs::path cfg = write_config(d, c, "contact.toml");
  const Exit e = run_ibrod({"run", cfg.string(), "-o", (d / "out").string()}, d / "out.log");
  ASSERT_EQ(e.code, 0) << e.output;
  const auto s = nlohmann::json::parse(read_file(d / "out" / "summary.json"));
  EXPECT_EQ(s["stop_reason"], "equilibrium");
  EXPECT_TRUE(s["equilibrium_verified"].get<bool>());
  const auto t = s["stability_tests"].back();
  EXPECT_EQ(t["negative_modes"].get<int>(), 0) << t.dump();
  // the toroid's slithering is not a rigid motion plus the spin: projected out as an eighth mode
  EXPECT_EQ(t["slithering_modes"].get<int>(), 1) << t.dump();
  EXPECT_EQ(t["zero_modes"].get<int>(), 8) << t.dump();
  EXPECT_GT(s["final"]["E_steric_kT"].get<double>(), 0.0);
  fs::remove_all(d);
}
