#pragma once
// The run driver behind `ibrod run`: output directory, time loop, diagnostics rows, trajectory,
// checkpoints, progress, final state and summary. Files written into the output directory are
// named by io::RunDir (docs/outputs.md describes each):
//   config.toml        the resolved configuration (every key)
//   timeseries.csv     one row per output step (columns: timeseries_header())
//   trajectory.h5md      H5MD trajectory: frames every output.frame_every_steps, observables,
//   config rod.pvd, vtk/      ParaView series of the rod (.vtp), with every frame fluid.pvd
//   ParaView series of the fluid velocity (.vti; output.fluid_vti) checkpoint.bin     full state at
//   the latest checkpoint (start, every
//                      output.checkpoint_every_steps, end, SIGINT/SIGTERM)
//   fftw.wisdom        the FFTW plans of the run (imported by --resume: same plans, same bits)
//   final_state.csv    one row per rod point: x_A,y_A,z_A,d1x..d3z
//   summary.json       steps, simulated time, why it stopped, link drift, observables, timing
//
// Continuing a run (--resume) from its checkpoint at step C drops every row and frame after C
// and recomputes them; the result is bitwise identical to a run that was never interrupted
// (same plans through fftw.wisdom, the same thread count, deterministic reductions).
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "io/observables.hpp"
#include "sim/simulation.hpp"

namespace ibrod::driver {

struct RunOptions {
  std::string output_dir = "ibrod-out";
  bool overwrite = false;      ///< replace the files of an existing, non-empty output directory
  bool resume = false;         ///< continue the run in output_dir from its checkpoint.bin
  bool force = false;          ///< resume even if the configuration differs from the checkpoint's
  std::string fftw_wisdom;     ///< import these FFTW plans before planning ("": none)
  bool handle_signals = true;  ///< SIGINT/SIGTERM: checkpoint at the end of the step, then return
  std::FILE* log = stdout;     ///< progress lines and warnings (nullptr: silent)
  int tty = -1;  ///< progress style: 1 in place ('\r'), 0 plain lines, −1 isatty(log)
  /// MPI rank and rank count of MPI_COMM_WORLD (`mpirun -np K ibrod run`, driver/mpi_env.hpp): with
  /// ranks > 1 the fluid grid is split over the ranks (fluid::DistributedFluid), every rank runs
  /// the rod and the loop, and rank 0 alone writes files and progress. Every rank must call run().
  int rank = 0;
  int ranks = 1;
  bool keep_rows = false;   ///< keep every time-series row in memory (Run::rows())
  bool write_files = true;  ///< false: no directory, no file (the Python module's default)
};

struct RunResult {
  std::int64_t steps = 0;
  double time_us = 0;
  sim::StopReason reason = sim::StopReason::none;
  sim::Observables initial, final;
  double wall_s = 0;       ///< this process
  double ms_per_step = 0;  ///< this process
  int signal = 0;          ///< SIGINT/SIGTERM that stopped the run after a checkpoint; 0: none
  bool already_finished = false;      ///< --resume of a run that had stopped: nothing was done
  std::int64_t resumed_from = -1;     ///< checkpoint step this process started from (−1: fresh)
  std::int64_t checkpoint_step = -1;  ///< step of the latest checkpoint written or read
  double link_drift = 0;              ///< final Lk − initial Lk
  double max_link_drift = 0;          ///< max |Lk − Lk(0)| over the output steps
  bool self_passage_warning = false;  ///< max_link_drift > kLinkDriftWarning
  /// implicit scheme, this process: factorisations of the local system, and refreshes of K made
  /// early by time.implicit_refresh_displacement_A (−1: the explicit scheme)
  long implicit_factorizations = -1;
  long implicit_early_refreshes = -1;
  long implicit_stokes_solves = -1;
};

/// |Lk − Lk(0)| beyond which a run warns (once) of a likely self-passage.
inline constexpr double kLinkDriftWarning = 0.1;

/// One trajectory from its configuration to its final files: prepares the output directory (or
/// checks the checkpoint to continue from), builds the Simulation, runs its time loop — writing
/// rows, frames and checkpoints when the Simulation's schedule says so, watching for blow-ups
/// and signals, printing progress — and writes the final state and summary.json.
///
///   Run r(config, options);   // validates; nothing written yet
///   RunResult result = r.execute();
///
/// Under MPI (options.ranks > 1) every rank constructs a Run and calls execute(); rank 0 alone
/// writes files and progress. execute() throws ConfigError (bad config, output directory
/// exists, unusable checkpoint) or RunError (blow-up, I/O failure: disk full, …); a SIGINT or
/// SIGTERM does not throw: the result has `signal` set.
class Run {
 public:
  Run(const config::Config& c, const RunOptions& opt);
  ~Run();
  Run(const Run&) = delete;
  Run& operator=(const Run&) = delete;
  RunResult execute();

  // Step by step (the Python module, python/ibrod): prepare() does what execute() does before
  // its time loop (the output directory, the Simulation, the files; no signal handlers); then
  // each advance() runs the same loop as execute() — the same rows, frames, checkpoints, blow-up
  // checks and final files — for one segment. Not with --resume or MPI.
  void prepare();
  /// Runs the time loop until the end time (set_end_time), a stop rule, `max_steps` steps
  /// (> 0; −1: no limit; the last step then ends the segment as its end time would) or until
  /// `pending` returns a signal number (asked before every step; the segment then stops as
  /// `ibrod run` does on SIGINT: checkpoint, final files, RunResult::signal set). Every segment
  /// ends with the final files (final_state.csv, summary.json) of the run so far.
  RunResult advance(std::int64_t max_steps, const std::function<int()>& pending);
  /// Moves the end of the run to t_end_us (time.t_end_us of the configuration and of
  /// config.toml; validated as the key is). ConfigError if out of range.
  void set_end_time(double t_end_us);
  sim::Simulation& simulation();
  const config::Config& config() const;
  /// The time-series rows so far (RunOptions::keep_rows).
  const std::vector<sim::Observables>& rows() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
};

/// The initial shapes of a fresh run, one entry per rod (config::rod_configs): its
/// rod.initial_shape, or none for the built-in shape. Read and checked before anything is
/// written: each shape fits its rod (sim::state_problem), and the rods' start together (the
/// built-in shapes where no file is given) has no two rods overlapping, across the periodic box's
/// faces too. Throws ConfigError naming the key. `ibrod check` calls it as `ibrod run` does.
using InitialShapes = std::vector<std::optional<rod::RodState>>;
InitialShapes read_initial_shapes(const config::Config& c);

/// Run(c, opt).execute().
RunResult run(const config::Config& c, const RunOptions& opt);

}  // namespace ibrod::driver
