// The power rule (`time.stop_power_kT_per_us`, docs/config.md "The power rule"): the power of the
// rods' loads in a step, Σ F·U + T·W, is the rate at which their potential energy falls, in
// either scheme (checked against the energy's change over one short step); the rule calls a
// resting state an equilibrium in either scheme, the stability test then decides, and it is the
// rule that fired (the same run without it goes on to t_end); it is off with noise.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "config/config.hpp"
#include "helpers.hpp"
#include "io/csv.hpp"
#include "run_helpers.hpp"
#include "sim/simulation.hpp"

using namespace ibrod;
using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

config::Config scheme_config(const std::string& scheme, int excess_link) {
  config::Config c = small_config(excess_link);
  c.time_scheme = scheme;
  c.run_threads = 1;
  if (scheme == "implicit") {
    c.time_implicit_order = 2;
    c.time_implicit_local_mobility = "overlap";
  }
  return c;
}

double potential_kT(sim::Simulation& s) {
  const sim::Observables o = s.observe();
  return o.E_total_kT - o.E_kinetic_kT;
}

}  // namespace

// A ΔLk = 4 ring buckling on 16³: P of one short step against −ΔE_pot/Δt of that step (measured
// ratios 1.006 and 1.005). The step is short (explicit 0.05 ns, implicit 0.1 ns) so that the O(Δt)
// difference between the power at the step's start and the mean over the step stays small.
TEST(PowerRule, ThePowerIsTheRateAtWhichThePotentialEnergyFalls) {
  for (const std::string scheme : {"explicit", "implicit"}) {
    config::Config c = scheme_config(scheme, 4);
    c.time_dt_ns = scheme == "explicit" ? 0.05 : 0.1;
    c.time_t_end_us = 10;
    config::validate(c);
    sim::Simulation s(config::to_params(c));
    EXPECT_TRUE(std::isnan(s.power_kT_per_us())) << scheme << ": no step yet";
    while (s.time() < 0.2e-6) s.step();
    for (int i = 0; i < 3; ++i) {
      const double E0 = potential_kT(s), t0 = s.time();
      s.step();
      const double E1 = potential_kT(s), t1 = s.time();
      const double rate = (E0 - E1) / ((t1 - t0) / 1e-6), P = s.power_kT_per_us();
      std::printf("  %s at %.4f us: P = %.6e kT/us, -dE/dt = %.6e kT/us, ratio %.6f\n",
                  scheme.c_str(), t0 / 1e-6, P, rate, rate / P);
      EXPECT_GT(P, 0) << scheme;
      EXPECT_NEAR(rate / P, 1.0, 0.02) << scheme;
    }
  }
}

// A perturbed ΔLk = 1 circle on 16³ relaxes by a power law (P ≈ 0.057 kT/µs at 0.55 µs, 0.024 at
// 1 µs in both schemes): with the power rule at 0.05 kT/µs alone (E_K rule off) both runs stop
// as a verified equilibrium within 0.1 µs of each other; without it they run to t_end.
TEST(PowerRule, FiresAtTheSameTimeInBothSchemesAndTheStabilityTestDecides) {
  const fs::path d = fresh_dir("power_rule");
  double stop_us[2] = {0, 0};
  for (int i = 0; i < 2; ++i) {
    const std::string scheme = i == 0 ? "explicit" : "implicit";
    config::Config c = scheme_config(scheme, 1);
    c.time_dt_ns = i == 0 ? 0.1 : 4.4;
    c.time_t_end_us = 1;
    c.time_stop_kinetic_kT = 0;
    c.time_stability_probe_us = 0.2;
    c.output_every_us = 0.01;
    c.output_frame_every_steps = 0;
    c.output_checkpoint_every_steps = 0;
    for (const double rule : {0.05, 0.0}) {
      c.time_stop_power_kT_per_us = rule;
      const std::string name = scheme + (rule > 0 ? "_rule" : "_off");
      const fs::path cfg = write_config(d, c, name + ".toml");
      const Exit e =
          run_ibrod({"run", cfg.string(), "-o", (d / name).string()}, d / (name + ".log"));
      ASSERT_EQ(e.code, 0) << e.output;
      const std::string summary = read_file(d / name / "summary.json");
      const io::CsvTable t = io::read_csv_table(d / name / "timeseries.csv");
      const double t_last = t.column("time_us").back();
      if (rule > 0) {
        EXPECT_THAT(summary, HasSubstr("\"stop_reason\": \"equilibrium\"")) << name;
        EXPECT_THAT(summary, HasSubstr("\"equilibrium_verified\": true")) << name;
        EXPECT_THAT(summary, HasSubstr("\"stable\": true")) << name;
        EXPECT_GT(t_last, 0.3) << name;
        EXPECT_LT(t_last, 0.9) << name;
        stop_us[i] = t_last;
      } else {
        EXPECT_THAT(summary, HasSubstr("\"stop_reason\": \"end_time\"")) << name;
        EXPECT_GT(t_last, 0.99) << name;
      }
    }
  }
  std::printf("  the power rule fired at %.3f µs (explicit), %.3f µs (implicit)\n", stop_us[0],
              stop_us[1]);
  EXPECT_NEAR(stop_us[0], stop_us[1], 0.1);
  fs::remove_all(d);
}
