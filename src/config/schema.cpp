#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include <toml++/toml.h>

#include "config/config.hpp"
#include "config/detail.hpp"
#include "config/toml_error.hpp"
#include "core/error.hpp"
#include "core/text_file.hpp"
#include "core/units.hpp"
#include "interactions/interactions.hpp"

// The schema of the user's configuration: every key, how it is read from TOML or `--set`, how it
// is written back, and its unit and meaning.
namespace ibrod::config {

using detail::bad;
using detail::echo;
using detail::fmt;
using rod::draw_perturbation;
using rod::RandomPerturbation;

Config::Config()
    : electrostatics_cutoff_debye(interactions::kDefaultCutoffDebye),
      // 0.1 kT/Å² as written in config.toml, not interactions::kDefaultStericStiffness (41.419
      // g s⁻², from kT(300 K) rounded to 414.19) converted back, which read 0.0999988652679525
      steric_stiffness_kT_A2(0.1) {}

namespace {

std::string show(const toml::node& n) {
  std::ostringstream os;
  n.visit([&](auto&& v) { os << v; });
  return os.str();
}

// One config key: how to read it from TOML into Config, and how to write it back.
struct Key {
  std::string name;  // "section.key"
  std::string help;  // unit and meaning
  std::function<void(Config&, const toml::node&)> set;
  std::function<void(const Config&, toml::table&)> put;  // into its section table
  std::function<std::string(const Config&)> value;
  bool is_table = false;  // its value is a table whose sub-keys `--set name.sub=v` may set
};

std::string section_of(const std::string& k) { return k.substr(0, k.find('.')); }
std::string leaf_of(const std::string& k) { return k.substr(k.find('.') + 1); }

double as_number(const std::string& key, const toml::node& n, const std::string& allowed) {
  if (auto v = n.value_exact<double>()) return *v;
  if (auto v = n.value_exact<int64_t>()) return double(*v);
  bad(key, show(n), allowed);
}

int64_t as_integer(const std::string& key, const toml::node& n, const std::string& allowed) {
  if (auto v = n.value_exact<int64_t>()) return *v;
  if (auto v = n.value_exact<double>())  // 2.0 is accepted as 2, 2.5 is not
    if (std::isfinite(*v) && std::floor(*v) == *v && std::abs(*v) < 9e15) return int64_t(*v);
  bad(key, show(n), allowed);
}

// A real number in (lo, hi] or [lo, hi] (lo_open picks), finite.
Key real(std::string name, double Config::*m, double lo, bool lo_open, double hi,
         std::string help) {
  std::string allowed = "a number " + std::string(lo_open ? "> " : ">= ") + fmt(lo) +
                        (hi < std::numeric_limits<double>::max() ? " and <= " + fmt(hi) : "");
  Key k;
  k.name = name;
  k.help = help;
  k.set = [=](Config& c, const toml::node& n) {
    const double v = as_number(name, n, allowed + " (" + help + ")");
    if (!std::isfinite(v) || (lo_open ? v <= lo : v < lo) || v > hi)
      bad(name, show(n), allowed + " (" + help + ")");
    c.*m = v;
  };
  k.put = [=](const Config& c, toml::table& t) { t.insert_or_assign(leaf_of(name), c.*m); };
  k.value = [=](const Config& c) { return fmt(c.*m); };
  return k;
}

template <class Int>
Key integer(std::string name, Int Config::*m, int64_t lo, int64_t hi, std::string help) {
  std::string allowed = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  Key k;
  k.name = name;
  k.help = help;
  k.set = [=](Config& c, const toml::node& n) {
    const int64_t v = as_integer(name, n, allowed + " (" + help + ")");
    if (v < lo || v > hi) bad(name, show(n), allowed + " (" + help + ")");
    c.*m = Int(v);
  };
  k.put = [=](const Config& c, toml::table& t) {
    t.insert_or_assign(leaf_of(name), int64_t(c.*m));
  };
  k.value = [=](const Config& c) { return std::to_string(c.*m); };
  return k;
}

Key boolean(std::string name, bool Config::*m, std::string help) {
  Key k;
  k.name = name;
  k.help = help;
  k.set = [=](Config& c, const toml::node& n) {
    auto v = n.value_exact<bool>();
    if (!v) bad(name, show(n), "true or false (" + help + ")");
    c.*m = *v;
  };
  k.put = [=](const Config& c, toml::table& t) { t.insert_or_assign(leaf_of(name), c.*m); };
  k.value = [=](const Config& c) { return std::string(c.*m ? "true" : "false"); };
  return k;
}

Key real_array(std::string name, std::vector<double> Config::*m, double max_abs, std::string help) {
  const std::string allowed =
      "an array of numbers with |value| <= " + fmt(max_abs) + " (" + help + ")";
  Key k;
  k.name = name;
  k.help = help;
  k.set = [=](Config& c, const toml::node& n) {
    const toml::array* a = n.as_array();
    if (!a) bad(name, show(n), allowed);
    std::vector<double> out;
    for (const toml::node& e : *a) {
      const double v = as_number(name, e, allowed);
      if (!std::isfinite(v) || std::abs(v) > max_abs) bad(name, show(n), allowed);
      out.push_back(v);
    }
    c.*m = out;
  };
  k.put = [=](const Config& c, toml::table& t) {
    toml::array a;
    for (double v : c.*m) a.push_back(v);
    t.insert_or_assign(leaf_of(name), a);
  };
  k.value = [=](const Config& c) {
    std::string s = "[";
    for (std::size_t i = 0; i < (c.*m).size(); ++i) s += (i ? ", " : "") + fmt((c.*m)[i]);
    return s + "]";
  };
  return k;
}

const double inf = std::numeric_limits<double>::max();

// A vector of three numbers, each |value| <= max_abs (external.force_pN, external.torque_pN_nm).
Key vec3_key(std::string name, std::vector<double> Config::*m, double max_abs, std::string help) {
  Key k = real_array(name, m, max_abs, help);
  const auto set = k.set;
  k.set = [=](Config& c, const toml::node& n) {
    const toml::array* a = n.as_array();
    if (!a || a->size() != 3)
      bad(name, show(n),
          "an array of three numbers [x, y, z] with |value| <= " + fmt(max_abs) + " (" + help +
              ")");
    set(c, n);
  };
  return k;
}

// A dimensional parameter of the model, within kDecades decades of its reference value (MODEL §1,
// the default) either way. Why 20: a step forms products and quotients of at most about ten such
// parameters (e.g. the kinetic energy ρ u² h³ with u ~ a Δt / (ρ Δs² h³)), so every intermediate
// stays within 10^±200, inside the double range (10^±308) with a margin; and far outside any
// physical value, so no real run is refused. `allow_zero`: 0 is allowed too (switches it off).
constexpr double kDecades = 20;
Key physical(std::string name, double Config::*m, double ref, bool allow_zero, std::string help) {
  // widened by 1e-13 so that the bound as printed (12 digits) is itself accepted
  const double f = std::pow(10.0, kDecades), lo = ref / f * (1 - 1e-13), hi = ref * f * (1 + 1e-13);
  return real(std::move(name), m, allow_zero ? 0 : lo, false, hi, std::move(help));
}

// output.frame_every_steps: −1 (the default) follows output.every_steps; written back resolved, so
// that config.toml holds the number of steps actually used.
Key frame_key() {
  Key k = integer("output.frame_every_steps", &Config::output_frame_every_steps, -1,
                  std::numeric_limits<int64_t>::max(),
                  "steps between trajectory frames (H5MD and ParaView; 0: none, -1: same as "
                  "output.every_steps)");
  // rows in simulated time (output.every_us): −1 stays −1 (frames with every row)
  const auto resolved = [](const Config& c) {
    return c.output_every_us > 0 && c.output_frame_every_steps < 0 ? std::int64_t(-1)
                                                                   : frame_every(c);
  };
  k.put = [=](const Config& c, toml::table& t) {
    t.insert_or_assign("frame_every_steps", int64_t(resolved(c)));
  };
  k.value = [=](const Config& c) { return std::to_string(resolved(c)); };
  return k;
}

// time.scheme: one of a few words (a string key)
Key scheme_key() {
  Key k;
  k.name = "time.scheme";
  k.help =
      "time scheme: \"explicit\" (MODEL §4, the reference) or \"implicit\" (Stokes limit, "
      "implicit stiffness, adaptive Δt ≤ time.dt_ns; docs/large_dt.md)";
  k.set = [](Config& c, const toml::node& n) {
    const auto v = n.value_exact<std::string>();
    if (!v || (*v != "explicit" && *v != "implicit"))
      bad("time.scheme", show(n), "\"explicit\" or \"implicit\"");
    c.time_scheme = *v;
  };
  k.put = [](const Config& c, toml::table& t) { t.insert_or_assign("scheme", c.time_scheme); };
  k.value = [](const Config& c) { return "\"" + c.time_scheme + "\""; };
  return k;
}

// time.stability_method: "auto", "dynamic" or "hessian" (the stability test, docs/config.md)
Key stability_method_key() {
  Key k;
  k.name = "time.stability_method";
  k.help =
      "how the stability test decides: \"dynamic\" (integrate a kicked copy and the "
      "unperturbed one for time.stability_probe_us and compare their energies), \"hessian\" "
      "(the lowest eigenvalue of the total energy's Hessian, less the rigid-body modes: "
      "unstable if a kick of time.stability_kick_A along its mode lowers the energy by more "
      "than time.stability_tolerance_kT; dense, at most 1500 points) or \"auto\" (\"hessian\" "
      "up to 1000 rod points, \"dynamic\" above; docs/config.md)";
  k.set = [](Config& c, const toml::node& n) {
    const auto v = n.value_exact<std::string>();
    if (!v || (*v != "auto" && *v != "dynamic" && *v != "hessian"))
      bad("time.stability_method", show(n), "\"auto\", \"dynamic\" or \"hessian\"");
    c.time_stability_method = *v;
  };
  k.put = [](const Config& c, toml::table& t) {
    t.insert_or_assign("stability_method", c.time_stability_method);
  };
  k.value = [](const Config& c) { return "\"" + c.time_stability_method + "\""; };
  return k;
}

// time.implicit_local_mobility: "self" or "overlap" (issue 24)
Key local_mobility_key() {
  Key k;
  k.name = "time.implicit_local_mobility";
  k.help =
      "implicit: the local mobility M_loc of the implicit solve: \"self\" (the kernel's self "
      "mobility on the diagonal, × time.implicit_mobility_scale) or \"overlap\" (the kernel "
      "overlap, which the Stokes mobility's near-null space shares, × "
      "time.implicit_overlap_scale; docs/large_dt.md)";
  k.set = [](Config& c, const toml::node& n) {
    const auto v = n.value_exact<std::string>();
    if (!v || (*v != "self" && *v != "overlap"))
      bad("time.implicit_local_mobility", show(n), "\"self\" or \"overlap\"");
    c.time_implicit_local_mobility = *v;
  };
  k.put = [](const Config& c, toml::table& t) {
    t.insert_or_assign("implicit_local_mobility", c.time_implicit_local_mobility);
  };
  k.value = [](const Config& c) { return "\"" + c.time_implicit_local_mobility + "\""; };
  return k;
}

// rod.intrinsic_curvature_per_A = [Ω¹₀, Ω²₀]: exactly two numbers (checked before any is set)
Key intrinsic_curvature_key() {
  const std::string name = "rod.intrinsic_curvature_per_A";
  Key k = real_array(name, &Config::rod_intrinsic_curvature_per_A, 1e6,
                     "intrinsic curvatures [Ω¹₀, Ω²₀] about D¹ and D², rad/Å ([0, 0]: straight "
                     "reference)");
  const auto set_array = k.set;
  k.set = [name, set_array, help = k.help](Config& c, const toml::node& n) {
    const toml::array* a = n.as_array();
    if (!a || a->size() != 2)
      bad(name, show(n), "an array of two numbers [Ω¹₀, Ω²₀], rad/Å (" + help + ")");
    set_array(c, n);
  };
  return k;
}

// rod.intrinsic_file: a file name (a string key; "" for none); read by to_params
Key intrinsic_file_key() {
  Key k;
  k.name = "rod.intrinsic_file";
  k.help =
      "per-link intrinsic curvatures and twist: a CSV with one row per rod point, Ω¹₀, Ω²₀, Ω³₀ "
      "in rad/Å (row k: link k → k+1); replaces rod.intrinsic_curvature_per_A and "
      "rod.intrinsic_twist_per_A; \"\": those keys";
  k.set = [](Config& c, const toml::node& n) {
    const auto v = n.value_exact<std::string>();
    if (!v) bad("rod.intrinsic_file", show(n), "a file name in quotes, or \"\" for none");
    c.rod_intrinsic_file = *v;
  };
  k.put = [](const Config& c, toml::table& t) {
    t.insert_or_assign("intrinsic_file", c.rod_intrinsic_file);
  };
  k.value = [](const Config& c) { return "\"" + c.rod_intrinsic_file + "\""; };
  return k;
}

// rod.moduli_file: a file name (a string key; "" for none); read by to_params
Key moduli_file_key() {
  Key k;
  k.name = "rod.moduli_file";
  k.help =
      "per-link moduli: a CSV with one row per rod point, a1, a2, a3 in erg·cm and b1, b2, b3 in "
      "dyn (row k: link k → k+1); replaces rod.bend_modulus_erg_cm, rod.twist_modulus_erg_cm, "
      "rod.shear_modulus_dyn and rod.stretch_modulus_dyn; \"\": those keys";
  k.set = [](Config& c, const toml::node& n) {
    const auto v = n.value_exact<std::string>();
    if (!v) bad("rod.moduli_file", show(n), "a file name in quotes, or \"\" for none");
    c.rod_moduli_file = *v;
  };
  k.put = [](const Config& c, toml::table& t) {
    t.insert_or_assign("moduli_file", c.rod_moduli_file);
  };
  k.value = [](const Config& c) { return "\"" + c.rod_moduli_file + "\""; };
  return k;
}

// rod.initial_shape: a file name (a string key; "" for none)
Key initial_shape_key() {
  Key k;
  k.name = "rod.initial_shape";
  k.help =
      "start from this shape instead of the twisted circle: a run's final_state.csv, or "
      "\"trajectory.h5md@FRAME\" (FRAME from 0, -1 the last); \"\": the circle";
  k.set = [](Config& c, const toml::node& n) {
    const auto v = n.value_exact<std::string>();
    if (!v) bad("rod.initial_shape", show(n), "a file name in quotes, or \"\" for the circle");
    c.rod_initial_shape = *v;
  };
  k.put = [](const Config& c, toml::table& t) {
    t.insert_or_assign("initial_shape", c.rod_initial_shape);
  };
  k.value = [](const Config& c) { return "\"" + c.rod_initial_shape + "\""; };
  return k;
}

// rod.perturbation_random = { modes = M, amplitude = A, seed = S }: an inline table (a Key whose
// value is a table). A partial table changes only the sub-keys it names, so that `--set
// rod.perturbation_random.seed=7` (see set_key) works on top of a file's table. Written back as the
// table; the drawn ε_m follow from it exactly (rod/perturbation.hpp) and `ibrod check` shows them.
Key random_perturbation_key() {
  const std::string name = "rod.perturbation_random";
  const std::string help =
      "random twist perturbation { modes = M, amplitude = A rad, seed = S }: ε_m, m = 1..M, "
      "uniform in [-A, A) from std::mt19937_64(S), added to rod.perturbation";
  Key k;
  k.name = name;
  k.help = help;
  k.is_table = true;
  k.set = [=](Config& c, const toml::node& n) {
    const toml::table* t = n.as_table();
    if (!t) bad(name, show(n), "an inline table { modes = M, amplitude = A, seed = S }");
    RandomPerturbation r = c.rod_perturbation_random;
    for (auto&& [sub, v] : *t) {
      const std::string s(sub.str());
      const std::string full = name + "." + s;
      if (s == "modes") {
        const int64_t m = as_integer(full, v, "an integer in [0, 10000] (number of modes M)");
        if (m < 0 || m > 10000) bad(full, show(v), "an integer in [0, 10000] (number of modes M)");
        r.modes = int(m);
      } else if (s == "amplitude") {
        const double a = as_number(full, v, "a number in [0, 100] (amplitude A, rad)");
        if (!std::isfinite(a) || a < 0 || a > 100)
          bad(full, show(v), "a number in [0, 100] (amplitude A, rad)");
        r.amplitude = a;
      } else if (s == "seed") {
        const int64_t sd = as_integer(full, v, "an integer >= 0 (seed of std::mt19937_64)");
        if (sd < 0) bad(full, show(v), "an integer >= 0 (seed of std::mt19937_64)");
        r.seed = std::uint64_t(sd);
      } else {
        throw ConfigError("config: unknown key '" + echo(full) + "' (keys in " + name +
                          ": modes, amplitude, seed)");
      }
    }
    c.rod_perturbation_random = r;
  };
  k.put = [](const Config& c, toml::table& t) {
    const RandomPerturbation& r = c.rod_perturbation_random;
    toml::table v{
        {"modes", int64_t(r.modes)}, {"amplitude", r.amplitude}, {"seed", int64_t(r.seed)}};
    v.is_inline(true);
    t.insert_or_assign("perturbation_random", v);
  };
  k.value = [](const Config& c) {
    const RandomPerturbation& r = c.rod_perturbation_random;
    std::string s = "{ modes = " + std::to_string(r.modes) + ", amplitude = " + fmt(r.amplitude) +
                    ", seed = " + std::to_string(r.seed) + " }";
    const std::vector<double> eps = draw_perturbation(r);
    if (!eps.empty()) {
      s += " -> eps = [";
      for (std::size_t i = 0; i < eps.size(); ++i) s += (i ? ", " : "") + fmt(eps[i]);
      s += "]";
    }
    return s;
  };
  return k;
}

// The public interface: every key ibrod understands, in output order.
const std::vector<Key>& schema() {
  static const std::vector<Key> keys = {
      integer("grid.n", &Config::grid_n, 8, 1024, "grid points per box edge, even"),
      physical("grid.box_A", &Config::grid_box_A, 725, false, "periodic box edge L, Å"),
      integer("grid.kernel_width", &Config::grid_kernel_width, 1, 16,
              "kernel width c/h, a positive integer"),
      real("time.dt_ns", &Config::time_dt_ns, kMinDtNs, false, kMaxDtNs, "time step Δt, ns"),
      real("time.t_end_us", &Config::time_t_end_us, 0, true, kMaxDtNs * 1e-3 * kMaxSteps,
           "simulated time, µs"),
      real("time.stop_kinetic_kT", &Config::time_stop_kinetic_kT, 0, false, 1e20,
           "stop when the fluid kinetic energy falls below this, kT (0: never)"),
      real("time.stop_power_kT_per_us", &Config::time_stop_power_kT_per_us, 0, false, 1e20,
           "stop when the power of the rods' loads, |Σ F·U + T·W| (the rate at which their "
           "energy goes into the fluid), falls below this, kT/µs; either scheme, with the "
           "stability test as the kinetic-energy rule (0: never; docs/config.md)"),
      boolean("time.stability_test", &Config::time_stability_test,
              "test a state the kinetic-energy rule calls an equilibrium by perturbing a copy "
              "(docs/config.md); false: stop at once"),
      real("time.stability_amplitude_rad", &Config::time_stability_amplitude_rad, 0, true, 1.0,
           "twist amplitude of the stability test's kick, rad"),
      real("time.stability_kick_A", &Config::time_stability_kick_A, 0, true, 100.0,
           "out-of-plane amplitude of the stability test's kick of the positions, Å"),
      real("time.stability_probe_us", &Config::time_stability_probe_us, 0, true, 1e3,
           "how long the stability test integrates the kicked copy and the unperturbed one, µs "
           "(\"hessian\": after k unstable verdicts in a row the next test waits 2^(k-1) × this)"),
      real("time.stability_tolerance_kT", &Config::time_stability_tolerance_kT, 0, false, 1e6,
           "how far the kicked copy's energy must end below the unperturbed one's to call the "
           "state unstable, kT"),
      integer("time.stability_seed", &Config::time_stability_seed, 0,
              std::numeric_limits<std::int64_t>::max(),
              "seed of the stability test's perturbation"),
      stability_method_key(),
      scheme_key(),
      real("time.max_displacement_A", &Config::time_max_displacement_A, 0, false, 1e4,
           "implicit: largest move of a rod point in one step, Å; a longer step is retried "
           "shorter (0: 0.2 min(Debye length, steric.diameter_A))"),
      real("time.energy_tolerance_kT", &Config::time_energy_tolerance_kT, 0, false, 1e6,
           "implicit: largest rise of the potential energy in one step, kT; a step that raises "
           "it more is retried shorter"),
      real("time.dt_min_ns", &Config::time_dt_min_ns, 0, false, kMaxDtNs,
           "implicit: smallest step, ns, always accepted (0: time.dt_ns/1000)"),
      real("time.implicit_mobility_scale", &Config::time_implicit_mobility_scale, 0, true, 1e6,
           "implicit: local mobility M_loc = this × the kernel's self mobility"),
      local_mobility_key(),
      real("time.implicit_overlap_scale", &Config::time_implicit_overlap_scale, 0, true, 1e6,
           "implicit, time.implicit_local_mobility = \"overlap\": M_loc = this × the kernel "
           "overlap scaled to the self mobility"),
      integer("time.implicit_overlap_refresh_every", &Config::time_implicit_overlap_refresh_every,
              1, 1000000,
              "implicit, time.implicit_local_mobility = \"overlap\": steps between refreshes of "
              "M_loc, the stiffness and their LU (which costs ~10 Stokes solves at the "
              "reference; > 1: a run resumed after a signal is not bitwise the same, except with "
              "solvent.thermal, whose checkpoint keeps the filter)"),
      real("time.implicit_refresh_displacement_A", &Config::time_implicit_refresh_displacement_A, 0,
           false, 1e4,
           "implicit: also refresh the stiffness, M_loc and their factorisation before their "
           "count of steps when a rod point has moved farther than this since the last refresh, "
           "Å (0: off; docs/large_dt.md §8)"),
      integer("time.implicit_jacobian_every", &Config::time_implicit_jacobian_every, 1, 1000000,
              "implicit: steps between refreshes of the stiffness and its factorisation (> 1: "
              "faster; a run resumed after a signal is then not bitwise the same)"),
      integer("time.implicit_krylov_iterations", &Config::time_implicit_krylov_iterations, 0, 1000,
              "implicit: GMRES iterations on the Stokes mobility, each one Stokes solve: order 1, "
              "toward linearly implicit Euler; order 2, on each ROS2 stage, W = I + γΔt M K "
              "(docs/large_dt.md §10) (0: none)"),
      real("time.implicit_krylov_tol", &Config::time_implicit_krylov_tol, 0, true, 1,
           "implicit: relative residual at which GMRES stops (order 1: not reached, the step is "
           "retried shorter; order 2: the step stands, its error estimate judges it)"),
      real("time.implicit_krylov_error_share", &Config::time_implicit_krylov_error_share, 0, false,
           1, "implicit, order 2 with GMRES and error control: GMRES also stops once a stage's "
           "residual moves the rod's points by at most this share of time.error_tolerance_A in "
           "RMS (Δt ‖r‖/√n ≤ share × tolerance; docs/large_dt.md §13) (0: "
           "time.implicit_krylov_tol alone)"),
      integer("time.implicit_order", &Config::time_implicit_order, 1, 2,
              "implicit: 1 (the linearly implicit IMEX Euler step, one Stokes solve a step; the "
              "default) or 2 (two-stage Rosenbrock-W, ROS2: second order, an error estimate and "
              "error control, two solves a step; docs/large_dt.md)"),
      real("time.error_tolerance_A", &Config::time_error_tolerance_A, 0, false, 1e4,
           "implicit, order 2: largest local error estimate of a step, Å (a rod point's position, "
           "a triad's turn times steric.diameter_A/2); Δt follows it, time.dt_ns is the cap "
           "(0: no error control)"),
      integer("rod.base_pairs", &Config::rod_base_pairs, 8, 1000000, "rod points = base pairs n"),
      integer("rod.excess_link", &Config::rod_excess_link, -1000, 1000,
              "excess link ΔLk of the initial circle, an integer"),
      real_array("rod.perturbation", &Config::rod_perturbation, 100.0,
                 "twist perturbation amplitudes ε_m for m = 1, 2, …, rad"),
      random_perturbation_key(),
      physical("rod.rise_A", &Config::rod_rise_A, 3.4, false, "rise per base pair Δs, Å"),
      physical("rod.bend_modulus_erg_cm", &Config::rod_bend_modulus_erg_cm, 1.3e-19, false,
               "bending moduli a1 = a2, erg·cm"),
      physical("rod.twist_modulus_erg_cm", &Config::rod_twist_modulus_erg_cm, 1.82e-19, false,
               "twist modulus a3, erg·cm"),
      physical("rod.shear_modulus_dyn", &Config::rod_shear_modulus_dyn, 5e-5, false,
               "shear constants b1 = b2, dyn"),
      physical("rod.stretch_modulus_dyn", &Config::rod_stretch_modulus_dyn, 5e-5, false,
               "stretch constant b3, dyn"),
      real("rod.intrinsic_twist_per_A", &Config::rod_intrinsic_twist_per_A, -inf, false, inf,
           "intrinsic twist Ω³₀, rad/Å (0: untwisted reference)"),
      intrinsic_curvature_key(),
      intrinsic_file_key(),
      moduli_file_key(),
      initial_shape_key(),
      boolean("rod.closed", &Config::rod_closed,
              "true: a closed ring; false: an open rod with two free ends, straight along x "
              "unless rod.initial_shape gives its shape (needs rod.excess_link = 0; "
              "docs/model.md \"Open rods\")"),
      vec3_key("rod.rotation_deg", &Config::rod_rotation_deg, 360.0,
               "turn the initial circle or straight rod about its centre by these angles about "
               "the x, then y, then z axis, degrees (not with rod.initial_shape)"),
      vec3_key("rod.offset_A", &Config::rod_offset_A, 1e9,
               "move the initial circle or straight rod's centre this far from the box centre, Å "
               "(not with rod.initial_shape)"),
      real("solvent.salt_M", &Config::solvent_salt_M, 0, false, 10.0,
           "monovalent salt concentration Cs, mol/L"),
      physical("solvent.viscosity_poise", &Config::solvent_viscosity_poise, 0.01, false,
               "viscosity μ, poise (g/(cm·s))"),
      physical("solvent.density_g_cm3", &Config::solvent_density_g_cm3, 1.0, false,
               "density ρ, g/cm³"),
      physical("solvent.temperature_K", &Config::solvent_temperature_K, 300, false,
               "temperature for kT, K"),
      boolean("solvent.advection", &Config::solvent_advection,
              "include the nonlinear advection term ρ u·∇u"),
      boolean(
          "solvent.thermal", &Config::solvent_thermal,
          "thermal fluctuations at solvent.temperature_K: a random stress in the fluid, keyed "
          "by run.seed (both schemes; implicit: with the overlap M_loc at order 1, a fixed Δt = "
          "time.dt_ns; docs/thermal.md)"),
      boolean("solvent.thermal_drift", &Config::solvent_thermal_drift,
              "with solvent.thermal: add the stochastic drift kT ∂·M by a random finite "
              "difference of the spreading and a midpoint interpolation (docs/thermal.md)"),
      vec3_key("external.force_pN", &Config::external_force_pN, 1e6,
               "total external force on the rod, spread evenly over its points, pN"),
      vec3_key("external.torque_pN_nm", &Config::external_torque_pN_nm, 1e8,
               "external torque on the rod about its centroid (as point forces of a rigid "
               "rotation), pN·nm"),
      boolean("electrostatics.enabled", &Config::electrostatics_enabled,
              "Debye–Hückel repulsion between rod points"),
      physical("electrostatics.charge_e", &Config::electrostatics_charge_e, 0.48, true,
               "net charge per base pair, e"),
      physical("electrostatics.dielectric", &Config::electrostatics_dielectric, 77.7, false,
               "dielectric constant of water εw"),
      physical("electrostatics.cutoff_debye", &Config::electrostatics_cutoff_debye, 16, false,
               "pair cutoff in Debye lengths 1/κ"),
      boolean("steric.enabled", &Config::steric_enabled, "hard-core repulsion between segments"),
      physical("steric.diameter_A", &Config::steric_diameter_A, 20, false,
               "hard-core diameter D, Å"),
      physical("steric.stiffness", &Config::steric_stiffness_kT_A2, 0.1, true,
               "hard-core spring constant g, kT/Å²"),
      integer("output.every_steps", &Config::output_every_steps, 1,
              std::numeric_limits<int64_t>::max(), "steps between diagnostics rows"),
      frame_key(),
      integer("output.checkpoint_every_steps", &Config::output_checkpoint_every_steps, 0,
              std::numeric_limits<int64_t>::max(),
              "steps between checkpoints (0: only at the start, the end and on SIGINT/SIGTERM)"),
      real("output.every_us", &Config::output_every_us, 0, false, 1e9,
           "simulated time between diagnostics rows, µs (0: every output.every_steps steps; "
           "> 0: takes precedence over it)"),
      real("output.frame_every_us", &Config::output_frame_every_us, 0, false, 1e9,
           "simulated time between trajectory frames, µs (0: by output.frame_every_steps; > 0: "
           "takes precedence over it)"),
      real("output.checkpoint_every_us", &Config::output_checkpoint_every_us, 0, false, 1e9,
           "simulated time between checkpoints, µs (0: by output.checkpoint_every_steps; > 0: "
           "takes precedence over it)"),
      boolean("output.fluid_vti", &Config::output_fluid_vti,
              "also write the fluid velocity (Å/ns) as a ParaView .vti image with every frame"),
      boolean("output.fluid_velocity", &Config::output_fluid_velocity,
              "write the final fluid velocity (Å/ns) as DIR/velocity.npy, shape (3, n, n, n)"),
      integer("run.threads", &Config::run_threads, 0, 1024,
              "threads (0: OMP_NUM_THREADS or all cores)"),
      boolean("run.fftw_measure", &Config::run_fftw_measure,
              "time FFTW plans at start (faster steps) instead of estimating them"),
      integer("run.seed", &Config::run_seed, 0, std::numeric_limits<std::int64_t>::max(),
              "seed of the thermal noise (solvent.thermal): the same seed, the same trajectory"),
  };
  return keys;
}

const Key* find_key(const std::string& name) {
  for (const Key& k : schema())
    if (k.name == name) return &k;
  return nullptr;
}

std::string known_keys_in(const std::string& section) {
  std::string s;
  for (const Key& k : schema())
    if (section_of(k.name) == section) s += (s.empty() ? "" : ", ") + leaf_of(k.name);
  return s;
}

std::string known_sections() {
  std::string s;
  std::string last;
  for (const Key& k : schema()) {
    const std::string sec = section_of(k.name);
    if (sec != last) s += (s.empty() ? "" : ", ") + sec;
    last = sec;
  }
  return s;
}

void set_key(Config& c, const std::string& name, const toml::node& n) {
  const Key* k = find_key(name);
  // a sub-key of a table-valued key (rod.perturbation_random.seed): set as a one-entry table
  if (const auto dot = name.rfind('.'); !k && dot != std::string::npos && dot > name.find('.')) {
    if (const Key* parent = find_key(name.substr(0, dot)); parent && parent->is_table) {
      toml::table t;
      t.insert(name.substr(dot + 1), n);
      parent->set(c, t);
      return;
    }
  }
  if (!k) {
    const std::string known = known_keys_in(section_of(name));
    if (name.find('.') == std::string::npos || known.empty())
      throw ConfigError("config: unknown key '" + echo(name) +
                        "' (sections are: " + known_sections() + ")");
    throw ConfigError("config: unknown key '" + echo(name) + "' (keys in [" +
                      echo(section_of(name)) + "]: " + known + ")");
  }
  k->set(c, n);
}

std::string toml_text(const toml::node& n);

// One key of a [[rods]] table: checked at once on a scratch copy (so that an error names the
// table and the key), kept as text, and set on top of [rod] when rod_config resolves the table.
void set_rod_key(Config& c, std::size_t r, const std::string& key, const toml::node& value) {
  const std::string where =
      "[[rods]] table " + std::to_string(r) + " (rods." + std::to_string(r) + "." + key + "): ";
  Config scratch;
  try {
    set_key(scratch, "rod." + key, value);
  } catch (const ConfigError& e) {
    throw ConfigError("config: " + where + e.what());
  }
  if (c.rods.size() <= r) c.rods.resize(r + 1);
  auto& t = c.rods[r];
  const std::string text = toml_text(value);
  for (auto& kv : t)
    if (kv.first == key) {
      kv.second = text;
      return;
    }
  t.emplace_back(key, text);
  // in key order, as a TOML table reads back: a table is the same however it was written
  std::sort(t.begin(), t.end());
}

// rods = [[rods]]: an array of tables; a file's array replaces any earlier one.
void set_rod_tables(Config& c, const toml::node& node) {
  const toml::array* a = node.as_array();
  if (!a || !a->is_array_of_tables() || a->empty())
    throw ConfigError(
        "config: 'rods' must be an array of tables, one [[rods]] table per rod, each with keys "
        "of [rod] (docs/config.md \"Several rods\")");
  if (a->size() > Config::kMaxRods)
    throw ConfigError("config: rods = " + std::to_string(a->size()) +
                      " [[rods]] tables is invalid: expected at most " +
                      std::to_string(Config::kMaxRods) +
                      " (one table per rod; docs/config.md \"Several rods\")");
  c.rods.clear();
  for (std::size_t r = 0; r < a->size(); ++r) {
    c.rods.emplace_back();
    for (auto&& [key, value] : *a->get(r)->as_table())
      set_rod_key(c, r, std::string(key.str()), value);
  }
}

}  // namespace

Config rod_config(const Config& c, int r) {
  Config out = c;
  out.rods.clear();
  if (c.rods.empty()) return out;
  for (const auto& [key, text] : c.rods.at(std::size_t(r))) {
    const toml::table t = toml::parse("v = " + text);
    set_key(out, "rod." + key, *t.get("v"));
  }
  return out;
}

int point_count(const Config& c) {
  int n = 0;
  for (const RodConfig& rc : rod_configs(c)) n += rc.keys.rod_base_pairs;
  return n;
}

std::string RodConfig::key(const std::string& k) const {
  return table < 0 ? "rod." + k : "rods." + std::to_string(table) + "." + k;
}

std::string RodConfig::where() const {
  return table < 0 ? "" : "[[rods]] table " + std::to_string(table) + ": ";
}

std::vector<RodConfig> rod_configs(const Config& c) {
  std::vector<RodConfig> out;
  if (c.rods.empty()) {
    out.push_back({rod_config(c, 0), -1});
    return out;
  }
  for (int r = 0; r < int(c.rods.size()); ++r) out.push_back({rod_config(c, r), r});
  return out;
}

std::vector<rod::RodRange> rod_layout(const Config& c) {
  std::vector<rod::RodRange> out;
  int offset = 0;
  for (const RodConfig& rc : rod_configs(c)) {
    const Config& k = rc.keys;
    out.push_back({offset, k.rod_base_pairs, k.rod_closed, k.rod_rise_A * units::angstrom});
    offset += k.rod_base_pairs;
  }
  return out;
}

std::string rods_incompatibility(const Config& old, const Config& c) {
  const std::vector<RodConfig> a = rod_configs(old), b = rod_configs(c);
  bool same = a.size() == b.size();
  for (std::size_t r = 0; same && r < b.size(); ++r)
    same = a[r].keys.rod_base_pairs == b[r].keys.rod_base_pairs &&
           a[r].keys.rod_closed == b[r].keys.rod_closed;
  if (same) return "";
  // a closed ring and an open rod are different structures: never continued into each other
  if (a.size() == 1 && b.size() == 1 && a[0].keys.rod_closed != b[0].keys.rod_closed)
    return std::string(a[0].keys.rod_closed ? "a closed rod (rod.closed = true)"
                                            : "an open rod (rod.closed = false)") +
           "; the configuration asks for rod.closed = " + (b[0].keys.rod_closed ? "true" : "false");
  return std::to_string(a.size()) +
         " rods whose sizes or kinds (rod.base_pairs, rod.closed) differ from the "
         "configuration's " +
         std::to_string(b.size());
}

std::int64_t frame_every(const Config& c) {
  return c.output_frame_every_steps < 0 ? c.output_every_steps : c.output_frame_every_steps;
}

void apply_toml(Config& c, const std::string& text, const std::string& source) {
  const toml::table tbl = parse_toml(text, source, "config");
  for (auto&& [sec, node] : tbl) {
    const std::string s(sec.str());
    if (s == "rods") {
      set_rod_tables(c, node);
      continue;
    }
    const toml::table* t = node.as_table();
    if (!t)
      throw ConfigError("config: top-level key '" + echo(s) + "' must be a section [" + echo(s) +
                        "] (sections are: " + known_sections() + ")");
    for (auto&& [key, value] : *t) set_key(c, s + "." + std::string(key.str()), value);
  }
}

Config load_config(const std::string& path) {
  Config c;
  if (path.empty()) return c;
  apply_toml(c, read_text_file(path, "config"), path);
  return c;
}

void apply_override(Config& c, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError("config: --set '" + echo(assignment) +
                      "' must have the form section.key=value");
  std::string key = assignment.substr(0, eq), value = assignment.substr(eq + 1);
  while (!key.empty() && key.back() == ' ') key.pop_back();
  // One line, one value: a newline would let TOML read (and this function drop) a second key.
  for (const char ch : assignment)
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f)
      throw ConfigError("config: --set " + echo(key) + "=" + echo(value) +
                        ": control characters (newline, tab, …) are not allowed in --set");
  toml::table t;
  try {
    t = toml::parse("v = " + value, "--set " + key);
  } catch (const toml::parse_error& e) {
    // a bare word is a string, as people type it (--set time.scheme=implicit); a key that is not
    // a string then says what it expects
    const bool word =
        !value.empty() && std::isalpha(static_cast<unsigned char>(value[0])) &&
        std::all_of(value.begin(), value.end(), [](char ch) {
          return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
        });
    if (!word)
      throw ConfigError("config: --set " + echo(key) + "=" + echo(value) +
                        ": the value is not a TOML number, boolean, string or array (" +
                        echo(std::string(e.description()), 200) + ")");
    t = toml::parse("v = \"" + value + "\"", "--set " + key);
  }
  // rods.K.key=value: a key of [[rods]] table K
  if (key.rfind("rods.", 0) == 0) {
    const std::string rest = key.substr(5);
    const auto dot = rest.find('.');
    std::size_t r = 0;
    const auto [end, ec] =
        std::from_chars(rest.data(), rest.data() + std::min(dot, rest.size()), r);
    if (dot == std::string::npos || ec != std::errc() || end != rest.data() + dot ||
        r > c.rods.size() || r >= Config::kMaxRods)
      throw ConfigError("config: --set " + echo(key) +
                        ": a [[rods]] key is rods.K.key with K a table number from 0 to " +
                        std::to_string(std::min(c.rods.size(), Config::kMaxRods - 1)) + " (" +
                        std::to_string(c.rods.size()) + " appends a table; at most " +
                        std::to_string(Config::kMaxRods) + " rods)");
    set_rod_key(c, r, rest.substr(dot + 1), *t.get("v"));
    return;
  }
  set_key(c, key, *t.get("v"));
}

namespace {

// A number as config.toml writes it: the shortest text that reads back as the same double
// (std::to_chars), with a decimal point or an exponent so that TOML reads a float (0.48, not
// 0.47999999999999998; 725.0, not 725).
std::string shortest(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // n: inf/nan (never finite-checked)
  return s;
}

// One TOML value as config.toml writes it (numbers shortest round-trip, strings as toml++).
std::string toml_text(const toml::node& n) {
  if (auto v = n.value_exact<double>()) return shortest(*v);
  if (auto v = n.value_exact<int64_t>()) return std::to_string(*v);
  if (auto v = n.value_exact<bool>()) return *v ? "true" : "false";
  if (const toml::array* a = n.as_array()) {
    std::string s = "[";
    for (std::size_t i = 0; i < a->size(); ++i) s += (i ? ", " : "") + toml_text(*a->get(i));
    return s + "]";
  }
  if (const toml::table* t = n.as_table()) {
    std::string s = "{ ";
    bool first = true;
    for (auto&& [k, v] : *t) {
      s += (first ? "" : ", ") + std::string(k.str()) + " = " + toml_text(v);
      first = false;
    }
    return s + " }";
  }
  return show(n);  // a string: toml++ quotes and escapes it
}

}  // namespace

std::string to_toml(const Config& c) {
  // one line per key, "key = value  # unit and meaning", under its [section]; numbers in their
  // shortest round-trip form; re-runnable as is (comments are TOML comments)
  std::ostringstream os;
  os << "# ibrod resolved configuration (every key, defaults included; units in the comments)\n";
  std::string section;
  for (const Key& k : schema()) {
    const std::string sec = section_of(k.name);
    if (sec != section) {
      os << "\n[" << sec << "]\n";
      section = sec;
    }
    toml::table t;
    k.put(c, t);
    const std::string leaf = leaf_of(k.name);
    std::string line = leaf + " = " + toml_text(*t.get(leaf));
    if (line.size() < 32) line.resize(32, ' ');
    os << line << " # " << k.help << "\n";
  }
  // [[rods]]: each table's own keys, on top of [rod]
  for (const auto& t : c.rods) {
    os << "\n[[rods]]\n";
    for (const auto& [key, text] : t) os << key << " = " << text << "\n";
  }
  return os.str();
}

std::string describe(const Config& c) {
  std::ostringstream os;
  for (const Key& k : schema()) {
    std::string lhs = k.name + " = " + k.value(c);
    if (lhs.size() < 44) lhs.resize(44, ' ');
    os << lhs << " # " << k.help << "\n";
  }
  for (std::size_t r = 0; r < c.rods.size(); ++r)
    for (const auto& [key, text] : c.rods[r]) {
      std::string lhs = "rods." + std::to_string(r) + "." + key + " = " + text;
      if (lhs.size() < 44) lhs.resize(44, ' ');
      os << lhs << " # [[rods]] table " << r << " (on top of [rod])\n";
    }
  return os.str();
}

}  // namespace ibrod::config
