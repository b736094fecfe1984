#pragma once
// `ibrod bench`: time one step of the configured simulation, split by phase, beside the time of
// the step's six FFTs alone, measured in the same run.
#include <cstdio>
#include <string>
#include <vector>

#include "config/config.hpp"

namespace ibrod::driver {

struct BenchPhase {
  std::string name;
  double ms = 0;  ///< mean per step
};

struct BenchResult {
  std::vector<BenchPhase> phases;  ///< rod forces, pair forces, spreading, the 3 fluid passes, …
  double step_ms = 0;              ///< full Stepper::step, timed on its own
  double fluid_solve_ms = 0;       ///< the three passes of FluidSolver::finish_step()
  double fftw3d_ms = 0;     ///< FFTW's threaded 3-D r2c + c2r plans alone (3 components each)
  double split_fft_ms = 0;  ///< the step's own split transforms alone (run_split_ffts_only)
  /// the FFT-only time the ratio is taken against: the faster of the two, so that neither a slow
  /// reference nor a slow decomposition can flatter the ratio
  double fft_ms = 0;
  double diagnostics_ms = 0;  ///< one observe() (output steps only)
  /// solvent.thermal = true: the whole step of a twin without noise, timed in the same rounds
  /// (docs/thermal.md); else 0
  double deterministic_step_ms = 0;
  /// solvent.thermal = true: the random stress of one step alone (FluidSolver::run_noise_only)
  double noise_ms = 0;
  int steps = 0, threads = 0;
  double ratio() const { return step_ms / fft_ms; }
};

/// Runs about 2 × `steps` steps (after a short warm-up) from the configured initial state, in
/// interleaved rounds of whole steps, phase-timed steps and FFTs alone; each figure is the
/// minimum over the rounds of its per-round mean.
BenchResult bench(const config::Config& c, int steps);
/// Prints the table; the last line is `ratio_step_to_fft=<value>`.
void print_bench(const config::Config& c, const BenchResult& r, std::FILE* out);

}  // namespace ibrod::driver
