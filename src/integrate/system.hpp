#pragma once
// The coupled rod–fluid system apart from the time schemes (issue 25; STYLE.md habit 12): the
// parameters, the fluid (serial, or split over MPI ranks), the IB coupling, the list of force
// terms (each rod's elastic loads on its own range, the electrostatic and steric pair terms, the
// external load) and their energies (StepEnergies, summed once). A time scheme (Scheme: the
// explicit Stepper, the implicit ImplicitIntegrator) advances the rods' state through it and owns
// nothing of it; several schemes may share one System (the benchmark times the explicit step on
// a Simulation's system).
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/grid.hpp"
#include "fluid/distributed_fluid.hpp"
#include "fluid/navier_stokes.hpp"
#include "ib/coupler.hpp"
#include "ib/plane_coupler.hpp"
#include "interactions/interactions.hpp"
#include "rod/rod.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::integrate {

struct StepperParams {
  GridSpec grid;
  int kernel_width = 1;  ///< c/h
  fluid::FluidParams fluid;
  /// The rods (`[rod]`, or one per `[[rods]]` table; docs/model.md "Several rods"), resolved
  /// once at load (config::to_params): their points lie in the state rod after rod
  /// (rod::RodRange). One rod is a collection of one; never empty.
  std::vector<rod::RodParams> rods{rod::RodParams{}};
  interactions::ElectroParams electro;
  interactions::StericParams steric;
  int threads = 0;           ///< OpenMP/FFTW threads, 0 = OpenMP default
  bool plan_measure = true;  ///< FFTW_MEASURE plans (slower start, faster steps)
  /// the fluid split over the ranks of MPI_COMM_WORLD (MPI initialised; see the file comment)
  bool distributed = false;
  /// external load on the rod (`external.force_pN`, `external.torque_pN_nm`; docs/thermal.md):
  /// a total force, g Å s⁻², spread evenly over the points (F/n each), its reaction −F/L³ a
  /// uniform body force on the fluid (the fluid's mean momentum stays constant); and a torque
  /// about the rod's centroid, g Å² s⁻², as point forces ω × (X_k − X̄) with
  /// Σ (X_k − X̄) × (ω × (X_k − X̄)) = torque (they add no net force)
  Vec3 external_force = Vec3::Zero();
  Vec3 external_torque = Vec3::Zero();
  /// with thermal noise (fluid.thermal_kT > 0): add the stochastic drift kT ∂_X·M(X) of the
  /// overdamped limit (docs/thermal.md, "The stochastic drift"): a random finite difference of
  /// the spreading, (kT/δ)[S(X + δW̃/2) − S(X − δW̃/2)]W̃ into the fluid, and U, W interpolated
  /// at the midpoint Xⁿ + (Δt/2)Uⁿ⁺¹ of a predictor step
  bool thermal_drift = false;
};

/// Points of all rods together (the size of the state and of every per-point buffer).
int point_count(const StepperParams& p);

/// The potential energy of a state by term, g Å² s⁻² (System::compute_forces with the forces,
/// System::energies without). The one list of the terms (terms()) that every sum of the
/// potential energy takes: the observables' E_total, Simulation::total_energy_kT and the implicit
/// step's energy check. A new force adds its term here (ARCHITECTURE.md "How to add a force").
struct StepEnergies {
  rod::ElasticEnergy elastic;
  double electro = 0;
  double steric = 0;
  /// f(term) for each term, in the order every sum takes: bend, twist, stretch, electrostatic,
  /// steric.
  template <class F>
  void terms(F&& f) const {
    f(elastic.bend);
    f(elastic.twist);
    f(elastic.stretch);
    f(electro);
    f(steric);
  }
  /// Σ of the terms, g Å² s⁻²
  double potential() const {
    double e = 0;
    terms([&](double t) { e += t; });
    return e;
  }
  /// Σ of the terms each in kT (the time series' unit: the sum of its columns), kT in g Å² s⁻²
  double potential_kT(double kT) const {
    double e = 0;
    terms([&](double t) { e += t / kT; });
    return e;
  }
};

/// The IB coupling as the fluid's plane-by-plane forcing and sampler (src/fluid knows nothing of
/// rods): spreading into each x-plane of the right-hand side, interpolation from each x-plane of
/// the new velocity.
struct PlaneCouplerForcing final : fluid::PlaneForcing {
  const ib::PlaneCoupler& coupler;
  explicit PlaneCouplerForcing(const ib::PlaneCoupler& c) : coupler(c) {}
  void add_plane(int i, std::array<double*, 3> plane) const override {
    coupler.add_plane(i, plane);
  }
};
struct PlaneCouplerSampler final : fluid::PlaneSampler {
  ib::PlaneCoupler& coupler;
  std::size_t points;  ///< sample the first `points` points only (all by default)
  explicit PlaneCouplerSampler(ib::PlaneCoupler& c, std::size_t first = std::size_t(-1))
      : coupler(c), points(first) {}
  void sample_plane(int i, std::array<const double*, 3> plane) const override {
    coupler.sample_plane(i, plane, points);
  }
};

/// Wall time of each phase of the serial step, accumulated over the steps it is passed to
/// (`ibrod bench`: the production step itself, timed phase by phase).
struct StepPhaseTimes {
  static constexpr int kCount = 8;
  static constexpr const char* kNames[kCount] = {
      "rod forces",   "pair forces",     "kernel weights", "rhs+spread+2D FFT",
      "x FFTs+solve", "2D iFFT+interp.", "interp. sums",   "update"};
  double ms[kCount] = {};
};

/// The system: what every time scheme steps through. Buffers are sized in the constructor;
/// compute_forces() allocates nothing.
class System {
 public:
  explicit System(const StepperParams& p);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  const StepperParams& params() const { return p_; }
  /// Every rod's parameters and where each lies in the state, in the state's order.
  const std::vector<rod::RodParams>& rods() const { return rods_; }
  const std::vector<rod::RodRange>& ranges() const { return ranges_; }
  /// Points of all rods together (the size of the state and of every per-point buffer).
  int point_count() const { return int(F_.size()); }

  /// The force terms at s: fills forces() and torques() (elastic, then += the pair terms and the
  /// external load) and returns the energies. phases (serial fluid): adds the wall time of the
  /// rod forces and of the pair forces (StepPhaseTimes 0 and 1).
  StepEnergies compute_forces(const rod::RodState& s, StepPhaseTimes* phases = nullptr);
  /// The energies of s without the forces (each term by its direct sum: the diagnostics' values,
  /// O(n²) for the pair terms). Every term compute_forces() adds is here too.
  StepEnergies energies(const rod::RodState& s) const;
  /// [n] point forces (g Å s⁻²) and torques (g Å² s⁻²) of the latest compute_forces()
  const std::vector<Vec3>& forces() const { return F_; }
  const std::vector<Vec3>& torques() const { return T_; }

  /// The counter of the fluid's thermal noise (fluid::FluidSolver::set_noise_step); the
  /// simulation sets it to its step number before each step.
  void set_noise_step(std::uint64_t s);
  /// The serial fluid solver (throws std::logic_error when StepperParams::distributed).
  fluid::FluidSolver& fluid() { return *serial_fluid(); }
  const fluid::FluidSolver& fluid() const { return *serial_fluid(); }
  /// The serial fluid, or nullptr when distributed; the distributed fluid, or nullptr.
  fluid::FluidSolver* serial_or_null() { return fluid_.get(); }
  fluid::DistributedFluid* distributed_or_null() { return dist_.get(); }

  // The fluid, whichever it is (collective calls when StepperParams::distributed:
  // every rank must make them in the same order).
  /// ½ρ Σ|u|² h³ of the whole grid, g Å² s⁻² (collective; the same bits on every rank)
  double fluid_kinetic_energy() const;
  int fluid_threads() const;
  /// The whole velocity (3 arrays of n³ values, GridSpec::index): the serial solver's own
  /// arrays, or (collective) gathered into `scratch` on rank 0; nullptrs on the other ranks.
  std::array<const double*, 3> whole_velocity(std::vector<double>& scratch) const;
  /// Sets the fluid velocity from the whole grid (every rank passes it; collective).
  void set_whole_velocity(std::array<const double*, 3> u);
  ib::Coupler& coupler() { return coupler_; }
  ib::PlaneCoupler& plane_coupler() { return plane_coupler_; }
  interactions::Electrostatics& electrostatics() { return electro_; }
  const interactions::Electrostatics& electrostatics() const { return electro_; }
  interactions::Steric& steric() { return steric_; }

 private:
  StepperParams p_;
  std::unique_ptr<fluid::FluidSolver> fluid_;      // serial, or
  std::unique_ptr<fluid::DistributedFluid> dist_;  // distributed
  ib::Coupler coupler_;
  ib::PlaneCoupler plane_coupler_;
  interactions::Electrostatics electro_;
  interactions::Steric steric_;
  // each rod's params, range, and a scratch copy of its state, its work and its F, T (one rod
  // is a collection of one: its loads too are computed on its copy and added back)
  std::vector<rod::RodParams> rods_;
  std::vector<rod::RodRange> ranges_;
  std::vector<rod::RodState> rod_state_;
  std::vector<rod::RodWork> rod_work_;
  std::vector<std::vector<Vec3>> rod_F_, rod_T_;
  rod::ElasticEnergy elastic(const rod::RodState& s);  // F_, T_ += every rod's elastic load
  // [n] point forces (g Å s⁻²), torques (g Å² s⁻²)
  std::vector<Vec3> F_, T_;
  const fluid::FluidSolver* serial_fluid() const;
  fluid::FluidSolver* serial_fluid();
  void add_external(const std::vector<Vec3>& X);  // the external force and torque into F_
};

/// A time scheme: advances the rods' state (and the fluid it holds) through a System by one
/// step. The explicit Stepper and the implicit ImplicitIntegrator are the two; Simulation holds
/// one and calls nothing else of it to step.
class Scheme {
 public:
  virtual ~Scheme() = default;
  /// One step: the state moves from t to t + Δt and Δt (s) is returned. An adaptive scheme takes
  /// at most max_dt (s; e.g. the time left to t_end); a fixed-step scheme takes its own Δt.
  virtual double advance(rod::RodState& s, double max_dt) = 0;
  /// Whether the scheme's Δt adapts (and honours max_dt), else it is fixed.
  virtual bool adaptive() const = 0;
  /// The next step starts afresh from the state (a checkpoint written or read, a state set):
  /// what a scheme keeps between steps from the state (the implicit stiffness) is rebuilt.
  virtual void refresh() {}
  /// A checkpoint of the state was just taken: what the scheme keeps between steps is either in
  /// the checkpoint or refreshed here (the default), so that the run and its resumption step
  /// alike.
  virtual void checkpoint_taken() { refresh(); }
  /// The power of the rods' loads in the latest step, Σ_k F_k·U_k + T_k·W_k (g Å² s⁻³), with
  /// the forces and torques the step moved the rods by and the velocities it moved them with:
  /// the rate −dE_pot/dt at which the potential energy goes into the fluid (the dissipation
  /// F·M F of the Stokes limit). NaN before this object's first step (time.stop_power_kT_per_us).
  virtual double power() const = 0;
};

/// Σ_k F_k·U_k + T_k·W_k over the points (g Å² s⁻³ for g Å s⁻², g Å² s⁻², Å s⁻¹, s⁻¹).
double power(std::span<const Vec3> F, std::span<const Vec3> T, std::span<const Vec3> U,
             std::span<const Vec3> W);

}  // namespace ibrod::integrate
