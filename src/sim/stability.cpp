#include "sim/stability.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "core/types.hpp"
#include "sim/simulation.hpp"

namespace ibrod::sim {

namespace {

double uniform01(std::mt19937_64& g) { return double(g() >> 11) * 0x1.0p-53; }

// D_k ← R(g(s_k) D³_k) D_k with the drawn g (see the header)
void perturb_twist(rod::RodState& s, const StabilityProbe& p, std::uint64_t index) {
  std::mt19937_64 g(p.seed + index);
  std::vector<double> u(std::size_t(p.modes)), phi(std::size_t(p.modes));
  for (int m = 0; m < p.modes; ++m) {
    u[std::size_t(m)] = 2 * uniform01(g) - 1;
    phi[std::size_t(m)] = 2 * std::numbers::pi * uniform01(g);
  }
  const int n = s.size();
  for (int k = 0; k < n; ++k) {
    const double th = 2 * std::numbers::pi * double(k) / double(n);
    double psi = 0;
    for (int m = 0; m < p.modes; ++m)
      psi += u[std::size_t(m)] * std::sin(double(m + 1) * th + phi[std::size_t(m)]);
    psi *= p.amplitude;
    s.D[k] = rotation(psi * s.D[k].col(2)) * s.D[k];
  }
}

}  // namespace

ProbeOutcome probe_stability(Simulation& sim, const StabilityProbe& p, std::uint64_t index) {
  ProbeOutcome o;
  const double kT = sim.params().kT;
  o.step = sim.step_count();
  o.time_us = sim.time() / 1e-6;
  const Observables before = sim.observe();
  o.E_before_kT = before.E_total_kT;
  o.writhe_before = before.writhe;

  // 1. save
  const rod::RodState saved_rod = sim.rod();
  std::vector<double> scratch;
  const auto u = sim.stepper().whole_velocity(scratch);
  const std::size_t n3 = sim.params().stepper.grid.size();
  std::vector<double> saved_u(3 * n3);
  for (int c = 0; c < 3; ++c) std::copy_n(u[std::size_t(c)], n3, saved_u.begin() + c * n3);
  const std::int64_t saved_step = sim.step_count();
  const double saved_time = sim.time();
  const auto saved_implicit = sim.implicit_state();  // time.scheme = "implicit": its controller

  // 2. perturb, 3. integrate
  perturb_twist(sim.rod(), p, index);
  // until the probe time has passed (whatever steps the scheme takes: with an adaptive Δt the
  // count is not known in advance)
  const double t_end = saved_time + p.time;
  do {
    sim.step();
    ++o.steps;
  } while (sim.time() < t_end - 0.5 * sim.dt());
  o.duration_us = (sim.time() - saved_time) / 1e-6;
  const Observables after = sim.observe();
  o.E_after_kT = after.E_total_kT;
  o.writhe_after = after.writhe;

  // 4. decide
  o.stable = !(o.E_after_kT < o.E_before_kT - p.tolerance / kT);
  if (o.stable) {
    sim.rod() = saved_rod;
    const double* v = saved_u.data();
    sim.stepper().set_whole_velocity({v, v + n3, v + 2 * n3});
    sim.restore_clock(saved_step, saved_time);
    sim.restore_implicit_state(saved_implicit);
  }
  return o;
}

std::string describe(const ProbeOutcome& o) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%s: E_total %.6g -> %.6g kT, Wr %+.4f -> %+.4f over %lld steps from t = %.4f us",
                o.stable ? "stable" : "unstable", o.E_before_kT, o.E_after_kT, o.writhe_before,
                o.writhe_after, static_cast<long long>(o.steps), o.time_us);
  return buf;
}

}  // namespace ibrod::sim
