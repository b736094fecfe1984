#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "config/config.hpp"
#include "config/detail.hpp"
#include "core/text_file.hpp"
#include "core/units.hpp"
#include "interactions/interactions.hpp"
#include "rod/rod.hpp"
#include "rod/rod_set.hpp"

// From the user's configuration (user units) to the simulation's parameters (internal units):
// the cross-key checks, the conversion and the derived quantities of `ibrod check`.
namespace ibrod::config {

using detail::bad;
using detail::fmt;

namespace {
void validate_one(const Config& c);
}

void validate(const Config& c) {
  // each rod as if alone (docs/config.md "Several rods"); an error names its [[rods]] table
  for (const RodConfig& rc : rod_configs(c)) {
    try {
      validate_one(rc.keys);
    } catch (const ConfigError& e) {
      throw ConfigError(rc.where() + e.what());
    }
  }
}

namespace {
void validate_one(const Config& c) {
  if (c.grid_n % 2 != 0)
    bad("grid.n", std::to_string(c.grid_n), "an even integer >= 8 (real-to-complex FFT grid)");
  if (4 * c.grid_kernel_width + 2 > c.grid_n)
    bad("grid.kernel_width", std::to_string(c.grid_kernel_width),
        "an integer m with 4m + 2 <= grid.n = " + std::to_string(c.grid_n) +
            " (the kernel must fit in the grid)");
  const double r0 = rod::circle_radius(c.rod_base_pairs, c.rod_rise_A);
  if (!c.rod_closed) {
    // docs/model.md "Open rods": no link to impose
    if (c.rod_excess_link != 0)
      bad("rod.excess_link", std::to_string(c.rod_excess_link),
          "0 with rod.closed = false (an open rod has free ends: no linking number to impose)");
    // the straight rod plus its hard core must fit in the box
    const double length = (c.rod_base_pairs - 1) * c.rod_rise_A;
    if (length + c.steric_diameter_A >= c.grid_box_A)
      bad("grid.box_A", fmt(c.grid_box_A),
          "a box longer than the open rod: rod.base_pairs = " + std::to_string(c.rod_base_pairs) +
              " at rod.rise_A = " + fmt(c.rod_rise_A) + " gives a straight rod " + fmt(length) +
              " Å long (plus the hard core steric.diameter_A = " + fmt(c.steric_diameter_A) +
              " Å)");
  }
  if (c.rod_closed) {
    // The ring plus its hard core must fit in the box; the key blamed is the one that grew past
    // it: the hard core when the bare ring fits, else the box (naming the ring's keys).
    if (2 * r0 < c.grid_box_A && 2 * r0 + c.steric_diameter_A >= c.grid_box_A)
      bad("steric.diameter_A", fmt(c.steric_diameter_A),
          "a hard core that leaves the ring (diameter " + fmt(2 * r0) +
              " Å) inside the box: steric.diameter_A < grid.box_A - 2 r0 = " +
              fmt(c.grid_box_A - 2 * r0) + " Å");
    if (2 * r0 + c.steric_diameter_A >= c.grid_box_A)
      bad("grid.box_A", fmt(c.grid_box_A),
          "a box larger than the ring: rod.base_pairs = " + std::to_string(c.rod_base_pairs) +
              " at rod.rise_A = " + fmt(c.rod_rise_A) + " gives a ring of diameter " + fmt(2 * r0) +
              " Å (plus the hard core steric.diameter_A = " + fmt(c.steric_diameter_A) + " Å)");
  }
  if (c.grid_box_A > kMaxBoxPerRise * c.rod_rise_A)
    bad("grid.box_A", fmt(c.grid_box_A),
        "at most " + fmt(kMaxBoxPerRise) + " rod.rise_A = " + fmt(kMaxBoxPerRise * c.rod_rise_A) +
            " Å (positions of that size keep 6 digits of a segment in double precision)");
  if (c.time_scheme == "implicit" && c.time_implicit_local_mobility == "overlap" &&
      2 * (4 * c.grid_kernel_width + 2) > c.grid_n)
    bad("time.implicit_local_mobility", "\"overlap\"",
        "\"self\" on a grid of fewer than 2 (4 grid.kernel_width + 2) = " +
            std::to_string(2 * (4 * c.grid_kernel_width + 2)) +
            " points per edge (grid.n = " + std::to_string(c.grid_n) +
            "): a kernel would overlap another one both ways round the "
            "periodic box");
  if (c.time_scheme == "implicit" && c.time_dt_min_ns > c.time_dt_ns)
    bad("time.dt_min_ns", fmt(c.time_dt_min_ns),
        "at most time.dt_ns = " + fmt(c.time_dt_ns) + " ns (the implicit scheme's largest step)");
  // docs/thermal.md, "The implicit step with noise": noise G with the overlap M_loc in the
  // first-order step; the diagonal M_loc heats the sub-kernel modes ×100s, order 2 and GMRES
  // are not derived
  if (c.solvent_thermal && c.time_scheme == "implicit") {
    if (c.time_implicit_local_mobility != "overlap")
      bad("time.implicit_local_mobility", "\"" + c.time_implicit_local_mobility + "\"",
          "\"overlap\" with solvent.thermal = true and time.scheme = \"implicit\" (the diagonal "
          "M_loc samples the sub-kernel modes hundreds of times too hot; docs/thermal.md)");
    if (c.time_implicit_order != 1)
      bad("time.implicit_order", std::to_string(c.time_implicit_order),
          "1 with solvent.thermal = true and time.scheme = \"implicit\" (the noise of the "
          "two-stage step is not derived; docs/thermal.md)");
    if (c.time_implicit_krylov_iterations > 0)
      bad("time.implicit_krylov_iterations", std::to_string(c.time_implicit_krylov_iterations),
          "0 with solvent.thermal = true and time.scheme = \"implicit\" (the noise is derived "
          "for the IMEX step; docs/thermal.md)");
  }
  if (c.time_dt_ns * 1e-3 > c.time_t_end_us)
    bad("time.t_end_us", fmt(c.time_t_end_us),
        "at least one time step (time.dt_ns = " + fmt(c.time_dt_ns) + " ns)");
  // Derived counts, in double so that nothing overflows before it is compared (MODEL: the
  // run takes steps_to_reach(t_end, Δt) steps; rows and frames follow from it).
  const double steps = c.time_t_end_us * 1e3 / c.time_dt_ns;
  if (!(steps <= kMaxSteps))
    bad("time.t_end_us", fmt(c.time_t_end_us),
        "at most " + fmt(kMaxSteps) + " time steps of time.dt_ns = " + fmt(c.time_dt_ns) +
            " ns, i.e. time.t_end_us <= " + fmt(kMaxSteps * c.time_dt_ns * 1e-3) +
            " (asked: " + fmt(steps) + " steps)");
  if (const double bytes = output_estimate_bytes(c); !(bytes <= kMaxOutputBytes)) {
    const bool frames = frame_every(c) > 0 || c.output_frame_every_us > 0;
    const bool in_time = frames ? c.output_frame_every_us > 0 : c.output_every_us > 0;
    bad(frames ? (in_time ? "output.frame_every_us" : "output.frame_every_steps")
               : (in_time ? "output.every_us" : "output.every_steps"),
        in_time ? fmt(frames ? c.output_frame_every_us : c.output_every_us)
                : std::to_string(frames ? frame_every(c) : c.output_every_steps),
        "rows and frames of at most 1 PiB in all to time.t_end_us = " + fmt(c.time_t_end_us) +
            " (asked: " + fmt(bytes / 1099511627776.0) + " TiB); write less often");
  }
  // The discretization represents a twist of at most kMaxTwistPerSegment between neighbours:
  // the circle's twist 2π ΔLk / n and the reference twist Ω³₀ Δs.
  const double max_link = kMaxTwistPerSegment * c.rod_base_pairs / (2 * std::acos(-1.0));
  if (std::abs(c.rod_excess_link) > max_link)
    bad("rod.excess_link", std::to_string(c.rod_excess_link),
        "|ΔLk| <= rod.base_pairs / 4 = " + fmt(std::floor(max_link)) +
            " (a twist of at most π/2 between neighbouring triads; docs/config.md)");
  if (std::abs(c.rod_intrinsic_twist_per_A) * c.rod_rise_A > kMaxTwistPerSegment)
    bad("rod.intrinsic_twist_per_A", fmt(c.rod_intrinsic_twist_per_A),
        "|Ω³₀| <= π / (2 rod.rise_A) = " + fmt(kMaxTwistPerSegment / c.rod_rise_A) +
            " rad/Å (a twist of at most π/2 between neighbouring triads; docs/config.md)");
  for (int i = 0; i < 2; ++i)
    if (std::abs(c.rod_intrinsic_curvature_per_A[i]) * c.rod_rise_A > kMaxTwistPerSegment)
      bad("rod.intrinsic_curvature_per_A", fmt(c.rod_intrinsic_curvature_per_A[i]),
          "|Ω" + std::string(i == 0 ? "¹" : "²") +
              "₀| <= π / (2 rod.rise_A) = " + fmt(kMaxTwistPerSegment / c.rod_rise_A) +
              " rad/Å (a bend of at most π/2 between neighbouring triads)");
  // MODEL §5: sin β must be a sine
  const double a = c.rod_bend_modulus_erg_cm * units::erg_cm;
  const double a3 = c.rod_twist_modulus_erg_cm * units::erg_cm;
  const double b = c.rod_shear_modulus_dyn * units::dyn;
  const double sin_beta = rod::circle_tilt_sin_beta(a, a3, b, r0, c.rod_excess_link);
  // (with rod.moduli_file, to_params checks it at the file's mean moduli)
  if (c.rod_closed && c.rod_moduli_file.empty() && !(std::abs(sin_beta) < 1))
    bad("rod.excess_link", std::to_string(c.rod_excess_link),
        "a link small enough that the twisted circle exists (|sin β| = " + fmt(std::abs(sin_beta)) +
            " >= 1)");
  // rod.rotation_deg and rod.offset_A place the built-in shapes only
  const bool placed =
      std::any_of(c.rod_rotation_deg.begin(), c.rod_rotation_deg.end(),
                  [](double v) { return v != 0; }) ||
      std::any_of(c.rod_offset_A.begin(), c.rod_offset_A.end(), [](double v) { return v != 0; });
  if (placed && !c.rod_initial_shape.empty())
    bad("rod.initial_shape", "\"" + c.rod_initial_shape + "\"",
        "\"\" when rod.rotation_deg or rod.offset_A is set (they place the circle or the straight "
        "rod; a shape from a file is used where it lies)");
}
}  // namespace

namespace {

// Rows of `cols` comma-separated finite numbers, one per rod point ('#' lines and blank lines
// skipped); `what` says what a row holds in the messages; row_problem(v) says what is wrong with a
// row of numbers ("" if nothing).
std::vector<std::vector<double>> read_rows(
    const std::string& key, const std::string& path, int n, std::size_t cols,
    const std::string& what,
    const std::function<std::string(const std::vector<double>&)>& row_problem) {
  std::vector<std::vector<double>> out;
  // a regular file only: a FIFO would block for ever, /dev/zero fill the memory, a directory read
  // as empty (refused before it is opened; core/text_file.hpp)
  if (const std::string why = unreadable_reason(path); !why.empty())
    bad(key, "\"" + path + "\"", "a readable regular file (" + why + ")");
  std::istringstream in(read_text_file(path, key));
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;  // blank lines, comments
    std::stringstream row(line);
    std::string cell;
    std::vector<double> v;
    bool ok = true;
    while (std::getline(row, cell, ',')) {
      char* end = nullptr;
      const double x = std::strtod(cell.c_str(), &end);
      while (end && (*end == ' ' || *end == '\t')) ++end;
      if (end == cell.c_str() || !end || *end != '\0' || !std::isfinite(x)) ok = false;
      v.push_back(x);
    }
    const std::string problem = ok && v.size() == cols && row_problem ? row_problem(v) : "";
    if (!ok || v.size() != cols || !problem.empty())
      bad(key, path,
          "rows of " + std::to_string(cols) + " finite numbers " + what +
              " separated by commas ('#' lines are comments), but line " + std::to_string(line_no) +
              " is \"" + detail::echo(line) + "\"" + (problem.empty() ? "" : " (" + problem + ")"));
    out.push_back(std::move(v));
  }
  if (int(out.size()) != n)
    bad(key, path,
        "one row per rod point, rod.base_pairs = " + std::to_string(n) + " rows, but it has " +
            std::to_string(out.size()));
  return out;
}

}  // namespace

std::vector<Vec3> read_intrinsic_file(const std::string& path, int n) {
  std::vector<Vec3> out;
  if (path.empty()) return out;
  for (const auto& v :
       read_rows("rod.intrinsic_file", path, n, 3, "Ω¹₀, Ω²₀, Ω³₀ (rad/Å)", nullptr))
    out.emplace_back(v[0], v[1], v[2]);
  return out;
}

std::pair<std::vector<Vec3>, std::vector<Vec3>> read_moduli_file(const std::string& path, int n) {
  std::pair<std::vector<Vec3>, std::vector<Vec3>> out;
  if (path.empty()) return out;
  // each value > 0 and, as the scalar keys, within 20 decades of MODEL §1's value
  static const char* names[6] = {"a1", "a2", "a3", "b1", "b2", "b3"};
  static const double ref[6] = {1.3e-19, 1.3e-19, 1.82e-19, 5e-5, 5e-5, 5e-5};
  const auto row_problem = [](const std::vector<double>& v) -> std::string {
    for (int i = 0; i < 6; ++i) {
      if (!(v[i] > 0)) return std::string(names[i]) + " = " + fmt(v[i]) + " is not > 0";
      if (!(v[i] >= ref[i] * 1e-20 && v[i] <= ref[i] * 1e20))
        return std::string(names[i]) + " = " + fmt(v[i]) + " is outside " + fmt(ref[i] * 1e-20) +
               " to " + fmt(ref[i] * 1e20) + ", 20 decades about " + fmt(ref[i]);
    }
    return "";
  };
  for (const auto& v : read_rows("rod.moduli_file", path, n, 6,
                                 "> 0, a1, a2, a3 (erg·cm) and b1, b2, b3 (dyn),", row_problem)) {
    out.first.emplace_back(v[0] * units::erg_cm, v[1] * units::erg_cm, v[2] * units::erg_cm);
    out.second.emplace_back(v[3] * units::dyn, v[4] * units::dyn, v[5] * units::dyn);
  }
  return out;
}

namespace {
// One rod's parameters in internal units (a rod's Config: rod_config for [[rods]]).
rod::RodParams rod_params(const Config& c) {
  using namespace units;
  rod::RodParams r;
  r.n = c.rod_base_pairs;
  r.ds = c.rod_rise_A * angstrom;
  const double a = c.rod_bend_modulus_erg_cm * erg_cm;
  r.a = Vec3(a, a, c.rod_twist_modulus_erg_cm * erg_cm);
  const double b = c.rod_shear_modulus_dyn * dyn;
  r.b = Vec3(b, b, c.rod_stretch_modulus_dyn * dyn);
  r.omega0 = Vec3(c.rod_intrinsic_curvature_per_A[0], c.rod_intrinsic_curvature_per_A[1],
                  c.rod_intrinsic_twist_per_A);
  r.omega0_k = read_intrinsic_file(c.rod_intrinsic_file, c.rod_base_pairs);
  for (std::size_t k = 0; k < r.omega0_k.size(); ++k)  // the scalar keys' bound, per row
    if (r.omega0_k[k].cwiseAbs().maxCoeff() * c.rod_rise_A > kMaxTwistPerSegment)
      bad("rod.intrinsic_file", c.rod_intrinsic_file,
          "|Ω¹₀|, |Ω²₀|, |Ω³₀| <= π / (2 rod.rise_A) = " + fmt(kMaxTwistPerSegment / c.rod_rise_A) +
              " rad/Å in every row (a bend or twist of at most π/2 between neighbouring "
              "triads), but row " +
              std::to_string(k + 1) + " exceeds it");
  r.closed = c.rod_closed;
  std::tie(r.a_k, r.b_k) = read_moduli_file(c.rod_moduli_file, c.rod_base_pairs);
  if (!r.a_k.empty()) {
    // the scalars become the means over the links in use (n closed, n − 1 open): the twisted
    // circle's tilt sin β (docs/config.md "rod.moduli_file")
    const int m = rod::links(r);
    r.a = r.b = Vec3::Zero();
    for (int k = 0; k < m; ++k) {
      r.a += r.a_k[k] / m;
      r.b += r.b_k[k] / m;
    }
    const double r0 = rod::circle_radius(c.rod_base_pairs, c.rod_rise_A);
    const double sin_beta =
        rod::circle_tilt_sin_beta(r.a.x(), r.a.z(), r.b.x(), r0, c.rod_excess_link);
    if (c.rod_closed && !(std::abs(sin_beta) < 1))
      bad("rod.excess_link", std::to_string(c.rod_excess_link),
          "a link small enough that the twisted circle exists at the mean moduli of "
          "rod.moduli_file = \"" +
              c.rod_moduli_file + "\" (|sin β| = " + fmt(std::abs(sin_beta)) + " >= 1)");
  }
  return r;
}

// One rod's initial circle (or straight rod): its link, twist perturbation and centre, the box
// centre moved by rod.offset_A (box edge L, Å).
rod::CircleParams circle_params(const Config& c, double L) {
  rod::CircleParams cp;
  cp.excess_link = c.rod_excess_link;
  cp.perturbation = combined_perturbation(c.rod_perturbation, c.rod_perturbation_random);
  cp.center = Vec3::Constant(0.5 * L);
  for (int d = 0; d < 3; ++d) cp.center[d] += c.rod_offset_A[d] * units::angstrom;
  return cp;
}
}  // namespace

sim::SimParams to_params(const Config& c) {
  using namespace units;
  sim::SimParams p;
  auto& s = p.stepper;
  s.grid.n = c.grid_n;
  s.grid.L = c.grid_box_A * angstrom;
  s.kernel_width = c.grid_kernel_width;
  s.fluid.density = c.solvent_density_g_cm3 * g_per_cm3;
  s.fluid.viscosity = c.solvent_viscosity_poise * poise;
  p.dt = c.time_dt_ns * ns;
  s.fluid.dt = p.dt;
  s.fluid.advection = c.solvent_advection;
  // the rods, resolved once: [rod] alone or each [[rods]] table on top of it (docs/config.md)
  s.rods.clear();
  p.shapes.clear();
  for (const RodConfig& rc : rod_configs(c)) {
    const Config& cr = rc.keys;
    s.rods.push_back(rod_params(cr));
    p.shapes.push_back({circle_params(cr, s.grid.L),
                        rod::rotation_xyz_deg(Vec3(cr.rod_rotation_deg[0], cr.rod_rotation_deg[1],
                                                   cr.rod_rotation_deg[2]))});
  }
  p.kT = kT(c.solvent_temperature_K);
  // MODEL (2.19–2.22): A = q²/(4π ε0 εw), κ = 0.329 √Cs
  s.electro = interactions::electro_params(c.electrostatics_enabled, c.electrostatics_charge_e,
                                           c.electrostatics_dielectric, c.solvent_salt_M,
                                           c.electrostatics_cutoff_debye);
  s.steric.enabled = c.steric_enabled;
  s.steric.diameter = c.steric_diameter_A;
  s.steric.stiffness = c.steric_stiffness_kT_A2 * p.kT;
  // docs/thermal.md: the random stress at kT, keyed by run.seed; the external load
  s.fluid.thermal_kT = c.solvent_thermal ? p.kT : 0.0;
  s.fluid.seed = std::uint64_t(c.run_seed);
  s.thermal_drift = c.solvent_thermal && c.solvent_thermal_drift;
  for (int d = 0; d < 3; ++d) {
    s.external_force[d] = c.external_force_pN[d] * pN;
    s.external_torque[d] = c.external_torque_pN_nm[d] * pN * nm;
  }
  s.threads = c.run_threads;
  s.plan_measure = c.run_fftw_measure;
  p.t_end = c.time_t_end_us * us;
  p.stop_kinetic = c.time_stop_kinetic_kT * p.kT;
  p.stop_power = c.time_stop_power_kT_per_us * p.kT / 1e-6;
  p.stability.enabled = c.time_stability_test;
  p.stability.amplitude = c.time_stability_amplitude_rad;
  p.stability.kick = c.time_stability_kick_A;
  p.stability.time = c.time_stability_probe_us * us;
  p.stability.tolerance = c.time_stability_tolerance_kT * p.kT;
  p.stability.seed = std::uint64_t(c.time_stability_seed);
  {
    int points = 0;
    for (const rod::RodParams& r : s.rods) points += r.n;
    // "auto": the Hessian where it is affordable (it finds the slow instabilities the dynamic
    // test misses, docs/config.md "The stability test"), the two copies above
    const bool hessian =
        c.time_stability_method == "hessian" ||
        (c.time_stability_method == "auto" && points <= sim::StabilityProbe::kAutoHessianPoints);
    p.stability.method =
        hessian ? sim::StabilityProbe::Method::hessian : sim::StabilityProbe::Method::dynamic;
    if (c.time_stability_test && c.time_stability_method == "hessian" &&
        points > sim::StabilityProbe::kMaxHessianPoints)
      bad("time.stability_method", "\"hessian\"",
          "\"dynamic\" for more than " + std::to_string(sim::StabilityProbe::kMaxHessianPoints) +
              " rod points (the run has " + std::to_string(points) +
              "): the Hessian is dense, 6 unknowns a point, and its eigenvalues cost O((6n)³)");
  }
  p.output.rows = c.output_every_steps;
  p.output.frames = frame_every(c);
  p.output.checkpoints = c.output_checkpoint_every_steps;
  // issue 14: in simulated time where asked (a *_us key > 0 takes precedence; frames at −1
  // follow the rows, in time or in steps)
  p.output.rows_every = c.output_every_us * us;
  p.output.frames_every = c.output_frame_every_us * us;
  if (c.output_frame_every_us <= 0 && c.output_frame_every_steps < 0)
    p.output.frames_every = p.output.rows_every;
  p.output.checkpoints_every = c.output_checkpoint_every_us * us;
  // issue 14: the implicit scheme (docs/large_dt.md); its dt_max is p.dt, its automatic
  // max_displacement and dt_min are resolved by sim::Simulation
  p.scheme =
      c.time_scheme == "implicit" ? sim::TimeScheme::implicit_step : sim::TimeScheme::explicit_step;
  p.adaptive.max_displacement = c.time_max_displacement_A * angstrom;
  p.adaptive.energy_tolerance = c.time_energy_tolerance_kT * p.kT;
  p.adaptive.dt_min = c.time_dt_min_ns * ns;
  const bool overlap = c.time_implicit_local_mobility == "overlap";
  p.implicit.local_mobility = overlap ? integrate::ImplicitParams::LocalMobility::overlap
                                      : integrate::ImplicitParams::LocalMobility::self;
  p.implicit.mobility_scale =
      overlap ? c.time_implicit_overlap_scale : c.time_implicit_mobility_scale;
  p.implicit.jacobian_every =
      overlap ? c.time_implicit_overlap_refresh_every : c.time_implicit_jacobian_every;
  p.implicit.refresh_displacement = c.time_implicit_refresh_displacement_A * angstrom;
  p.implicit.krylov_max_iter = c.time_implicit_krylov_iterations;
  p.implicit.krylov_tol = c.time_implicit_krylov_tol;
  // issue 24: the two-stage step and its error control (order 1 has no estimate: off)
  p.implicit.order = c.time_implicit_order;
  p.adaptive.error_tolerance =
      c.time_implicit_order == 2 ? c.time_error_tolerance_A * angstrom : 0.0;
  p.implicit.krylov_error_budget =
      c.time_implicit_krylov_error_share * p.adaptive.error_tolerance;
  return p;
}

double memory_estimate_bytes(const Config& c, int ranks) {
  const double n = c.grid_n;
  // velocity + force (3 real arrays each) + spectrum (3 complex half arrays), split over ranks
  const double fluid = 8.0 * (6 * n * n * n + 2 * 3 * n * n * (n / 2 + 1)) / std::max(ranks, 1);
  // measured at grid.n = 128: 167 MiB resident against 145 MiB of arrays
  const double program = 32.0 * (1 << 20);
  return fluid + 400.0 * c.rod_base_pairs + program;
}

double output_estimate_bytes(const Config& c) {
  const double steps = std::ceil(c.time_t_end_us * 1e3 / c.time_dt_ns);
  const double rows = (c.output_every_us > 0 ? c.time_t_end_us / c.output_every_us
                                             : steps / double(c.output_every_steps)) +
                      1;
  const std::int64_t every = frame_every(c);
  double frames = every > 0 ? steps / double(every) + 1 : 0;
  if (c.output_frame_every_us > 0)
    frames = c.time_t_end_us / c.output_frame_every_us + 1;
  else if (c.output_frame_every_steps < 0 && c.output_every_us > 0)
    frames = rows;
  // docs/outputs.md: a row ≈ 400 bytes of text; a frame 96 n (H5MD) + 270 n (.vtp) bytes, and
  // ≈ 32 N³ more with output.fluid_vti (3 Float64 a grid point, base64)
  const double n = c.grid_n;
  const double frame = 366.0 * c.rod_base_pairs + (c.output_fluid_vti ? 32.0 * n * n * n : 0);
  return rows * 400.0 + frames * frame;
}

std::string derived_report(const Config& c) {
  const auto p = to_params(c);
  const auto& s = p.stepper;
  const rod::RodParams& rod0 = s.rods.front();  // the ring's quantities: the first rod's
  const double h = s.grid.h();
  const double r0 = rod::circle_radius(rod0.n, rod0.ds);
  const double sin_beta =
      rod::circle_tilt_sin_beta(rod0.a[0], rod0.a[2], rod0.b[0], r0, c.rod_excess_link);
  const auto steps = sim::steps_to_reach(p.t_end, p.dt);
  const double N3 = double(s.grid.size());
  std::ostringstream os;
  os.precision(5);
  os << "grid spacing h            = " << h << " Å\n"
     << "kernel width c            = " << c.grid_kernel_width * h << " Å (" << c.grid_kernel_width
     << " h)\n"
     << "rod spacing Δs            = " << rod0.ds << " Å\n"
     << "ring radius r0            = " << r0 << " Å\n"
     << "tilt angle β              = " << std::asin(sin_beta) << " rad\n"
     << "kT                        = " << p.kT << " g Å² s⁻²\n"
     << "Debye length 1/κ          = "
     << (s.electro.law.kappa > 0 ? 1.0 / s.electro.law.kappa : INFINITY) << " Å\n"
     << "Bjerrum length            = "
     << units::bjerrum_length(c.electrostatics_dielectric, c.solvent_temperature_K) << " Å\n"
     << "electrostatic cutoff      = " << s.electro.cutoff << " Å\n"
     << "steric stiffness g        = " << s.steric.stiffness << " g s⁻²\n"
     << "time steps                = " << steps << "\n"
     << "diagnostics rows          = "
     << (p.output.rows_every > 0 ? std::int64_t(p.t_end / p.output.rows_every)
                                 : steps / p.output.rows) +
            1
     << "\n"
     << "memory estimate           = " << memory_estimate_bytes(c) / (1 << 20) << " MiB\n";
  // docs/outputs.md: checkpoint = 3 N³ velocities + 12 n rod numbers; a frame = 4 × n × 3 numbers
  std::int64_t frames = p.output.frames > 0 ? steps / p.output.frames + 1 : 0;
  if (p.output.frames_every > 0) frames = std::int64_t(p.t_end / p.output.frames_every) + 1;
  os << "checkpoint size           = " << (24.0 * N3 + 96.0 * rod0.n) / (1 << 20) << " MiB\n"
     << "trajectory frames         = " << frames << " (H5MD ≈ "
     << frames * 96.0 * rod0.n / (1 << 20) << " MiB, .vtp ≈ " << frames * 270.0 * rod0.n / (1 << 20)
     << " MiB)\n"
     << "output estimate           = " << output_estimate_bytes(c) / (1 << 20)
     << " MiB (rows and frames to t_end)\n";
  return os.str();
}

double stable_dt_limit_ns(const Config& c) {
  // measured (docs/large_dt.md, docs/config.md): the explicit scheme of the 600 bp reference at
  // MODEL §1's moduli and viscosity is stable to 0.22 ns with c = h = 725/64 Å, and to 0.9 ns
  // but not 1.3 ns with c = h = 725/32 Å: the limit grows as c². The implicit scheme is stable
  // to 20× the explicit limit (4.4 ns at the reference).
  // A rod stiffer than MODEL §1's lowers it as 1/stiffness (the explicit update of a stiff spring
  // is stable for Δt < 2/(mobility × stiffness)), each modulus taken per link with
  // rod.moduli_file (the stiffest link). Measured at c = 725/32 Å (docs/config.md): the shear and
  // stretch set the limit (b1 or b3 doubled: unstable at 0.9 and 0.6 ns, stable at 0.45), the
  // bending and twist only beyond 4× (a1, a3 ×4: stable at 0.9 ns; ×8: unstable), so the factor
  // is max(1, b/b_ref, a/(4 a_ref)); a softer rod keeps the measured limit.
  const double c_ref = 725.0 / 64, c_A = c.grid_kernel_width * c.grid_box_A / c.grid_n;
  Vec3 a_max(c.rod_bend_modulus_erg_cm, c.rod_bend_modulus_erg_cm, c.rod_twist_modulus_erg_cm);
  Vec3 b_max(c.rod_shear_modulus_dyn, c.rod_shear_modulus_dyn, c.rod_stretch_modulus_dyn);
  if (!c.rod_moduli_file.empty()) {
    const auto [a_k, b_k] = read_moduli_file(c.rod_moduli_file, c.rod_base_pairs);
    a_max = b_max = Vec3::Zero();
    for (int k = 0; k < rod::half_points(c.rod_base_pairs, c.rod_closed); ++k) {
      a_max = a_max.cwiseMax(a_k[k] / units::erg_cm);
      b_max = b_max.cwiseMax(b_k[k] / units::dyn);
    }
  }
  const double stiffer =
      std::max({1.0, b_max.x() / 5e-5, b_max.y() / 5e-5, b_max.z() / 5e-5,
                a_max.x() / (4 * 1.3e-19), a_max.y() / (4 * 1.3e-19), a_max.z() / (4 * 1.82e-19)});
  const double explicit_limit = 0.22 * (c_A / c_ref) * (c_A / c_ref) / stiffer;
  return c.time_scheme == "implicit" ? 20 * explicit_limit : explicit_limit;
}

std::vector<std::string> check_warnings(const Config& c) {
  std::vector<std::string> w;
  const auto p = to_params(c);
  const double h = p.stepper.grid.h();
  if (c.steric_enabled && h > c.steric_diameter_A)
    w.push_back("the grid spacing h = " + fmt(h) +
                " Å (grid.box_A / grid.n) exceeds the hard-core "
                "diameter steric.diameter_A = " +
                fmt(c.steric_diameter_A) +
                " Å: the fluid cannot resolve strands in contact (raise grid.n)");
  if (const double limit = stable_dt_limit_ns(c); c.time_dt_ns > limit)
    w.push_back("the time step time.dt_ns = " + fmt(c.time_dt_ns) + " ns exceeds " +
                fmt(std::round(limit * 100) / 100) + " ns, the largest step the " + c.time_scheme +
                " scheme was measured stable at for this kernel width (c = " +
                fmt(c.grid_kernel_width * h) +
                " Å; docs/large_dt.md): the run may blow up (lower time.dt_ns" +
                (c.time_scheme == "explicit" ? ", or use time.scheme = \"implicit\")" : ")"));
  // docs/thermal.md, "What the disagreement was": the measured rules of a thermal run
  if (c.solvent_thermal && !c.solvent_thermal_drift)
    w.push_back(
        "solvent.thermal = true with solvent.thermal_drift = false leaves out the "
        "stochastic drift kT ∂·M: the sampled equilibrium is biased (at 16³ the writhe "
        "fluctuations 7–21 % too small, the ring 1 % too small; docs/thermal.md) (set "
        "solvent.thermal_drift = true)");
  if (const double limit = stable_dt_limit_ns(c);
      c.solvent_thermal && c.time_scheme == "explicit" && c.time_dt_ns > 0.25 * limit &&
      c.time_dt_ns <= limit)
    w.push_back("with solvent.thermal = true the time step time.dt_ns = " + fmt(c.time_dt_ns) +
                " ns is more than a quarter of the explicit limit " +
                fmt(std::round(limit * 1000) / 1000) +
                " ns: the stiff stretch and shear modes come out hot by O(Δt) (measured +9 % at "
                "0.37 of the limit, +3 % at 0.19; docs/thermal.md) (use time.dt_ns <= " +
                fmt(std::floor(0.25 * limit * 1000) / 1000) + " ns)");
  // docs/thermal.md, "The geometric stiffness in the filter": with the full-Hessian filter at the
  // midpoint the 100 bp ring is 9-14 % above the Monte-Carlo energies at 1 ns (3.2x the explicit
  // limit, 10 us), 30-54 % at 2 ns; no Monte-Carlo check of the shapes yet
  if (c.solvent_thermal && c.time_scheme == "implicit")
    w.push_back(
        "solvent.thermal = true with time.scheme = \"implicit\" is measured only on the 100 bp "
        "ring: its stretch/shear, bend and twist energies 9-14 % above their Monte-Carlo means at "
        "time.dt_ns = 1 and 30-54 % at 2 (docs/thermal.md, \"The geometric stiffness in the "
        "filter\"); the shapes are not checked against Monte Carlo (keep time.dt_ns within ~3x "
        "the explicit limit, or use time.scheme = \"explicit\")");
  const double r0 = rod::circle_radius(c.rod_base_pairs, c.rod_rise_A);
  const double kappa = p.stepper.electro.law.kappa;
  if (c.electrostatics_enabled && kappa > 0) {
    const double need = 2 * r0 + c.steric_diameter_A + 3.0 / kappa;
    if (c.grid_box_A < need)
      w.push_back("the box grid.box_A = " + fmt(c.grid_box_A) +
                  " Å leaves less than 3 Debye "
                  "lengths (3/κ = " +
                  fmt(3.0 / kappa) + " Å) between the ring (diameter " + fmt(2 * r0) +
                  " Å) and its periodic images: they interact (raise grid.box_A)");
  }
  return w;
}

}  // namespace ibrod::config
