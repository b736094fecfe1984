#pragma once
// The run driver behind `ibrod run`: output directory, time loop, diagnostics rows, progress,
// final state and summary. Files written into the output directory:
//   config.toml       the resolved configuration (every key)
//   timeseries.csv    one row per output step (columns: timeseries_header())
//   final_state.csv   one row per rod point: x_A,y_A,z_A,d1x..d3z
//   summary.json      steps, simulated time, why it stopped, final observables, timing
#include <cstdio>
#include <string>

#include "io/config.hpp"
#include "sim/simulation.hpp"

namespace ibrod::io {

struct RunOptions {
  std::string output_dir = "ibrod-out";
  bool overwrite = false;  ///< replace an existing, non-empty output directory
  std::FILE* log = stdout; ///< progress lines (nullptr: silent)
};

struct RunResult {
  std::int64_t steps = 0;
  double time_us = 0;
  sim::StopReason reason = sim::StopReason::none;
  sim::Observables initial, final;
  double wall_s = 0;
  double ms_per_step = 0;
};

/// Run one trajectory. Throws ConfigError (bad config, output directory exists) or RunError
/// (non-finite state, I/O failure).
RunResult run(const Config& c, const RunOptions& opt);

/// The header row of timeseries.csv.
std::string timeseries_header();
/// One row of timeseries.csv (no newline).
std::string timeseries_row(const sim::Observables& o);

}  // namespace ibrod::io
