// The stability-aware stop ([study], sim/stability.hpp): a state the kinetic-energy rule calls an
// equilibrium is tested by perturbing a copy. The twisted circle above the Michell threshold
// (ΔLk = 3 for a1 = 1.3e-19, a3 = 1.82e-19 erg·cm: threshold √3 a1/a3 ≈ 1.2) with no perturbation
// sits on an unstable equilibrium; below it (ΔLk = 1) the circle is stable.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <fstream>
#include <string>

#include "config/config.hpp"
#include "helpers.hpp"
#include "io/csv.hpp"
#include "run_helpers.hpp"

using namespace ibrod;
using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

// 16³, 100 points, no perturbation, a loose stop rule (E_K < 1e-8 kT fires after ~200 steps),
// a 0.2 µs probe
fs::path circle_config(const fs::path& d, int excess_link) {
  config::Config c = small_config(excess_link);
  c.rod_perturbation = {0.0};
  c.time_t_end_us = 0.5;
  c.time_stop_kinetic_kT = 1e-8;
  c.time_stability_probe_us = 0.2;
  c.output_every_steps = 100;
  c.output_frame_every_steps = 0;
  c.output_checkpoint_every_steps = 0;
  c.run_threads = 1;
  const fs::path p = d / ("dlk" + std::to_string(excess_link) + ".toml");
  std::ofstream(p) << small_config_toml(c);
  return p;
}

double final_writhe(const fs::path& out) {
  const io::CsvTable t = io::read_csv_table(out / "timeseries.csv");
  return t.column("writhe").back();
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
