#pragma once
// `ibrod bench`: time one step of the configured simulation, split by phase, beside the time of
// the step's six FFTs alone, measured in the same run.
#include <cstdio>
#include <string>
#include <vector>

#include "io/config.hpp"

namespace ibrod::io {

struct BenchPhase {
  std::string name;
  double ms = 0;  ///< mean per step
};

struct BenchResult {
  std::vector<BenchPhase> phases;  ///< rod forces, pair forces, fluid rhs pass, spreading, FFTs, …
  double step_ms = 0;              ///< full Stepper::step, timed on its own
  double fluid_solve_ms = 0;       ///< begin_step() + finish_step() (rhs pass, FFTs, spectral)
  double fft_ms = 0;               ///< the step's FFTs alone (forward + backward, 3 components)
  double diagnostics_ms = 0;       ///< one observe() (output steps only)
  int steps = 0, threads = 0;
  double ratio() const { return step_ms / fft_ms; }
};

/// Runs about 2 × `steps` steps (after a short warm-up) from the configured initial state, in
/// interleaved rounds of whole steps, phase-timed steps and FFTs alone; each figure is the
/// minimum over the rounds of its per-round mean.
BenchResult bench(const Config& c, int steps);
/// Prints the table; the last line is `ratio_step_to_fft=<value>`.
void print_bench(const Config& c, const BenchResult& r, std::FILE* out);

}  // namespace ibrod::io
