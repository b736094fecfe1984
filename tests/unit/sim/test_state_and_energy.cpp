// The one state snapshot and the one potential-energy sum of a Simulation (issue 25): a Snapshot
// put back makes the next steps bitwise those of the run it was taken from (explicit and
// implicit, one rod and several); the observables' E_total, total_energy_kT and the stepper's
// energies are the same sum (StepEnergies::terms); each rod's observables of a collection of one
// are the totals. 16³, 40-point rings: well under a second.
#include <gtest/gtest.h>

#include <cmath>

#include "config/config.hpp"
#include "sim/simulation.hpp"

namespace ibrod::sim {
namespace {

config::Config ring(const std::string& scheme, int rods) {
  config::Config c;
  c.grid_n = 16;
  c.grid_box_A = 200;
  c.rod_base_pairs = 40;
  c.rod_excess_link = 2;
  c.run_threads = 1;
  c.run_fftw_measure = false;
  c.time_scheme = scheme;
  c.time_dt_ns = scheme == "implicit" ? 1.0 : 0.1;
  if (rods == 2) {
    config::apply_override(c, "rods.0.offset_A=[0, 0, -30]");
    config::apply_override(c, "rods.1.offset_A=[0, 0, 30]");
    config::apply_override(c, "rods.1.closed=false");
    config::apply_override(c, "rods.1.excess_link=0");
    config::apply_override(c, "rods.1.base_pairs=30");
  }
  config::validate(c);
  return c;
}

bool same_state(const rod::RodState& a, const rod::RodState& b) { return a.X == b.X && a.D == b.D; }

TEST(Snapshot, RestoredStateStepsBitwiseAsTheOriginal) {
  for (const std::string scheme : {"explicit", "implicit"})
    for (const int rods : {1, 2}) {
      Simulation s(config::to_params(ring(scheme, rods)));
      for (int k = 0; k < 5; ++k) s.step();
      const Snapshot at5 = s.snapshot();
      EXPECT_EQ(at5.step, 5);
      EXPECT_EQ(at5.velocity.size(), 3 * s.params().stepper.grid.size());
      EXPECT_EQ(at5.implicit.next_dt > 0, scheme == "implicit");
      s.checkpoint_taken();  // as a run does where it writes a checkpoint
      for (int k = 0; k < 5; ++k) s.step();
      const rod::RodState end = s.rod();
      const double t_end = s.time();
      // the same steps from the snapshot, in another Simulation of the same parameters
      Simulation r(config::to_params(ring(scheme, rods)));
      r.restore(at5);
      EXPECT_EQ(r.step_count(), 5);
      EXPECT_EQ(r.time(), at5.time);
      for (int k = 0; k < 5; ++k) r.step();
      EXPECT_TRUE(same_state(r.rod(), end)) << scheme << " " << rods;
      EXPECT_EQ(r.time(), t_end);
      const Snapshot a = s.snapshot(), b = r.snapshot();
      EXPECT_EQ(a.velocity, b.velocity);
      EXPECT_EQ(a.implicit.next_dt, b.implicit.next_dt);
      // without the velocity: nothing gathered
      EXPECT_TRUE(s.snapshot(false).velocity.empty());
    }
}

TEST(PotentialEnergy, OneSumForObservablesTotalEnergyAndTheStepper) {
  for (const int rods : {1, 2}) {
    Simulation s(config::to_params(ring("explicit", rods)));
    for (int k = 0; k < 20; ++k) s.step();
    const Observables o = s.observe();
    const double kT = s.params().kT;
    const integrate::StepEnergies E = s.system().energies(s.rod());
    EXPECT_EQ(o.E_total_kT, s.total_energy_kT());
    EXPECT_EQ(o.E_total_kT, E.potential_kT(kT) + o.E_kinetic_kT);
    EXPECT_EQ(o.E_bend_kT + o.E_twist_kT + o.E_stretch_kT + o.E_electro_kT + o.E_steric_kT +
                  o.E_kinetic_kT,
              o.E_total_kT);
    // the forces' energies (cell lists) are the same terms to round-off
    const integrate::StepEnergies F = s.system().compute_forces(s.rod());
    EXPECT_NEAR(F.potential(), E.potential(), 1e-12 * std::abs(E.potential()));
    double sum = 0;
    E.terms([&](double t) { sum += t; });
    EXPECT_EQ(sum, E.potential());
  }
}

TEST(Observables, EachRodOfACollectionOfOneIsTheTotals) {
  Simulation s(config::to_params(ring("explicit", 1)));
  for (int k = 0; k < 10; ++k) s.step();
  const Observables o = s.observe();
  ASSERT_EQ(o.rods.size(), 1u);
  EXPECT_EQ(o.rods[0].writhe, o.writhe);
  EXPECT_EQ(o.rods[0].twist, o.twist);
  EXPECT_EQ(o.rods[0].link, o.link);
  EXPECT_TRUE(o.pair_links.empty());
  // several rods: the totals are the sums (an open rod: link and writhe not defined)
  Simulation t(config::to_params(ring("explicit", 2)));
  const Observables p = t.observe();
  ASSERT_EQ(p.rods.size(), 2u);
  EXPECT_NEAR(p.twist, p.rods[0].twist + p.rods[1].twist, 1e-12);
  EXPECT_TRUE(std::isnan(p.rods[1].link));
  EXPECT_TRUE(std::isnan(p.link));
  EXPECT_NEAR(p.rods[0].link, 2.0, 1e-9);
}

TEST(Observables, AnOpenRodAloneIsItsOwnTotalsToo) {
  config::Config c = ring("explicit", 1);
  config::apply_override(c, "rod.closed=false");
  config::apply_override(c, "rod.excess_link=0");
  config::validate(c);
  Simulation s(config::to_params(c));
  for (int k = 0; k < 5; ++k) s.step();
  const Observables o = s.observe();
  ASSERT_EQ(o.rods.size(), 1u);
  EXPECT_EQ(o.rods[0].twist, o.twist);
  EXPECT_NE(o.twist, 0.0);
  // not defined for an open rod: NaN in the rod's entry and in the totals alike
  EXPECT_TRUE(std::isnan(o.rods[0].writhe) && std::isnan(o.writhe));
  EXPECT_TRUE(std::isnan(o.rods[0].link) && std::isnan(o.link));
  EXPECT_TRUE(std::isnan(link_drift(o, o)));  // no linking number to conserve
}

TEST(LinkDrift, EachClosedRodsOwnLinkAndEachPairsOrTheTotalWithoutPerRodValues) {
  Observables a, b;
  a.rods = {{0.5, 1.5, 2.0}, {0, 0.2, std::nan("")}};
  a.link = std::nan("");
  a.pair_links = {};
  b = a;
  b.rods[0].link = 2.25;
  b.rods[1].twist = 0.3;
  EXPECT_DOUBLE_EQ(link_drift(b, a), 0.25);  // rod 0's drift; rod 1 is open
  b.pair_links = {1.0};
  a.pair_links = {0.0};
  EXPECT_DOUBLE_EQ(link_drift(b, a), 1.0);  // a passage of one rod through the other
  // an initial row read back from a checkpoint has the columns only: the total link
  Observables c0, c1;
  c0.link = 3.0;
  c1.link = 3.5;
  c1.rods = {{1.0, 2.5, 3.5}};
  EXPECT_DOUBLE_EQ(link_drift(c1, c0), 0.5);
  // one rod: its own link is the total, so the two ways agree bitwise
  Simulation s(config::to_params(ring("explicit", 1)));
  const Observables o0 = s.observe();
  for (int k = 0; k < 10; ++k) s.step();
  const Observables o1 = s.observe();
  Observables columns_only = o0;
  columns_only.rods.clear();
  EXPECT_EQ(link_drift(o1, o0), link_drift(o1, columns_only));
  EXPECT_EQ(link_drift(o1, o0), std::abs(o1.link - o0.link));
}

}  // namespace
}  // namespace ibrod::sim
