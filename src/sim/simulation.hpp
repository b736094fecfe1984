#pragma once
// Simulation: parameters, rod state, the system and its time scheme (integrate::System, one
// integrate::Scheme: explicit or implicit) and the diagnostics of one trajectory, and the
// rules of its time loop: the time step Δt, the simulated time (state, advanced by each step and
// restored from checkpoints, never recomputed as step × Δt), the output schedule (rows, frames,
// checkpoints) and the stop rules. No I/O here (file formats live in io/, the loop that writes
// them in driver/Run); the driver calls step(), asks output_due() / frame_due() /
// checkpoint_due() and stop_reason(), and writes.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "diagnostics/topology.hpp"
#include "integrate/implicit.hpp"
#include "integrate/stepper.hpp"
#include "integrate/system.hpp"
#include "rod/rod.hpp"
#include "rod/rod_set.hpp"
#include "sim/stability.hpp"

namespace ibrod::sim {

/// When a run writes: a time-series row every `rows` steps and at the end; a trajectory frame
/// every `frames` steps and at the end (0: none); a checkpoint every `checkpoints` steps (0: only
/// at the start, at the end and on a signal). Each may instead be in simulated time (issue 14:
/// `*_every` > 0, s, takes precedence over the step count): due at the first step that reaches
/// or passes each multiple of the interval. The implicit scheme shortens the step that would
/// pass one, so that its rows, frames and checkpoints fall on the multiples exactly.
struct OutputSchedule {
  std::int64_t rows = 1000;
  std::int64_t frames = 1000;
  std::int64_t checkpoints = 10000;
  double rows_every = 0;         ///< s; 0: by steps
  double frames_every = 0;       ///< s; 0: by steps
  double checkpoints_every = 0;  ///< s; 0: by steps
};

/// The time scheme (`time.scheme`): MODEL §4's explicit step (the reference), or the implicit
/// Stokes-limit step with an adaptive Δt (issue 14, docs/large_dt.md).
enum class TimeScheme { explicit_step, implicit_step };
std::string to_string(TimeScheme s);  ///< "explicit", "implicit"

/// Everything a trajectory needs, in internal units (g, Å, s).
struct SimParams {
  integrate::StepperParams stepper;  ///< its fluid.dt is set from dt by Simulation
  /// A rod's initial shape: the twisted circle (closed) or the straight rod (open) of `circle`
  /// (its centre, link and twist perturbation), turned about its centroid by `rotation`
  /// (rod.rotation_deg).
  struct Shape {
    rod::CircleParams circle;
    Mat3 rotation = Mat3::Identity();
  };
  /// One per rod of stepper.rods, in the same order.
  std::vector<Shape> shapes{Shape{}};
  TimeScheme scheme = TimeScheme::explicit_step;
  /// implicit only: the scheme's knobs, and the controller's (its dt_max is set from dt; a
  /// dt_min ≤ 0 becomes 1e-3 dt, a max_displacement ≤ 0 becomes 0.2 min(1/κ, D))
  integrate::ImplicitParams implicit;
  integrate::AdaptiveDtParams adaptive;
  double dt = 1e-10;        ///< time step Δt, s (implicit: the largest and the first)
  double t_end = 1e-6;      ///< s
  double stop_kinetic = 0;  ///< stop when E_K < this (g Å² s⁻²) at an output step; 0: never
  /// stop when |the power of the rods' loads| (integrate::Scheme::power) < this (g Å² s⁻³) at an
  /// output step; 0: never. Either rule calls the state an equilibrium (and so the stability test)
  double stop_power = 0;
  StabilityProbe stability;  ///< tests a state the kinetic-energy rule calls an equilibrium
  OutputSchedule output;
  double kT = 414.2;                ///< g Å² s⁻²
  int closest_min_separation = 20;  ///< pairs at least this many points apart (MODEL §6)
};

/// One row of the time series (MODEL §6). Energies in kT, time in µs, lengths in Å.
struct Observables {
  std::int64_t step = 0;
  double time_us = 0;
  double E_bend_kT = 0, E_twist_kT = 0, E_stretch_kT = 0;
  double E_electro_kT = 0;   ///< absolute Debye–Hückel energy
  double dE_electro_kT = 0;  ///< minus that of the initial circle at the same salt
  double E_steric_kT = 0, E_kinetic_kT = 0, E_total_kT = 0;
  double writhe = 0, twist = 0, link = 0;
  double closest_approach_A = 0, bp_spacing_A = 0;
  /// Each rod's writhe, twist and link, in the state's order (NaN where not defined: open rods);
  /// the columns above hold their sums (link and writhe NaN if any rod is open; one rod: its
  /// own values), the closest approach over each rod's own pairs and every pair of points of
  /// different rods, the spacing averaged over all links. One rod: one entry, equal to the
  /// columns above.
  struct PerRod {
    double writhe = 0, twist = 0, link = 0;
  };
  std::vector<PerRod> rods;
  /// Rod r's entry; NaNs where the row has none (an initial row read back from a checkpoint).
  PerRod rod(std::size_t r) const;
  /// Several rods: the Gauss linking number of each pair a < b of closed rods, in the order
  /// (0,1), (0,2), …, (1,2), …; a topological invariant like each rod's link (a passage of one
  /// rod through another changes it). Empty for one rod.
  std::vector<double> pair_links;
};

/// The largest drift of a conserved linking number from `initial` to `now`: each closed rod's
/// own link (o.rods) and each pair's (o.pair_links), against the initial row's; where the initial
/// row has no per-rod values (a checkpoint keeps the columns only: after a resume), the total
/// link instead (a collection of one: its rod's link). NaN where none is defined (open rods).
double link_drift(const Observables& now, const Observables& initial);

/// The dynamical state of a trajectory, all that a Simulation of the same parameters needs to go
/// on bitwise as the one it was taken from: what a checkpoint keeps (written and read back on
/// resume) and what the stability test saves and puts back. Taken by Simulation::snapshot() and
/// put back by Simulation::restore().
struct Snapshot {
  rod::RodState rod;  ///< every rod's points and triads (Simulation::rod())
  /// the fluid velocity, [3 N³] Å/s: the u_x block, then u_y, then u_z (GridSpec::index);
  /// empty when not taken (snapshot(false), or an MPI rank other than 0)
  std::vector<double> velocity;
  std::int64_t step = 0;
  double time = 0;  ///< simulated time, s
  /// time.scheme = "implicit": the step controller's next Δt and run of accepted steps;
  /// next_dt ≤ 0 for the explicit scheme (none)
  integrate::ImplicitIntegrator::State implicit{-1, 0, std::nullopt};
};

/// Why a run stopped (summary.json's stop_reason, the checkpoint's): none while it runs.
enum class StopReason { none, end_time, equilibrium, interrupted, blow_up, error };
std::string to_string(StopReason r);
/// The reason named by to_string (ConfigError-free: an unknown name is StopReason::error).
StopReason stop_reason_from(const std::string& name);

/// The end-of-run rule: the number of steps of Δt that reach t_end (t_end = k Δt gives exactly
/// k steps; half a step of tolerance).
std::int64_t steps_to_reach(double t_end, double dt);

/// The built-in initial state of p (each rod's twisted circle or straight rod, placed, laid end to
/// end): the state a Simulation of p starts from, without building one (no fluid).
rod::RodState initial_state(const SimParams& p);

class Simulation {
 public:
  /// Builds the initial state (the twisted circle of p.circle, or each rod's shape placed in
  /// turn). Throws std::invalid_argument for a non-positive Δt or output interval.
  explicit Simulation(const SimParams& p);

  const SimParams& params() const { return p_; }
  /// Every rod's parameters, in the state's order (one for a run of one rod).
  const std::vector<rod::RodParams>& rods() const { return system_.rods(); }
  /// Where each rod lies in rod() (rod::RodRange).
  const std::vector<rod::RodRange>& rod_ranges() const { return system_.ranges(); }
  /// Whether the collection's link and writhe are defined (diagnostics::link_defined of every
  /// rod; they are the sums of each rod's), so the progress lines and summary.json report them;
  /// else "not defined".
  bool link_defined() const { return diagnostics::link_defined(rod_ranges()); }
  /// What is wrong with the state, "" if nothing (sim::rods_problem: each rod's spacing, triads,
  /// finiteness; the spacing tolerance widened for thermal noise).
  std::string state_check() const;
  /// What is wrong with the state as a start, "" if nothing: sim::rods_state_problem (each rod's
  /// count, spacing, triads, handedness; with several rods also two rods closer than half a rise,
  /// O(n²)). The driver asks before the first step.
  std::string start_problem() const;
  const rod::RodState& rod() const { return rod_; }
  rod::RodState& rod() { return rod_; }
  /// The system the scheme steps through (the fluid, the coupling, the force terms).
  integrate::System& system() { return system_; }
  const integrate::System& system() const { return system_; }
  std::int64_t step_count() const { return step_; }
  double time() const { return time_; }  ///< simulated time, s
  double dt() const { return p_.dt; }    ///< time step, s (implicit: the largest)
  /// The Δt the next step will try (explicit: dt(); implicit: the controller's), s.
  double next_dt() const { return implicit_ ? implicit_->state().next_dt : p_.dt; }
  /// The implicit scheme (nullptr for the explicit one).
  integrate::ImplicitIntegrator* implicit() { return implicit_; }
  const integrate::ImplicitIntegrator* implicit() const { return implicit_; }
  /// The dynamical state (Snapshot): rod, fluid velocity (with_velocity; collective when the
  /// fluid is distributed: the whole velocity on rank 0 only), clock and the implicit scheme's
  /// controller.
  Snapshot snapshot(bool with_velocity = true) const;
  /// Puts a Snapshot back (a checkpoint's on resume, the stability test's saved state): the rod
  /// as it is (no check), the fluid velocity (every rank passes the whole velocity; collective),
  /// the step counter and simulated time, and the implicit controller (when next_dt > 0; K is
  /// then refreshed at the next step).
  void restore(const Snapshot& s);
  /// To be called where a checkpoint is written, so that the run and its resumption refresh the
  /// implicit scheme's stiffness at the same step (resume stays bitwise). No-op for the explicit
  /// scheme.
  void checkpoint_taken() { scheme_->checkpoint_taken(); }
  /// Moves the end of the time (t_end, s; > 0): a run continued in segments (the Python module's
  /// `run(steps=…)`, driver::Run::set_end_time). Throws std::invalid_argument if not positive.
  void set_t_end(double t_end);
  /// Replaces the rod's state (an initial shape from a file, the Python module's set_state):
  /// throws std::invalid_argument naming what is wrong (sim::state_problem: a count of points
  /// other than rod.base_pairs, a non-finite value, a spacing off Δs by more than 50 %, a triad
  /// off orthonormal by more than 1e-3 or left-handed); `what` heads the message. The
  /// implicit scheme refreshes its stiffness at the next step. dE_electro stays relative to the
  /// initial circle.
  void set_rod_state(rod::RodState s, const std::string& what = "set_state");

  /// One time step: the state and the time advance by Δt (implicit: by the accepted step,
  /// never past t_end).
  void step();

  /// Whether the simulated time has reached t_end, with half a step of tolerance (the
  /// end-of-run rule: t_end = k Δt stops after exactly k steps; steps_to_reach). Implicit: the
  /// last step lands on t_end (to round-off).
  bool at_end() const {
    return scheme_->adaptive() ? time_ >= p_.t_end * (1 - 1e-12) : time_ >= p_.t_end - 0.5 * p_.dt;
  }
  /// The step at which at_end() becomes true at the present Δt (progress lines, estimates).
  std::int64_t end_step() const {
    if (at_end()) return step_;
    return step_ + std::max<std::int64_t>(1, steps_to_reach(p_.t_end - time_, next_dt()));
  }
  /// Whether the current step is an output step: a time-series row is due (every
  /// output.rows steps, and at the end).
  bool output_due() const { return due(p_.output.rows, p_.output.rows_every) || at_end(); }
  /// Whether a trajectory frame is due at the current step (`stopping`: the run stops here).
  bool frame_due(bool stopping) const {
    const bool any = p_.output.frames > 0 || p_.output.frames_every > 0;
    return any && (due(p_.output.frames, p_.output.frames_every) || stopping);
  }
  /// Whether the current step is on the row / frame schedule proper (not written only because
  /// the run stopped here): what an extended run keeps of the rows and frames it resumes after.
  bool row_on_schedule() const { return on_schedule(p_.output.rows, p_.output.rows_every); }
  bool frame_on_schedule() const { return on_schedule(p_.output.frames, p_.output.frames_every); }
  /// Whether a checkpoint is due at the current step (`stopping`: the run stops here).
  bool checkpoint_due(bool stopping) const {
    return due(p_.output.checkpoints, p_.output.checkpoints_every) || stopping;
  }
  /// Diagnostics of the current state (O(n²) writhe and closest approach: output steps only).
  /// With a distributed fluid every rank must call step() and observe() alike (the kinetic
  /// energy is summed over the ranks).
  Observables observe();
  /// E_total of observe() (the same terms, summed in the same order, so the same number) without
  /// the O(n²) diagnostics: cheap enough for every few steps.
  double total_energy_kT();
  /// The power of the rods' loads in the latest step (integrate::Scheme::power), kT/µs; NaN
  /// before this object's first step.
  double power_kT_per_us() const { return scheme_->power() * 1e-6 / p_.kT; }
  /// The stop rules, checked at output steps (o: the row of the current step): E_K below its
  /// threshold, or the power of the loads below its (when set), after step 0 (equilibrium), else
  /// the end of the time (end_time), else none.
  StopReason stop_reason(const Observables& o) const;

 private:
  /// Due at this step: every `steps` steps (0: never), or, with `every` > 0 (s), when the last
  /// step reached or passed a multiple of `every`.
  bool due(std::int64_t steps, double every) const;
  /// due() from the clock alone (no previous time: after a resume): the implicit scheme lands
  /// on the multiples, the explicit one passed one in its last step of Δt.
  bool on_schedule(std::int64_t steps, double every) const;
  /// The simulated time left to the next multiple of an interval in simulated time (HUGE_VAL
  /// without one): the implicit scheme's step is capped by it.
  double time_to_next_output() const;
  SimParams p_;
  std::vector<double> tolerances_;  ///< each rod's spacing tolerance (state_check)
  rod::RodState rod_;
  integrate::System system_;
  std::unique_ptr<integrate::Scheme> scheme_;          // explicit Stepper or ImplicitIntegrator
  integrate::ImplicitIntegrator* implicit_ = nullptr;  // scheme_, time.scheme = "implicit"
  std::int64_t step_ = 0;
  double time_ = 0;            ///< s
  double prev_time_ = 0;       ///< s, before the last step (schedules in simulated time)
  double electro_circle_ = 0;  ///< E_electro of the initial circle, g Å² s⁻²
};

}  // namespace ibrod::sim
