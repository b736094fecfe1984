// Bounds on inputs and on what they imply (issue 13 items 5, 6, 8): derived counts that would
// overflow, a link the discretization cannot represent, and values at which a step forms
// non-finite numbers are refused by validate() naming the key; every value inside the bounds
// builds a Simulation whose first step stays finite.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "config/config.hpp"
#include "core/error.hpp"
#include "sim/simulation.hpp"

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

// The error of `--set assignment` on top of c, then validate ("" if accepted).
std::string refusal(config::Config c, const std::string& assignment) {
  return error_of([&] {
    config::apply_override(c, assignment);
    config::validate(c);
  });
}

config::Config small() {
  config::Config c;
  c.grid_n = 16;
  c.grid_box_A = 200;
  c.rod_base_pairs = 100;
  c.rod_excess_link = 2;
  c.time_t_end_us = 0.2;
  c.output_every_steps = 100;
  c.run_fftw_measure = false;
  c.run_threads = 1;
  return c;
}

std::string num(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

}  // namespace

// Item 5: before, t_end = 1e308 µs gave "time steps = -9223372036854775808" and a 1-step run.
TEST(Bounds, DerivedCountsThatWouldOverflowAreRefusedNamingTheKey) {
  const config::Config c;
  EXPECT_THAT(refusal(c, "time.t_end_us=1e308"), HasSubstr("time.t_end_us"));
  EXPECT_THAT(refusal(c, "time.dt_ns=1e-308"), HasSubstr("time.dt_ns"));
  EXPECT_THAT(refusal(c, "time.dt_ns=1e7"), HasSubstr("time.dt_ns"));
  // within each key's range, but 1e18 steps together
  config::Config d;
  d.time_dt_ns = 1e-6;
  EXPECT_THAT(refusal(d, "time.t_end_us=1e12"), HasSubstr("time.t_end_us"));
  EXPECT_THAT(refusal(d, "time.t_end_us=1e12"), HasSubstr("at most 1e+12 time steps"));
  EXPECT_EQ(refusal(d, "time.t_end_us=1e3"), "");  // 1e12 steps: the largest allowed
  // rows and frames beyond 1 PiB name the output key
  d = config::Config{};
  d.time_t_end_us = 1e8;
  EXPECT_THAT(refusal(d, "output.frame_every_steps=1"), HasSubstr("output.frame_every_steps"));
  EXPECT_THAT(refusal(d, "output.fluid_vti=true"), HasSubstr("output.frame_every_steps"));
  EXPECT_EQ(refusal(d, "output.frame_every_steps=1000000"), "");
  // what `ibrod check` derives from the largest accepted run has no negative count
  d = config::Config{};
  d.time_dt_ns = 1e-6;
  d.time_t_end_us = 1e3;
  d.output_every_steps = 1000000;
  d.output_frame_every_steps = 0;
  config::validate(d);
  const std::string report = config::derived_report(d);
  EXPECT_THAT(report, HasSubstr("time steps                = 1000000000000\n"));
  EXPECT_THAT(report, ::testing::Not(HasSubstr("-922337")));
}

// Item 6: before, rod.excess_link = 500 with 600 points built a rod of link −100 (2π·500/600
// per segment is past π and wraps).
TEST(Bounds, ALinkTheDiscretizationCannotRepresentIsRefused) {
  config::Config c;                                  // 600 base pairs
  EXPECT_EQ(refusal(c, "rod.excess_link=150"), "");  // π/2 per segment
  EXPECT_THAT(refusal(c, "rod.excess_link=151"), HasSubstr("rod.excess_link"));
  EXPECT_THAT(refusal(c, "rod.excess_link=-151"), HasSubstr("rod.base_pairs / 4 = 150"));
  c.rod_shear_modulus_dyn = 5e-4;  // a stiffer shear keeps the twisted circle (|sin β| < 1)
  EXPECT_THAT(refusal(c, "rod.excess_link=500"), HasSubstr("rod.excess_link"));
  // the reference twist, at most π/2 per segment too
  c = config::Config{};
  EXPECT_EQ(refusal(c, "rod.intrinsic_twist_per_A=0.46"), "");
  EXPECT_THAT(refusal(c, "rod.intrinsic_twist_per_A=-0.47"),
              HasSubstr("rod.intrinsic_twist_per_A"));
  EXPECT_THAT(refusal(c, "rod.intrinsic_twist_per_A=1e308"),
              HasSubstr("rod.intrinsic_twist_per_A"));
}

// Item 8: before, each of these at 1e308 passed `check` and blew up at step 0.
TEST(Bounds, ValuesAStepCannotRepresentAreRefusedWithTheRange) {
  const config::Config c;
  for (const char* key :
       {"grid.box_A", "rod.bend_modulus_erg_cm", "rod.twist_modulus_erg_cm",
        "rod.shear_modulus_dyn", "rod.stretch_modulus_dyn", "rod.rise_A", "electrostatics.charge_e",
        "electrostatics.dielectric", "electrostatics.cutoff_debye", "solvent.viscosity_poise",
        "solvent.density_g_cm3", "solvent.temperature_K", "steric.diameter_A", "steric.stiffness",
        "time.stop_kinetic_kT"}) {
    const std::string msg = refusal(c, std::string(key) + "=1e308");
    EXPECT_THAT(msg, HasSubstr(key)) << key;
    EXPECT_THAT(msg, HasSubstr("<= ")) << key << ": the message gives the range";
  }
  EXPECT_THAT(refusal(c, "grid.box_A=1e11"), HasSubstr("rod.rise_A"));  // positions keep Δs
}

// The bounds are what a step can represent: at each end of each range (20 decades from the
// reference value), a Simulation is built and its first step leaves every position and triad
// finite (the physics may be absurd; the numbers are not NaN or inf).
TEST(Bounds, AtEveryBoundTheFirstStepStaysFinite) {
  const struct {
    const char* key;
    double ref;
    bool zero;
  } keys[] = {
      {"rod.bend_modulus_erg_cm", 1.3e-19, false},
      {"rod.twist_modulus_erg_cm", 1.82e-19, false},
      {"rod.shear_modulus_dyn", 5e-5, false},
      {"rod.stretch_modulus_dyn", 5e-5, false},
      {"solvent.viscosity_poise", 0.01, false},
      {"solvent.density_g_cm3", 1.0, false},
      {"solvent.temperature_K", 300, false},
      {"electrostatics.charge_e", 0.48, true},
      {"electrostatics.dielectric", 77.7, false},
      {"electrostatics.cutoff_debye", 16, false},
      {"steric.stiffness", 0.1, true},
      {"steric.diameter_A", 20, false},
      {"rod.rise_A", 3.4, false},
      {"grid.box_A", 725, false},
  };
  int built = 0;
  for (const auto& k : keys) {
    const double lo = k.zero ? 0 : k.ref * 1e-20, hi = k.ref * 1e20;
    EXPECT_THAT(refusal(small(), std::string(k.key) + "=" + num(hi * 1.001)), HasSubstr(k.key));
    for (const double v : {lo, hi}) {
      config::Config c = small();
      const std::string set = std::string(k.key) + "=" + num(v);
      config::apply_override(c, set);
      if (!error_of([&] { config::validate(c); }).empty()) continue;  // a cross-key bound
      sim::Simulation s(config::to_params(c));
      s.step();
      ++built;
      bool finite = true;
      for (int i = 0; i < s.rod().size(); ++i)
        finite = finite && s.rod().X[i].allFinite() && s.rod().D[i].allFinite();
      EXPECT_TRUE(finite) << set;
    }
  }
  EXPECT_GE(built, 20);
}
