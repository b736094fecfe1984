// Validation tier (CTest label `validation`, minutes each; `ctest --preset validation`): the
// reference parameters of MODEL §1 at the reference grid (64³, c = h, 600 bp), integrated with
// the implicit scheme (time.scheme = "implicit", Δt ≤ 2 ns; docs/large_dt.md): the explicit
// scheme at 0.1 ns needs ~2.5 h of a 2-core machine for this tier, the implicit one minutes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "config/config.hpp"
#include "sim/rod_problem.hpp"
#include "sim/simulation.hpp"

using namespace ibrod;

namespace {

constexpr double kDtNs = 2.0;  // the implicit scheme's largest step

config::Config reference(int excess_link, double salt_M) {
  config::Config c;  // defaults: MODEL §1
  c.rod_excess_link = excess_link;
  c.solvent_salt_M = salt_M;
  c.rod_perturbation = {1.0};
  c.time_scheme = "implicit";
  c.time_dt_ns = kDtNs;
  return c;
}

struct Outcome {
  sim::Observables last;
  double max_link_error = 0;
  double min_closest = 1e300;
};

// Runs until `until(o)` holds at an output step (every `every` steps) or t_max (µs) passes;
// checks the link on the way.
template <class Until>
Outcome run(config::Config c, double t_max_us, int every, Until until) {
  c.time_t_end_us = t_max_us;
  sim::Simulation s(config::to_params(c));
  Outcome out;
  const double dlk = c.rod_excess_link;
  for (;;) {
    for (int i = 0; i < every; ++i) s.step();
    const auto o = s.observe();
    out.last = o;
    out.max_link_error = std::max(out.max_link_error, std::abs(o.link - dlk));
    out.min_closest = std::min(out.min_closest, o.closest_approach_A);
    if (!sim::rod_problem(s.rod(), c.rod_rise_A).empty() || !std::isfinite(o.E_total_kT) ||
        until(o) || o.time_us >= t_max_us)
      break;
  }
  std::printf(
      "  ΔLk = %d, Cs = %g M: t = %.2f µs, Wr = %.4f, Lk = %.6f, closest %.2f Å, spacing "
      "%.4f Å, E_K = %.3e kT\n",
      c.rod_excess_link, c.solvent_salt_M, out.last.time_us, out.last.writhe, out.last.link,
      out.last.closest_approach_A, out.last.bp_spacing_A, out.last.E_kinetic_kT);
  return out;
}

}  // namespace

// MODEL §7, issue 2: above the critical link (≈ 1.24 for these moduli) the twisted circle
// buckles out of plane. Measured (explicit scheme, 0.1 ns): ΔLk = 4 passes Wr = 0.5 at
// t ≈ 3.6 µs. ΔLk = 2 grows far more slowly from a smaller seed (its Wr still decays, 1.7e-4 →
// 3.4e-5, over the first 2.5 µs while the twist perturbation relaxes; growth rate estimated ~6×
// below ΔLk = 4's 1.6/µs), hence the 100 µs window (5e4 implicit steps of ≤ 2 ns).
TEST(Reference, TwistedRingsBuckleOutOfPlaneKeepingTheirLink) {
  for (int dlk : {4, 2}) {
    const auto r = run(reference(dlk, 0.1), dlk == 4 ? 10.0 : 100.0, 50,
                       [](const sim::Observables& o) { return o.writhe > 0.5; });
    EXPECT_GT(r.last.writhe, 0.5) << "ΔLk = " << dlk;
    EXPECT_LT(r.max_link_error, 1e-3) << "ΔLk = " << dlk;
  }
}

// Issue 3: electrostatic repulsion is longer-ranged at low salt, so after the collapse the strands
// stay farther apart and adjacent base pairs are pushed farther apart.
TEST(Reference, LowerSaltKeepsStrandsFartherApart) {
  const double t_us = 30.0;
  const auto high =
      run(reference(3, 0.1), t_us, 100, [](const sim::Observables&) { return false; });
  const auto low =
      run(reference(3, 0.01), t_us, 100, [](const sim::Observables&) { return false; });
  EXPECT_GT(high.last.writhe, 0.5);  // collapsed within the window
  EXPECT_LT(high.max_link_error, 1e-3);
  EXPECT_LT(low.max_link_error, 1e-3);
  EXPECT_GT(low.last.closest_approach_A, high.last.closest_approach_A);
  EXPECT_GT(low.last.bp_spacing_A, high.last.bp_spacing_A);
}
