// Several rods in one state ([[rods]], docs/model.md "Several rods"): the configuration resolves
// each [[rods]] table on top of [rod]; the stepper's forces on two rods are each rod's own elastic
// forces plus the pair forces between all points; the pair forces between two rods obey Newton's
// third law (the force of rod A on rod B is minus that of B on A, and so is the moment); the
// whole force is −∇E by finite differences, the interaction across the rods included.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "config/config.hpp"
#include "core/error.hpp"
#include "integrate/stepper.hpp"
#include "rod/rod_set.hpp"
#include "sim/simulation.hpp"

namespace ibrod::integrate {
namespace {

// Two rings of 40 points (Δs 3.4 Å, r ≈ 21.6 Å) whose planes are 16 Å apart: within the hard
// core (D = 20 Å) and the Debye length, so both pair forces act across the rods.
config::Config two_rings() {
  config::Config c;
  c.grid_n = 16;
  c.grid_box_A = 200;
  c.rod_base_pairs = 40;
  c.rod_excess_link = 1;
  c.rod_perturbation = {0.0};
  c.run_threads = 1;
  c.run_fftw_measure = false;
  config::apply_override(c, "rods.0.offset_A=[0, 0, -8]");
  config::apply_override(c, "rods.1.offset_A=[5, 0, 8]");
  config::apply_override(c, "rods.1.rotation_deg=[20, 0, 0]");
  config::apply_override(c, "rods.1.base_pairs=36");
  config::apply_override(c, "rods.1.excess_link=0");
  return c;
}

TEST(SeveralRods, ConfigTablesResolveOnTopOfRod) {
  config::Config c = two_rings();
  config::validate(c);
  EXPECT_EQ(config::rod_configs(c).size(), 2u);
  EXPECT_EQ(config::point_count(c), 76);
  const config::Config r0 = config::rod_config(c, 0), r1 = config::rod_config(c, 1);
  EXPECT_EQ(r0.rod_base_pairs, 40);  // from [rod]
  EXPECT_EQ(r1.rod_base_pairs, 36);  // its own
  EXPECT_EQ(r1.rod_excess_link, 0);
  EXPECT_EQ(r0.rod_excess_link, 1);
  EXPECT_DOUBLE_EQ(r1.rod_rotation_deg[0], 20.0);
  // written back and read again: the same configuration
  config::Config back;
  config::apply_toml(back, config::to_toml(c), "config.toml");
  EXPECT_EQ(config::describe(back), config::describe(c));
  EXPECT_EQ(config::config_differences(config::to_toml(c), c, "x"), "");
  config::Config d = c;
  config::apply_override(d, "rods.1.excess_link=2");
  EXPECT_NE(config::config_differences(config::to_toml(c), d, "x").find("rods.1.excess_link"),
            std::string::npos);
  // from a file
  config::Config f;
  config::apply_toml(
      f,
      "[rod]\nbase_pairs = 50\n[[rods]]\nexcess_link = 0\n[[rods]]\nbase_pairs = 30\n"
      "closed = false\nexcess_link = 0\n",
      "f.toml");
  EXPECT_EQ(config::rod_configs(f).size(), 2u);
  EXPECT_EQ(config::rod_config(f, 0).rod_base_pairs, 50);
  EXPECT_FALSE(config::rod_config(f, 1).rod_closed);
  EXPECT_EQ(config::point_count(f), 80);
}

TEST(SeveralRods, BadTablesNameTheTableAndKey) {
  config::Config c;
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  const std::string unknown = message([&] { config::apply_override(c, "rods.0.colour=1"); });
  EXPECT_NE(unknown.find("rods.0.colour"), std::string::npos) << unknown;
  const std::string value = message([&] { config::apply_override(c, "rods.0.base_pairs=-3"); });
  EXPECT_NE(value.find("rod.base_pairs"), std::string::npos) << value;
  EXPECT_NE(value.find("[[rods]] table 0"), std::string::npos) << value;
  const std::string skip = message([&] { config::apply_override(c, "rods.3.base_pairs=30"); });
  EXPECT_NE(skip.find("from 0 to 0"), std::string::npos) << skip;
  const std::string notable = message([&] { config::apply_toml(c, "rods = 3\n", "f.toml"); });
  EXPECT_NE(notable.find("array of tables"), std::string::npos) << notable;
  config::Config impl = two_rings();  // the implicit scheme runs on several rods (issue 25)
  impl.time_scheme = "implicit";
  EXPECT_EQ(message([&] { config::validate(impl); }), "");
  config::Config open = two_rings();
  config::apply_override(open, "rods.1.closed=false");
  config::apply_override(open, "rods.1.excess_link=2");
  const std::string link = message([&] { config::validate(open); });
  EXPECT_NE(link.find("[[rods]] table 1"), std::string::npos) << link;
  EXPECT_NE(link.find("rod.excess_link"), std::string::npos) << link;
}

TEST(SeveralRods, ElasticForcesAreEachRodsOwn) {
  const sim::SimParams p = config::to_params(two_rings());
  ASSERT_EQ(p.stepper.rods.size(), 2u);
  sim::Simulation sim(p);
  rod::RodState s = sim.rod();
  std::mt19937_64 rng(3);
  std::normal_distribution<double> N(0.0, 0.3);
  for (int k = 0; k < s.size(); ++k) s.X[k] += Vec3(N(rng), N(rng), N(rng));
  StepperParams sp = p.stepper;
  sp.electro.enabled = false;
  sp.steric.enabled = false;
  System st(sp);
  const StepEnergies e = st.compute_forces(s);
  double sum = 0;
  const auto ranges = rod::ranges_of(sp.rods);
  const auto rods = sp.rods;
  for (std::size_t r = 0; r < rods.size(); ++r) {
    rod::RodState one;
    rod::extract(s, ranges[r], one);
    rod::RodWork w;
    std::vector<Vec3> F(one.size(), Vec3::Zero()), T(one.size(), Vec3::Zero());
    sum += rod::elastic_forces(rods[r], one, w, F, T).total();
    for (int k = 0; k < one.size(); ++k) {
      EXPECT_EQ(st.forces()[ranges[r].offset + k], F[k]);
      EXPECT_EQ(st.torques()[ranges[r].offset + k], T[k]);
    }
  }
  EXPECT_DOUBLE_EQ(e.elastic.total(), sum);
}

TEST(SeveralRods, PairForcesObeyNewtonsThirdLawAndAreMinusGradient) {
  const sim::SimParams p = config::to_params(two_rings());
  sim::Simulation sim(p);
  const rod::RodState s = sim.rod();
  const auto ranges = sim.rod_ranges();
  // pair forces only: elastic off (zero moduli would be refused; take them out by difference)
  StepperParams sp = p.stepper;
  System all(sp);
  StepperParams el = sp;
  el.electro.enabled = false;
  el.steric.enabled = false;
  System elastic_only(el);
  const StepEnergies e = all.compute_forces(s);
  elastic_only.compute_forces(s);
  ASSERT_GT(e.steric, 0.0) << "the rings must overlap within the hard core";
  ASSERT_GT(e.electro, 0.0);
  // the pair forces of each rod alone (one-rod steppers): what the other rod adds is the rest
  Vec3 on[2] = {Vec3::Zero(), Vec3::Zero()}, moment[2] = {Vec3::Zero(), Vec3::Zero()};
  for (int r = 0; r < 2; ++r) {
    rod::RodState one;
    rod::extract(s, ranges[r], one);
    StepperParams alone = sp;
    alone.rods = {sp.rods[r]};
    System a(alone);
    a.compute_forces(one);
    for (int k = 0; k < one.size(); ++k) {
      const int i = ranges[r].offset + k;
      const Vec3 from_other = all.forces()[i] - a.forces()[k];
      on[r] += from_other;
      moment[r] += s.X[i].cross(from_other);
    }
  }
  std::printf("  force of rod 1 on rod 0: (%.4g, %.4g, %.4g), of 0 on 1: (%.4g, %.4g, %.4g)\n",
              on[0][0], on[0][1], on[0][2], on[1][0], on[1][1], on[1][2]);
  ASSERT_GT(on[0].norm(), 0.0);
  EXPECT_LT((on[0] + on[1]).norm(), 1e-11 * on[0].norm());
  EXPECT_LT((moment[0] + moment[1]).norm(), 1e-9 * moment[0].norm());
  // the rods push apart: rod 0 (below) is pushed down, along −z
  EXPECT_LT(on[0][2], 0.0);
  // F = −∇E of electro + steric + elastic by central differences, for points of both rods
  auto energy = [&](const rod::RodState& x) {
    System t(sp);
    const StepEnergies en = t.compute_forces(x);
    return en.elastic.total() + en.electro + en.steric;
  };
  const double h = 1e-5;
  double worst = 0;
  for (int i : {0, 7, 39, 40, 55, 75})
    for (int d = 0; d < 3; ++d) {
      rod::RodState a = s, b = s;
      a.X[i][d] += h;
      b.X[i][d] -= h;
      const double fd = -(energy(a) - energy(b)) / (2 * h);
      const double F = all.forces()[i][d];
      worst = std::max(worst, std::abs(fd - F) / (std::abs(F) + 1e-3 * on[0].norm()));
    }
  std::printf("  F = -dE/dX across two rods: worst relative error %.3g\n", worst);
  EXPECT_LT(worst, 1e-5);
}

TEST(SeveralRods, StateChecksEachRodApart) {
  const sim::SimParams p = config::to_params(two_rings());
  sim::Simulation sim(p);
  EXPECT_EQ(sim.state_check(), "");  // the gap between the rods is not a link
  rod::RodState s = sim.rod();
  s.X[41] += Vec3(10.0, 0, 0);  // rod 1, its point 1
  try {
    sim.set_rod_state(s);
    FAIL() << "a stretched link was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rod 1"), std::string::npos) << e.what();
  }
  s = sim.rod();
  s.X.pop_back();
  s.D.pop_back();
  EXPECT_THROW(sim.set_rod_state(s), std::invalid_argument);
}

TEST(SeveralRods, OneTableIsTheRodItselfBitForBit) {
  // [[rods]] with one empty table is the run of [rod]: the same state after 50 steps
  config::Config plain;
  plain.grid_n = 16;
  plain.grid_box_A = 200;
  plain.rod_base_pairs = 60;
  plain.rod_excess_link = 2;
  plain.run_threads = 1;
  plain.run_fftw_measure = false;
  config::Config one = plain;
  config::apply_toml(one, "[[rods]]\n", "one.toml");
  ASSERT_EQ(one.rods.size(), 1u);
  config::validate(one);
  sim::Simulation a(config::to_params(plain)), b(config::to_params(one));
  for (int k = 0; k < 50; ++k) {
    a.step();
    b.step();
  }
  EXPECT_EQ(a.rod().X, b.rod().X);
  EXPECT_EQ(a.rod().D, b.rod().D);
  // and a second, identical table: twice the points, each ring moving as the pair dictates
  config::Config two = one;
  config::apply_override(two, "rods.1.offset_A=[0, 0, 40]");
  sim::Simulation c(config::to_params(two));
  EXPECT_EQ(c.rod().size(), 120);
  EXPECT_EQ(c.rods().size(), 2u);
}

}  // namespace
}  // namespace ibrod::integrate
