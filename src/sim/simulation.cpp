#include "sim/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "diagnostics/topology.hpp"
#include "sim/rod_problem.hpp"

namespace ibrod::sim {

std::string to_string(StopReason r) {
  switch (r) {
    case StopReason::none:
      return "none";
    case StopReason::end_time:
      return "end_time";
    case StopReason::equilibrium:
      return "equilibrium";
    case StopReason::interrupted:
      return "interrupted";
    case StopReason::blow_up:
      return "blow_up";
    case StopReason::error:
      return "error";
  }
  return "unknown";
}

StopReason stop_reason_from(const std::string& name) {
  for (StopReason r : {StopReason::none, StopReason::end_time, StopReason::equilibrium,
                       StopReason::interrupted, StopReason::blow_up, StopReason::error})
    if (to_string(r) == name) return r;
  return StopReason::error;
}

std::string to_string(TimeScheme s) {
  return s == TimeScheme::implicit_step ? "implicit" : "explicit";
}

std::int64_t steps_to_reach(double t_end, double dt) {
  return std::int64_t(std::ceil(t_end / dt - 0.5));
}

namespace {
SimParams checked(SimParams p) {
  if (!(p.dt > 0) || !(p.t_end > 0))
    throw std::invalid_argument("Simulation: dt and t_end must be positive");
  if (p.output.rows <= 0 || p.output.frames < 0 || p.output.checkpoints < 0 ||
      !(p.output.rows_every >= 0) || !(p.output.frames_every >= 0) ||
      !(p.output.checkpoints_every >= 0))
    throw std::invalid_argument(
        "Simulation: output intervals must be positive (frames, "
        "checkpoints: or 0)");
  p.stepper.fluid.dt = p.dt;  // the fluid's Δt is the simulation's
  if (p.stepper.fluid.thermal_kT > 0) {
    // (the implicit scheme takes noise with its overlap M_loc at order 1 only: ImplicitStepper
    // throws otherwise, config::to_params refuses it first naming the keys)
    // docs/thermal.md: with noise the fluid never comes to rest, so the kinetic-energy
    // equilibrium rule (and the stability test it triggers) is off; a run ends at t_end
    p.stop_kinetic = 0;
    p.stop_power = 0;
    p.stability.enabled = false;
  }
  if (p.stepper.rods.empty() || p.shapes.size() != p.stepper.rods.size())
    throw std::invalid_argument("Simulation: one rod at least, and one initial shape per rod");
  if (p.scheme == TimeScheme::implicit_step) {
    if (p.stepper.distributed)
      throw std::invalid_argument("Simulation: the implicit scheme runs on one process only");
    integrate::AdaptiveDtParams& a = p.adaptive;
    a.dt_max = p.dt;
    if (!(a.dt_min > 0)) a.dt_min = 1e-3 * p.dt;
    a.dt_min = std::min(a.dt_min, p.dt);
    if (!(a.max_displacement > 0)) {
      // the pair forces stay explicit: a step moves no point by more than a fifth of the
      // shorter of their ranges (Debye length, hard-core diameter)
      double range = HUGE_VAL;
      for (const rod::RodParams& r : p.stepper.rods) range = std::min(range, r.ds * 10);
      if (p.stepper.electro.enabled && p.stepper.electro.law.kappa > 0)
        range = 1 / p.stepper.electro.law.kappa;
      if (p.stepper.steric.enabled) range = std::min(range, p.stepper.steric.diameter);
      a.max_displacement = 0.2 * range;
    }
    // the error estimate counts a triad's turn as the move of the rod's surface (issue 24)
    if (p.stepper.steric.enabled && p.stepper.steric.diameter > 0)
      p.implicit.rotation_length = 0.5 * p.stepper.steric.diameter;
  }
  return p;
}
// One rod's initial shape (rod::initial_shape: the twisted circle or the straight rod), turned
// about its centroid by R.
rod::RodState shape_of(const rod::RodParams& rp, const SimParams::Shape& shape) {
  rod::RodState s = rod::initial_shape(rp, shape.circle);
  if (!shape.rotation.isIdentity(0)) rod::place(s, shape.rotation, Vec3::Zero());
  return s;
}

}  // namespace

rod::RodState initial_state(const SimParams& p) {
  rod::RodState s;
  rod::for_each_range(p.stepper.rods, [&](std::size_t r, const rod::RodRange&) {
    rod::append(s, shape_of(p.stepper.rods[r], p.shapes.at(r)));
  });
  return s;
}

Simulation::Simulation(const SimParams& p)
    : p_(checked(p)), rod_(initial_state(p_)), system_(p_.stepper) {
  const std::vector<rod::RodRange>& ranges = rod_ranges();
  // docs/thermal.md: with noise a segment's thermal stretch alone may pass 50 %
  for (const rod::RodParams& r : rods())
    tolerances_.push_back(spacing_tolerance(r, p_.stepper.fluid.thermal_kT));
  // MODEL §6: the electrostatic energy is also reported relative to the circle at the same salt.
  // The unperturbed circle (perturbation only rotates triads, so X is the same); for an open rod
  // the straight rod. Several rods: the sum of each rod's own shape alone (rods placed anywhere,
  // even on top of each other before rod.initial_shape moves them, give the same reference).
  if (p_.stepper.electro.enabled)
    for (const rod::RodRange& g : ranges)
      electro_circle_ += system_.electrostatics().energy(
          std::span<const Vec3>(rod_.X).subspan(std::size_t(g.offset), std::size_t(g.n)));
  if (p_.scheme == TimeScheme::implicit_step) {
    auto imp = std::make_unique<integrate::ImplicitIntegrator>(system_, p_.implicit, p_.adaptive);
    implicit_ = imp.get();
    scheme_ = std::move(imp);
  } else {
    scheme_ = std::make_unique<integrate::Stepper>(system_);
  }
}

void Simulation::set_t_end(double t_end) {
  if (!(t_end > 0) || !std::isfinite(t_end))
    throw std::invalid_argument("Simulation: t_end must be positive and finite");
  p_.t_end = t_end;
}

std::string Simulation::start_problem() const {
  return rods_state_problem(rods(), rod_, p_.stepper.grid.L);
}

std::string Simulation::state_check() const { return rods_problem(rods(), rod_, tolerances_); }

Snapshot Simulation::snapshot(bool with_velocity) const {
  Snapshot s;
  s.rod = rod_;
  if (with_velocity) {
    std::vector<double> scratch;
    const auto u = system_.whole_velocity(scratch);  // collective when distributed
    if (u[0]) {
      const std::size_t n3 = p_.stepper.grid.size();
      s.velocity.resize(3 * n3);
      for (int c = 0; c < 3; ++c) std::copy_n(u[std::size_t(c)], n3, s.velocity.begin() + c * n3);
    }
  }
  s.step = step_;
  s.time = time_;
  if (implicit_) s.implicit = implicit_->state();
  return s;
}

void Simulation::restore(const Snapshot& s) {
  rod_ = s.rod;
  const std::size_t n3 = p_.stepper.grid.size();
  if (s.velocity.size() != 3 * n3)
    throw std::invalid_argument("Simulation::restore: a velocity of " +
                                std::to_string(s.velocity.size()) + " values, the grid needs " +
                                std::to_string(3 * n3));
  const double* v = s.velocity.data();
  system_.set_whole_velocity({v, v + n3, v + 2 * n3});
  step_ = s.step;
  time_ = s.time;
  prev_time_ = s.time;
  if (implicit_ && s.implicit.next_dt > 0) implicit_->restore(s.implicit);
}

void Simulation::set_rod_state(rod::RodState s, const std::string& what) {
  if (const std::string bad = rods_state_problem(rods(), s, p_.stepper.grid.L); !bad.empty())
    throw std::invalid_argument(what + ": " + bad);
  rod_ = std::move(s);
  scheme_->refresh();
}

namespace {
// the index of the last multiple of `every` at or before t (a multiple reached to round-off
// counts: time accumulates step by step)
double multiples(double t, double every) { return std::floor(t / every + 1e-9); }
}  // namespace

bool Simulation::due(std::int64_t steps, double every) const {
  if (every > 0) return step_ > 0 && multiples(time_, every) > multiples(prev_time_, every);
  return steps > 0 && step_ % steps == 0;
}

bool Simulation::on_schedule(std::int64_t steps, double every) const {
  if (every > 0) {
    if (step_ == 0) return true;
    if (scheme_->adaptive()) return std::abs(time_ / every - std::round(time_ / every)) <= 1e-9;
    return multiples(time_, every) > multiples(time_ - p_.dt, every);
  }
  return steps > 0 && step_ % steps == 0;
}

double Simulation::time_to_next_output() const {
  double left = HUGE_VAL;
  for (double every : {p_.output.rows_every, p_.output.frames_every, p_.output.checkpoints_every})
    if (every > 0) left = std::min(left, (multiples(time_, every) + 1) * every - time_);
  return left;
}

void Simulation::step() {
  prev_time_ = time_;
  // an adaptive step lands on t_end, and on each multiple of an output interval in simulated
  // time (a stability probe may step beyond t_end: no cap there); a fixed step takes its Δt
  const double left = p_.t_end - time_;
  double cap = left > 0 ? left : HUGE_VAL;
  cap = std::max(std::min(cap, time_to_next_output()), p_.adaptive.dt_min);
  system_.set_noise_step(std::uint64_t(step_));  // the noise of step n: resumes draw alike
  time_ += scheme_->advance(rod_, cap);
  ++step_;
}

Observables Simulation::observe() {
  const double kT = p_.kT;
  Observables o;
  o.step = step_;
  o.time_us = time() / 1e-6;
  const integrate::StepEnergies E = system_.energies(rod_);
  o.E_bend_kT = E.elastic.bend / kT;
  o.E_twist_kT = E.elastic.twist / kT;
  o.E_stretch_kT = E.elastic.stretch / kT;
  o.E_electro_kT = E.electro / kT;
  if (p_.stepper.electro.enabled) o.dE_electro_kT = (E.electro - electro_circle_) / kT;
  o.E_steric_kT = E.steric / kT;
  o.E_kinetic_kT = system_.fluid_kinetic_energy() / kT;  // collective when distributed
  o.E_total_kT = E.potential_kT(kT) + o.E_kinetic_kT;    // the one sum (StepEnergies::terms)

  // each rod's own (o.rods, always filled), summed (a sum of writhe(), twist() from +0 is never
  // −0, so one rod's totals are its own values bitwise); the closest approach over each rod's own
  // pairs and every pair of points of different rods; the spacing the mean over all links,
  // folded rod by rod as a weighted mean (no links yet: the rod's own mean)
  const std::vector<rod::RodRange>& ranges = rod_ranges();
  const std::span<const Vec3> X(rod_.X);
  const std::span<const Mat3> D(rod_.D);
  double closest = HUGE_VAL;
  int links = 0;
  std::vector<Vec3> d1(D.size());  // the directors D¹
  for (std::size_t k = 0; k < D.size(); ++k) d1[k] = D[k].col(0);
  for (const rod::RodRange& g : ranges) {
    const diagnostics::RodTopology t =
        diagnostics::rod_topology(X, d1, g, p_.closest_min_separation);
    o.rods.push_back({t.writhe, t.twist, t.link});
    o.writhe += t.writhe;
    o.twist += t.twist;
    o.link += t.link;
    if (std::isfinite(t.closest)) closest = std::min(closest, t.closest);
    o.bp_spacing_A =
        links == 0 ? t.spacing : (o.bp_spacing_A * links + t.spacing * t.links) / (links + t.links);
    links += t.links;
  }
  rod::for_each_pair(ranges, [&](std::size_t a, std::size_t b) {
    const rod::RodRange &ga = ranges[a], &gb = ranges[b];
    for (int i = 0; i < ga.n; ++i)
      for (int j = 0; j < gb.n; ++j)
        closest = std::min(closest, (X[ga.offset + i] - X[gb.offset + j]).norm());
    if (diagnostics::link_defined(ga) && diagnostics::link_defined(gb))
      o.pair_links.push_back(
          diagnostics::linking_number(X.subspan(std::size_t(ga.offset), std::size_t(ga.n)),
                                      X.subspan(std::size_t(gb.offset), std::size_t(gb.n))));
  });
  o.closest_approach_A = closest;
  return o;
}

Observables::PerRod Observables::rod(std::size_t r) const {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  return r < rods.size() ? rods[r] : PerRod{nan, nan, nan};
}

double link_drift(const Observables& now, const Observables& initial) {
  double drift = std::numeric_limits<double>::quiet_NaN();
  const auto take = [&](double link, double link0) {
    if (!std::isfinite(link)) return;  // an open rod has no linking number to conserve
    drift = std::isnan(drift) ? std::abs(link - link0) : std::max(drift, std::abs(link - link0));
  };
  // each closed rod's own link (a passage between two rings changes neither)
  for (std::size_t r = 0; r < now.rods.size() && r < initial.rods.size(); ++r)
    take(now.rods[r].link, initial.rods[r].link);
  if (initial.rods.empty()) take(now.link, initial.link);  // the initial row of a checkpoint
  // and each pair's linking number: one rod passing through another changes it
  for (std::size_t q = 0; q < now.pair_links.size() && q < initial.pair_links.size(); ++q)
    take(now.pair_links[q], initial.pair_links[q]);
  return drift;
}

double Simulation::total_energy_kT() {
  const double kT = p_.kT;
  return system_.energies(rod_).potential_kT(kT) + system_.fluid_kinetic_energy() / kT;
}

StopReason Simulation::stop_reason(const Observables& o) const {
  if (step_ > 0 && o.E_kinetic_kT * p_.kT < p_.stop_kinetic) return StopReason::equilibrium;
  // (NaN before this process's first step: a resumed run decides after a step of its own)
  if (step_ > 0 && p_.stop_power > 0 && std::abs(scheme_->power()) < p_.stop_power)
    return StopReason::equilibrium;
  if (at_end()) return StopReason::end_time;
  return StopReason::none;
}

}  // namespace ibrod::sim
