#include "io/bench.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>

#include "sim/simulation.hpp"

namespace ibrod::io {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

}  // namespace

BenchResult bench(const Config& c, int steps) {
  validate(c);
  sim::Simulation s(to_params(c));
  auto& st = s.stepper();
  const auto& p = st.params();
  auto& rod = s.rod();
  const int n = rod.size();
  BenchResult r;
  r.steps = steps;
  r.threads = omp_get_max_threads();

  // Warm up (first touches, caches), then time whole steps.
  for (int i = 0; i < std::min(steps, 10); ++i) s.step();
  auto t = Clock::now();
  for (int i = 0; i < steps; ++i) s.step();
  r.step_ms = ms_since(t) / steps;

  // The same work phase by phase, on private buffers, from the current state.
  std::vector<Vec3> F(n), T(n), U(n), W(n);
  rod::RodWork work;
  work.resize(n);
  double ph[7] = {0, 0, 0, 0, 0, 0, 0};
  auto& fl = st.fluid();
  for (int i = 0; i < steps; ++i) {
    t = Clock::now();
    std::fill(F.begin(), F.end(), Vec3::Zero());
    std::fill(T.begin(), T.end(), Vec3::Zero());
    rod::elastic_forces(p.rod, rod, work, F, T);
    ph[0] += ms_since(t);
    t = Clock::now();
    if (p.electro.enabled) st.electrostatics().accumulate(rod.X, F);
    if (p.steric.enabled) st.steric().accumulate(rod.X, F);
    ph[1] += ms_since(t);
    t = Clock::now();
    fl.zero_force();
    st.coupler().spread(rod.X, F, T, fl.force());
    ph[2] += ms_since(t);
    t = Clock::now();
    fl.step();
    ph[3] += ms_since(t);
    t = Clock::now();
    const fluid::FluidSolver& cfl = fl;
    st.coupler().interpolate(rod.X, cfl.velocity(), U, W);
    ph[4] += ms_since(t);
    t = Clock::now();
    rod::advance(rod, U, W, p.fluid.dt);
    ph[5] += ms_since(t);
  }
  const char* names[] = {"rod forces", "pair forces", "spreading", "fluid solve", "interpolation",
                         "update"};
  for (int i = 0; i < 6; ++i) r.phases.push_back({names[i], ph[i] / steps});

  // Diagnostics (output steps only).
  const int reps = std::max(1, std::min(steps / 10, 20));
  t = Clock::now();
  for (int i = 0; i < reps; ++i) s.observe();
  r.diagnostics_ms = ms_since(t) / reps;

  // The FFTs alone, last: they clobber the fluid's buffers.
  fl.run_ffts_only();
  t = Clock::now();
  for (int i = 0; i < steps; ++i) fl.run_ffts_only();
  r.fft_ms = ms_since(t) / steps;
  return r;
}

void print_bench(const Config& c, const BenchResult& r, std::FILE* out) {
  std::fprintf(out, "ibrod bench: %d³ grid, %d rod points, Cs = %g M, electrostatics %s, steric %s, "
               "%d threads, %d steps\n",
               c.grid_n, c.rod_base_pairs, c.solvent_salt_M,
               c.electrostatics_enabled ? "on" : "off", c.steric_enabled ? "on" : "off", r.threads,
               r.steps);
  std::fprintf(out, "%-22s %10s %8s\n", "phase", "ms/step", "share");
  double sum = 0;
  for (const auto& ph : r.phases) sum += ph.ms;
  for (const auto& ph : r.phases)
    std::fprintf(out, "%-22s %10.4f %7.1f%%\n", ph.name.c_str(), ph.ms, 100 * ph.ms / sum);
  std::fprintf(out, "%-22s %10.4f\n", "sum of phases", sum);
  std::fprintf(out, "%-22s %10.4f\n", "full step", r.step_ms);
  std::fprintf(out, "%-22s %10.4f\n", "FFTs alone", r.fft_ms);
  std::fprintf(out, "%-22s %10.4f   (per output step, every %lld steps)\n", "diagnostics",
               r.diagnostics_ms, static_cast<long long>(c.output_every_steps));
  std::fprintf(out, "ratio_step_to_fft=%.4f\n", r.ratio());
}

}  // namespace ibrod::io
