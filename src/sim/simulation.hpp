#pragma once
// Simulation: parameters, rod state, the stepper and the diagnostics of one trajectory. No I/O
// here (writers live in io/); the run driver calls step() and observe().
#include <cstdint>
#include <string>

#include "integrate/stepper.hpp"
#include "rod/rod.hpp"

namespace ibrod::sim {

/// Everything a trajectory needs, in internal units (g, Å, s).
struct SimParams {
  integrate::StepperParams stepper;
  rod::CircleParams circle;
  double t_end = 1e-6;          ///< s
  double stop_kinetic = 0;      ///< stop when E_K < this (g Å² s⁻²) at an output step; 0: never
  std::int64_t output_every = 1000;  ///< steps between diagnostics
  double kT = 414.2;            ///< g Å² s⁻²
  int closest_min_separation = 20;   ///< pairs at least this many points apart (MODEL §6)
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
};

enum class StopReason { none, end_time, equilibrium };
std::string to_string(StopReason r);

class Simulation {
 public:
  explicit Simulation(const SimParams& p);

  const SimParams& params() const { return p_; }
  const rod::RodState& rod() const { return rod_; }
  rod::RodState& rod() { return rod_; }
  integrate::Stepper& stepper() { return stepper_; }
  const integrate::Stepper& stepper() const { return stepper_; }
  std::int64_t step_count() const { return step_; }
  /// Sets the step counter (and so time()) when a checkpoint restores rod() and the fluid
  /// velocity; nothing else of the state depends on it.
  void restore_step_count(std::int64_t step) { step_ = step; }
  double time() const { return step_ * p_.stepper.fluid.dt; }  ///< s

  /// One time step.
  void step();
  /// Diagnostics of the current state (O(n²) writhe and closest approach: output steps only).
  /// With a distributed fluid every rank must call step() and observe() alike (the kinetic
  /// energy is summed over the ranks).
  Observables observe();
  /// Stop rule, checked at output steps: t ≥ t_end, or E_K below the threshold (after step 0).
  StopReason stop_reason(const Observables& o) const;

 private:
  SimParams p_;
  rod::RodState rod_;
  integrate::Stepper stepper_;
  std::int64_t step_ = 0;
  double electro_circle_ = 0;  ///< E_electro of the initial circle, g Å² s⁻²
};

}  // namespace ibrod::sim
