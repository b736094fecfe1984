#pragma once
// The user's configuration: a TOML file plus `--set section.key=value` overrides, in user units
// (Å, ns, µs, kT, mol/L, poise, erg·cm, dyn; each key's unit is in its name or in `describe()`).
// Every key has a default (the reference parameters of MODEL §1); unknown keys and invalid
// values throw ConfigError naming the key, the value and what is allowed.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "rod/perturbation.hpp"
#include "sim/simulation.hpp"

namespace ibrod::config {

// Bounds on what a run may ask for (docs/config.md, "Bounds"); validate() refuses beyond them.
inline constexpr double kMinDtNs = 1e-6;   ///< time.dt_ns at least 1 fs
inline constexpr double kMaxDtNs = 1e6;    ///< time.dt_ns at most 1 ms
inline constexpr double kMaxSteps = 1e12;  ///< time steps t_end/Δt (int64 with a wide margin)
inline constexpr double kMaxOutputBytes = 1125899906842624.0;  ///< 1 PiB of rows and frames
/// Largest twist between neighbouring triads, rad: the twist strain is 2 sin(θ/2)/Δs, which is
/// within 10% of θ/Δs for |θ| ≤ π/2 and not invertible past π (rod/rod.cpp eval_half).
inline constexpr double kMaxTwistPerSegment = 1.5707963267948966;
/// grid.box_A / rod.rise_A at most: positions of size L keep ≥ 6 digits of a segment Δs.
inline constexpr double kMaxBoxPerRise = 1e9;

struct Config {
  // [grid]
  int grid_n = 64;            ///< grid.n: points per box edge (even, ≥ 8)
  double grid_box_A = 725.0;  ///< grid.box_A: periodic box edge, Å
  int grid_kernel_width = 1;  ///< grid.kernel_width: c/h, positive integer
  // [time]
  double time_dt_ns = 0.1;     ///< time.dt_ns: Δt, ns
  double time_t_end_us = 0.5;  ///< time.t_end_us: simulated time, µs
  double time_stop_kinetic_kT =
      1e-12;  ///< time.stop_kinetic_kT: stop when E_K below, kT (0: never)
  double time_stop_power_kT_per_us = 0;  ///< time.stop_power_kT_per_us: stop when |Σ F·U| below
  bool time_stability_test = true;       ///< test a state before calling it an equilibrium
  double time_stability_amplitude_rad = 0.05;  ///< twist perturbation of the test, rad
  double time_stability_kick_A = 1.0;          ///< out-of-plane position kick of the test, Å
  double time_stability_probe_us = 2.0;        ///< how long both copies are integrated, µs
  double time_stability_tolerance_kT = 1e-6;   ///< kicked below continuation by more: unstable, kT
  std::int64_t time_stability_seed = 1;        ///< seed of the test's perturbation
  /// "auto" ("hessian" up to StabilityProbe::kAutoHessianPoints rod points, else "dynamic"),
  /// "dynamic" (two copies) or "hessian"
  std::string time_stability_method = "auto";
  std::string time_scheme = "explicit";        ///< time.scheme: "explicit" | "implicit" (issue 14)
  double time_max_displacement_A = 0;       ///< implicit: largest point move per step, Å (0: auto)
  double time_energy_tolerance_kT = 1e-6;   ///< implicit: allowed energy rise per step, kT
  double time_dt_min_ns = 0;                ///< implicit: smallest step, ns (0: time.dt_ns / 1000)
  double time_implicit_mobility_scale = 8;  ///< implicit: β of M_loc
  /// implicit: M_loc "self" (β × the self mobility, diagonal) or "overlap" (the kernel overlap,
  /// issue 24)
  std::string time_implicit_local_mobility = "self";
  double time_implicit_overlap_scale = 1;        ///< implicit: β of the overlap M_loc
  int time_implicit_overlap_refresh_every = 50;  ///< implicit, overlap: steps between its LUs
  double time_implicit_refresh_displacement_A =
      1;  ///< implicit: refresh W when a point moved this far, Å (0: off)
  int time_implicit_jacobian_every = 1;     ///< implicit: steps between stiffness refreshes
  int time_implicit_krylov_iterations = 0;  ///< implicit: GMRES iterations (0: IMEX)
  double time_implicit_krylov_tol = 1e-2;   ///< implicit: GMRES relative residual
  /// implicit, order 2 with GMRES: the share of time.error_tolerance_A that a stage's residual
  /// may move the rod's points by, in RMS: Δt ‖r‖/√n (0: the relative residual alone)
  double time_implicit_krylov_error_share = 0.0;
  int time_implicit_order = 1;              ///< implicit: 1 (IMEX Euler) or 2 (ROS2), issue 24
  double time_error_tolerance_A = 0.1;  ///< implicit, order 2: local error per step, Å (0: off)
  // [rod]
  int rod_base_pairs = 600;                         ///< rod.base_pairs: rod points n
  int rod_excess_link = 6;                          ///< rod.excess_link: ΔLk (integer)
  std::vector<double> rod_perturbation{1.0};        ///< rod.perturbation: ε_m, m = 1, 2, …, rad
  rod::RandomPerturbation rod_perturbation_random;  ///< rod.perturbation_random: drawn ε_m, added
  double rod_rise_A = 3.4;                          ///< rod.rise_A: Δs, Å
  double rod_bend_modulus_erg_cm = 1.3e-19;         ///< a1 = a2, erg·cm
  double rod_twist_modulus_erg_cm = 1.82e-19;       ///< a3, erg·cm
  double rod_shear_modulus_dyn = 5e-5;              ///< b1 = b2, dyn
  double rod_stretch_modulus_dyn = 5e-5;            ///< b3, dyn
  double rod_intrinsic_twist_per_A = 0.0;           ///< Ω³₀, rad/Å
  std::vector<double> rod_intrinsic_curvature_per_A{0.0, 0.0};  ///< Ω¹₀, Ω²₀, rad/Å
  std::string
      rod_initial_shape;  ///< rod.initial_shape: "" (the twisted circle) or a file (io/rod_shape)
  std::string rod_intrinsic_file;  ///< rod.intrinsic_file: "" or a CSV of per-link Ω¹₀, Ω²₀, Ω³₀
  std::string rod_moduli_file;  ///< rod.moduli_file: "" or a CSV of per-link a1 a2 a3, b1 b2 b3
  bool rod_closed = true;       ///< rod.closed: a closed ring, or an open rod with free ends
  std::vector<double> rod_rotation_deg{0.0, 0.0, 0.0};  ///< rod.rotation_deg: about x, y, z, °
  std::vector<double> rod_offset_A{0.0, 0.0, 0.0};      ///< rod.offset_A: centre − box centre, Å
  /// [[rods]] (docs/config.md "Several rods"): one table per rod, each a list of (rod key without
  /// "rod.", its value as TOML text) set on top of the [rod] keys; empty: one rod, [rod] itself.
  /// rod_config() resolves a table into the Config of that rod.
  std::vector<std::vector<std::pair<std::string, std::string>>> rods;
  /// At most this many [[rods]] tables: each pair of rods has its own linking number (rods.csv),
  /// so the outputs and the pair checks grow as the square of the count.
  static constexpr std::size_t kMaxRods = 1000;
  // [solvent]
  double solvent_salt_M = 0.1;  ///< Cs, mol/L
  double solvent_viscosity_poise = 0.01;
  double solvent_density_g_cm3 = 1.0;
  double solvent_temperature_K = 300.0;
  bool solvent_advection = true;      ///< include the nonlinear advection term
  bool solvent_thermal = false;       ///< thermal fluctuations (random stress; docs/thermal.md)
  bool solvent_thermal_drift = true;  ///< add the stochastic drift kT ∂·M (docs/thermal.md)
  // [external] (docs/thermal.md)
  std::vector<double> external_force_pN{0.0, 0.0, 0.0};      ///< total force on the rod, pN
  std::vector<double> external_torque_pN_nm{0.0, 0.0, 0.0};  ///< torque about its centre, pN·nm
  // [electrostatics]
  bool electrostatics_enabled = true;
  double electrostatics_charge_e = 0.48;    ///< charge per base pair, e
  double electrostatics_dielectric = 77.7;  ///< εw
  double electrostatics_cutoff_debye = 0;   ///< set from interactions::kDefaultCutoffDebye
  // [steric]
  bool steric_enabled = true;
  double steric_diameter_A = 20.0;    ///< D, Å
  double steric_stiffness_kT_A2 = 0;  ///< g, kT/Å²; 0.1 by default (Config())
  // [output]
  std::int64_t output_every_steps = 1000;      ///< output.every_steps: steps between rows
  std::int64_t output_frame_every_steps = -1;  ///< steps between trajectory frames; 0: none;
                                               ///< −1: same as output.every_steps (frame_every())
  std::int64_t output_checkpoint_every_steps = 10000;  ///< steps between checkpoints; 0: only at
                                                       ///< start, end and on SIGINT/SIGTERM
  /// issue 14: the schedule in simulated time (µs; 0: by steps). A *_us key > 0 takes precedence
  /// over its *_steps sibling; output.frame_every_steps = −1 follows the rows either way.
  double output_every_us = 0;
  double output_frame_every_us = 0;
  double output_checkpoint_every_us = 0;
  bool output_fluid_vti = false;       ///< fluid velocity .vti with every frame
  bool output_fluid_velocity = false;  ///< DIR/velocity.npy at the end (io/npy.hpp)
  // [run]
  int run_threads = 0;           ///< 0: OpenMP default (OMP_NUM_THREADS or all cores)
  bool run_fftw_measure = true;  ///< FFTW_MEASURE plans (false: FFTW_ESTIMATE)
  std::int64_t run_seed = 1;     ///< run.seed: key of the thermal noise

  Config();
};

/// Steps between trajectory frames (output.frame_every_steps resolved: −1 → output.every_steps);
/// 0: no trajectory.
std::int64_t frame_every(const Config& c);

/// Rod r's configuration: c with the keys of [[rods]] table r set on top of [rod] (and no
/// [[rods]] of its own); c itself (rods cleared) for r = 0 without [[rods]]. Throws ConfigError
/// naming the table for a key it does not accept.
Config rod_config(const Config& c, int r);
/// Points of all rods together.
int point_count(const Config& c);

/// One rod of the configuration, resolved: its keys and how messages name them.
struct RodConfig {
  Config keys;     ///< rod_config(c, table): [rod] with the table's keys on top (no [[rods]])
  int table = -1;  ///< its [[rods]] table, −1 for [rod] alone
  /// The full path of one of its keys: "rod.<key>" for [rod] alone, "rods.<table>.<key>".
  std::string key(const std::string& k) const;
  /// The heading of its errors: "" for [rod] alone, "[[rods]] table <table>: ".
  std::string where() const;
};
/// The rods of c, resolved once, in the state's order: [rod] alone, or one per [[rods]] table.
/// The driver, the files and the analysis walk this list instead of asking whether c has
/// [[rods]] tables.
std::vector<RodConfig> rod_configs(const Config& c);
/// The rods' layout (rod::RodRange: offset, rod.base_pairs, rod.closed, rod.rise_A as Δs) as
/// rod_configs resolves them, in the state's order, without reading any file (rod.moduli_file):
/// what rod.initial_shape is checked against and the analysis lays out the frames of a run's
/// config.toml by.
std::vector<rod::RodRange> rod_layout(const Config& c);
/// A message why old's rods cannot be continued as c's (a checkpoint's configuration against the
/// resumed one: another count of rods, or a rod of another size or kind, closed or open); ""
/// if they can.
std::string rods_incompatibility(const Config& old, const Config& c);

/// Parse a TOML document (file contents) on top of the defaults.
void apply_toml(Config& c, const std::string& toml_text, const std::string& source_name);
/// Load a TOML file on top of the defaults (an empty path: defaults only).
Config load_config(const std::string& path);
/// Apply one `section.key=value` override; value is TOML (numbers, true/false, [arrays],
/// "strings"). `rods.K.key=value` sets a key of [[rods]] table K (from 0; K = the number of
/// tables appends one).
void apply_override(Config& c, const std::string& assignment);
/// Cross-key checks (ring fits in the box, kernel fits in the grid, …); throws ConfigError.
void validate(const Config& c);
/// The resolved config as a TOML document (every key, with its value).
std::string to_toml(const Config& c);
/// One line per key: name, value, unit and meaning (for `ibrod check` and docs).
std::string describe(const Config& c);

/// "key: old → new; …" for every key whose value differs between the configuration `old_toml`
/// (a run's config.toml or a checkpoint's, read from `source`) and `now`; "" if none. A document
/// this ibrod cannot read is reported as a difference.
std::string config_differences(const std::string& old_toml, const Config& now,
                               const std::string& source);

/// Whether `now` differs from the configuration `old_toml` in a later time.t_end_us alone (the
/// extension of a run: `--resume DIR --set time.t_end_us=T` needs no --force).
bool only_end_time_extended(const std::string& old_toml, const Config& now,
                            const std::string& source);

/// Convert to internal units (g, Å, s) for the simulation.
sim::SimParams to_params(const Config& c);

/// rod.intrinsic_file: the per-link intrinsic strains (Ω¹₀, Ω²₀, Ω³₀ per row, rad/Å; '#' lines
/// and blank lines skipped), exactly n rows of 3 finite numbers; empty for path "". Throws
/// ConfigError naming the key, the file and the offending line or count.
std::vector<Vec3> read_intrinsic_file(const std::string& path, int n);

/// rod.moduli_file: the per-link moduli, exactly n rows of 6 finite numbers > 0 (a1, a2, a3 in
/// erg·cm, b1, b2, b3 in dyn; '#' lines and blank lines skipped), converted to internal units:
/// {a_k, b_k} (g Å³ s⁻², g Å s⁻²); both empty for path "". Throws ConfigError naming the key, the
/// file and the offending line or count.
std::pair<std::vector<Vec3>, std::vector<Vec3>> read_moduli_file(const std::string& path, int n);

/// What `ibrod check` warns of (the run is allowed): a grid spacing larger than the hard core,
/// a time step above the scheme's measured stability limit, a box that leaves the ring's periodic
/// images within a few Debye lengths. One sentence each.
std::vector<std::string> check_warnings(const Config& c);
/// The largest time.dt_ns (ns) the configured scheme was measured stable at, scaled to the kernel
/// width c (∝ c²; 0.22 ns explicit, 4.4 ns implicit at the reference grid; docs/config.md).
double stable_dt_limit_ns(const Config& c);

/// Derived quantities for `ibrod check`: h, c, Δs, r0, 1/κ, Bjerrum length, steps, memory.
std::string derived_report(const Config& c);

/// Bytes one process of a run holds (the fluid's arrays split over `ranks` x-slabs, the rod, and
/// a fixed allowance for the program itself); the "memory estimate" of `ibrod check`.
double memory_estimate_bytes(const Config& c, int ranks = 1);
/// Bytes of time-series rows and trajectory frames (H5MD, .vtp, .vti) a run to t_end writes.
double output_estimate_bytes(const Config& c);

/// What this process may allocate, bytes: the least of physical memory, the cgroup's
/// memory.max, and RLIMIT_AS / RLIMIT_DATA less what is mapped already; `why` names which.
double memory_available_bytes(std::string* why = nullptr);
/// Throws ConfigError naming grid.n (or rod.base_pairs) and the memory needed when
/// memory_estimate_bytes(c, ranks) exceeds memory_available_bytes() (before anything is
/// allocated, so that a run never ends in std::bad_alloc for want of memory it could foresee).
void check_memory(const Config& c, int ranks = 1);

}  // namespace ibrod::config
