#pragma once
// `ibrod sweep SWEEP.toml [-j K] [-o DIR] [--list]` (docs/sweeps.md): runs the points of a
// parameter sweep as `ibrod run` processes, K at a time; under `mpirun -np R` the points are
// shared round-robin among the R ranks (each running K at a time). Like add_analysis_commands,
// the subcommand runs from its CLI11 callback and ends parsing by throwing
// CLI::RuntimeError(status): 0 every point finished, 2 a bad sweep file, 4 some points failed
// (named on stderr) or are still being written by another process, 128 + N stopped by signal N (run
// the same command again to continue). main needs only: add_sweep_command(app) before app.parse.
#include <CLI/CLI.hpp>

void add_sweep_command(CLI::App& app);
