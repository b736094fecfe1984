#include "driver/bench_schemes.hpp"

#include <algorithm>
#include <chrono>

#include "sim/simulation.hpp"

namespace ibrod::driver {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}
}  // namespace

SchemeBenchResult bench_schemes(const config::Config& c, int explicit_steps, double implicit_dt_ns,
                                double implicit_ns) {
  SchemeBenchResult r;
  config::Config ce = c;
  ce.time_scheme = "explicit";
  config::validate(ce);
  {
    sim::Simulation s(config::to_params(ce));
    for (int i = 0; i < 10; ++i) s.step();  // first touches
    const auto t0 = Clock::now();
    for (int i = 0; i < explicit_steps; ++i) s.step();
    const double wall = seconds_since(t0);
    r.explicit_dt_ns = s.dt() / 1e-9;
    r.explicit_steps = explicit_steps;
    r.explicit_ms_per_step = 1e3 * wall / explicit_steps;
    r.us_per_hour_explicit = explicit_steps * s.dt() / 1e-6 / wall * 3600;
  }
  config::Config ci = c;
  ci.time_scheme = "implicit";
  ci.time_dt_ns = implicit_dt_ns;
  ci.time_t_end_us = implicit_ns * 1e-3;
  config::validate(ci);
  {
    sim::Simulation s(config::to_params(ci));
    const auto t0 = Clock::now();
    while (!s.at_end()) s.step();
    const double wall = seconds_since(t0);
    r.implicit_dt_max_ns = implicit_dt_ns;
    r.implicit_ns = s.time() / 1e-9;
    r.implicit_steps = long(s.step_count());
    r.implicit_rejections = s.implicit()->rejections();
    r.implicit_ms_per_step = 1e3 * wall / double(s.step_count());
    r.us_per_hour_implicit = s.time() / 1e-6 / wall * 3600;
    const integrate::ImplicitTimings& t = s.implicit()->stepper().timings();
    const double per = 1e3 / double(s.step_count());
    r.ms_forces = t.forces * per;
    r.ms_stiffness = t.stiffness * per;
    r.ms_overlap = t.overlap * per;
    r.ms_factorize = t.factorize * per;
    r.ms_local_solve = t.local_solve * per;
    r.ms_stokes = t.stokes * per;
    r.factorizations = t.factorizations;
    r.stokes_solves = t.stokes_solves;
  }
  return r;
}

void print_bench_schemes(const SchemeBenchResult& r, std::FILE* out) {
  std::fprintf(out,
               "explicit: %d steps of %.4g ns, %.4f ms/step\n"
               "implicit: %.4g ns in %ld steps (Δt ≤ %.4g ns, mean %.4g ns, %ld rejected "
               "trials), %.4f ms/step\n"
               "implicit/explicit = %.1f\n",
               r.explicit_steps, r.explicit_dt_ns, r.explicit_ms_per_step, r.implicit_ns,
               r.implicit_steps, r.implicit_dt_max_ns, r.implicit_ns / double(r.implicit_steps),
               r.implicit_rejections, r.implicit_ms_per_step, r.ratio());
  std::fprintf(out,
               "implicit, ms per step: forces %.2f, stiffness %.2f (M_loc %.2f), factorisation "
               "%.2f (%ld of them), local solves %.2f, Stokes solves %.2f (%.2f a step)\n",
               r.ms_forces, r.ms_stiffness, r.ms_overlap, r.ms_factorize, r.factorizations,
               r.ms_local_solve, r.ms_stokes,
               double(r.stokes_solves) / double(std::max(r.implicit_steps, 1L)));
  std::fprintf(out, "us_per_hour_explicit=%.4g us_per_hour_implicit=%.4g\n", r.us_per_hour_explicit,
               r.us_per_hour_implicit);
}

}  // namespace ibrod::driver
