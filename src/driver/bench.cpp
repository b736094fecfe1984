#include "driver/bench.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>

#include "integrate/stepper.hpp"
#include "sim/simulation.hpp"

namespace ibrod::driver {

using namespace ibrod::config;

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Timings on a shared machine are noisy: everything is measured in `kRounds` interleaved
// rounds (full steps, the phases, the FFTs alone), and each figure is the minimum over the rounds
// of its per-round mean, so that a burst of load in one round does not bias one figure only.
constexpr int kRounds = 5;

}  // namespace

BenchResult bench(const Config& c, int steps) {
  validate(c);
  sim::Simulation s(to_params(c));
  // the explicit step on the simulation's own system, timed phase by phase below
  integrate::Stepper st(s.system());
  auto& rod = s.rod();
  auto& fl = s.system().fluid();
  BenchResult r;
  r.steps = steps;
  r.threads = fl.threads();

  // Warm up (first touches, caches).
  for (int i = 0; i < std::min(steps, 10); ++i) s.step();

  // A copy of the velocity to put back after the FFTs alone have clobbered it.
  const std::size_t n3 = fl.grid().size();
  std::vector<double> saved(3 * n3);
  constexpr int kPhases = integrate::StepPhaseTimes::kCount;
  constexpr double inf = std::numeric_limits<double>::infinity();
  double best_phase[kPhases];
  std::fill(best_phase, best_phase + kPhases, inf);
  double best_step = inf, best_fft = inf, best_split = inf;
  const int per_round = std::max(1, steps / kRounds);
  // with noise, a deterministic twin timed in the same rounds (the noise's cost, one run)
  std::unique_ptr<sim::Simulation> twin;
  if (c.solvent_thermal) {
    Config d = c;
    d.solvent_thermal = false;
    twin = std::make_unique<sim::Simulation>(to_params(d));
    for (int i = 0; i < std::min(steps, 10); ++i) twin->step();
  }
  double best_twin = inf, best_noise = inf;

  for (int round = 0; round < kRounds; ++round) {
    // 1. whole steps, exactly as a run does them
    auto t = Clock::now();
    for (int i = 0; i < per_round; ++i) s.step();
    best_step = std::min(best_step, ms_since(t) / per_round);
    if (twin) {
      // the deterministic twin's steps, and the noise of one step alone (the spectrum buffer is
      // scratch between steps)
      t = Clock::now();
      for (int i = 0; i < per_round; ++i) twin->step();
      best_twin = std::min(best_twin, ms_since(t) / per_round);
      t = Clock::now();
      for (int i = 0; i < per_round; ++i) fl.run_noise_only();
      best_noise = std::min(best_noise, ms_since(t) / per_round);
    }

    // 2. the same steps, timed phase by phase (Stepper::step with a phase clock; the fluid
    // half is split into the three passes of FluidSolver::step)
    integrate::StepPhaseTimes phases;
    for (int i = 0; i < per_round; ++i) st.step(rod, &phases);
    for (int k = 0; k < kPhases; ++k)
      best_phase[k] = std::min(best_phase[k], phases.ms[k] / per_round);

    // 3. FFTW's threaded 3-D transforms alone (the six FFTs of one step), on the solver's own
    // buffers; the velocity is saved and put back so that the trajectory goes on undisturbed
    for (int comp = 0; comp < 3; ++comp)
      std::copy_n(fl.velocity(comp), n3, saved.begin() + comp * n3);
    fl.run_ffts_only();  // planned on first use: not timed
    double fft = 0, split = 0;
    for (int i = 0; i < per_round; ++i) {
      t = Clock::now();
      fl.run_ffts_only();
      fft += ms_since(t);
      t = Clock::now();
      fl.run_split_ffts_only();
      split += ms_since(t);
    }
    best_fft = std::min(best_fft, fft / per_round);
    best_split = std::min(best_split, split / per_round);
    fl.zero_force();
    for (int comp = 0; comp < 3; ++comp)
      std::copy_n(saved.begin() + comp * n3, n3, fl.velocity(comp));
  }
  for (int k = 0; k < kPhases; ++k)
    r.phases.push_back({integrate::StepPhaseTimes::kNames[k], best_phase[k]});
  r.step_ms = best_step;
  r.fftw3d_ms = best_fft;
  r.split_fft_ms = best_split;
  r.fft_ms = std::min(best_fft, best_split);
  r.fluid_solve_ms = best_phase[3] + best_phase[4] + best_phase[5];
  if (twin) {
    r.deterministic_step_ms = best_twin;
    r.noise_ms = best_noise;
  }

  // Diagnostics (output steps only).
  const int reps = std::max(1, std::min(steps / 10, 20));
  auto t = Clock::now();
  for (int i = 0; i < reps; ++i) s.observe();
  r.diagnostics_ms = ms_since(t) / reps;
  return r;
}

void print_bench(const Config& c, const BenchResult& r, std::FILE* out) {
  std::fprintf(out,
               "ibrod bench: %d³ grid, %d rod points, Cs = %g M, electrostatics %s, steric %s, "
               "%d threads, %d steps\n",
               c.grid_n, c.rod_base_pairs, c.solvent_salt_M,
               c.electrostatics_enabled ? "on" : "off", c.steric_enabled ? "on" : "off", r.threads,
               r.steps);
  std::fprintf(out, "(each figure: the minimum over %d interleaved rounds of its mean per step)\n",
               kRounds);
  std::fprintf(out, "%-22s %10s %8s\n", "phase", "ms/step", "share");
  double sum = 0;
  for (const auto& ph : r.phases) sum += ph.ms;
  for (const auto& ph : r.phases)
    std::fprintf(out, "%-22s %10.4f %7.1f%%\n", ph.name.c_str(), ph.ms, 100 * ph.ms / sum);
  std::fprintf(out, "%-22s %10.4f\n", "sum of phases", sum);
  std::fprintf(out, "%-22s %10.4f   (the three fluid passes)\n", "fluid solve", r.fluid_solve_ms);
  std::fprintf(out, "%-22s %10.4f\n", "full step", r.step_ms);
  std::fprintf(out, "%-22s %10.4f   (FFTW's threaded 3-D r2c + c2r plans, 3 components)\n",
               "FFTs alone, FFTW 3-D", r.fftw3d_ms);
  std::fprintf(out, "%-22s %10.4f   (the same transforms as the step does them: planes, x lines)\n",
               "FFTs alone, split", r.split_fft_ms);
  std::fprintf(out, "%-22s %10.4f   (the faster of the two: the ratio's denominator)\n",
               "FFT-only time", r.fft_ms);
  std::fprintf(out, "%-22s %10.4f   (per output step, every %lld steps: %.4f ms/step)\n",
               "diagnostics", r.diagnostics_ms, static_cast<long long>(c.output_every_steps),
               r.diagnostics_ms / double(std::max<long long>(1, c.output_every_steps)));
  if (r.deterministic_step_ms > 0) {
    std::fprintf(out, "%-22s %10.4f   (the same configuration without solvent.thermal)\n",
                 "deterministic step", r.deterministic_step_ms);
    std::fprintf(out, "%-22s %10.4f   (the random stress of one step alone)\n", "thermal noise",
                 r.noise_ms);
    std::fprintf(out, "noise_cost_ratio=%.4f   (thermal noise / deterministic step)\n",
                 r.noise_ms / r.deterministic_step_ms);
  }
  std::fprintf(out, "ratio_step_to_fft=%.4f\n", r.ratio());
}

}  // namespace ibrod::driver
