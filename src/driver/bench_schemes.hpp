#pragma once
// `ibrod bench --schemes` (issue 14): simulated µs per wall hour of the explicit and the
// implicit time scheme in the same run, from the same initial state of the configured
// simulation (the production Simulation::step of each).
#include <cstdio>

#include "config/config.hpp"

namespace ibrod::driver {

struct SchemeBenchResult {
  double explicit_dt_ns = 0;  ///< the explicit step (time.dt_ns of the config)
  int explicit_steps = 0;
  double explicit_ms_per_step = 0;
  double implicit_dt_max_ns = 0;  ///< the implicit scheme's largest step
  double implicit_ns = 0;         ///< simulated time of the implicit part
  long implicit_steps = 0, implicit_rejections = 0;
  double implicit_ms_per_step = 0;
  double us_per_hour_explicit = 0, us_per_hour_implicit = 0;
  /// where the implicit step's time went, ms per accepted step (trials included): forces, K and
  /// M_loc (overlap: of which M_loc), the local factorisation, local solves, Stokes solves
  long factorizations = 0;  ///< of the implicit step's local system
  long stokes_solves = 0;   ///< of the implicit steps, rejected trials included
  double ms_forces = 0, ms_stiffness = 0, ms_overlap = 0, ms_factorize = 0, ms_local_solve = 0,
         ms_stokes = 0;
  double ratio() const { return us_per_hour_implicit / us_per_hour_explicit; }
};

/// `explicit_steps` explicit steps of time.dt_ns (after 10 untimed ones), then `implicit_ns` of
/// simulated time with time.scheme = "implicit" and time.dt_ns = implicit_dt_ns (the other keys
/// as configured), both from the configured initial state.
SchemeBenchResult bench_schemes(const config::Config& c, int explicit_steps, double implicit_dt_ns,
                                double implicit_ns);
/// Prints the two and the implicit step's parts; the last line is `us_per_hour_explicit=…
/// us_per_hour_implicit=…`.
void print_bench_schemes(const SchemeBenchResult& r, std::FILE* out);

}  // namespace ibrod::driver
