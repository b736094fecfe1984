#pragma once
// Running a sweep (`ibrod sweep SWEEP.toml [-j K]`, docs/sweeps.md): every point of a Sweep
// (driver/sweep_file.hpp) as its own `ibrod run` process, K at a time or shared among MPI ranks,
// skipping finished points and resuming interrupted ones from their checkpoints.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "driver/sweep_file.hpp"

namespace ibrod::driver {

/// The names under a sweep's output root:
///   points.csv          index,name,<swept keys…>: every point (written once, by rank 0)
///   configs/NAME.toml   the resolved configuration of each point (re-runnable as is)
///   logs/NAME.log       the output of the point's `ibrod run` processes (appended)
///   NAME/               the point's run directory (io::RunDir)
struct SweepDir {
  std::filesystem::path root;
  std::filesystem::path points() const { return root / "points.csv"; }
  std::filesystem::path configs() const { return root / "configs"; }
  std::filesystem::path logs() const { return root / "logs"; }
  std::filesystem::path config(const std::string& name) const {
    return configs() / (name + ".toml");
  }
  std::filesystem::path log(const std::string& name) const { return logs() / (name + ".log"); }
  std::filesystem::path run(const std::string& name) const { return root / name; }
};

/// What a point's directory holds.
enum class PointState {
  fresh,          ///< absent or empty: run it
  no_checkpoint,  ///< files but no checkpoint (killed before the first one): run it with
                  ///< --overwrite
  interrupted,    ///< a checkpoint and no final summary: `ibrod run --resume`
  finished,       ///< summary.json says end_time or equilibrium: skip
  failed,         ///< summary.json says blow_up: not run again (delete the directory to retry)
  running,        ///< another process holds the directory's lock (driver/dir_lock.hpp): not started
};
PointState point_state(const std::filesystem::path& dir);
const char* to_string(PointState s);

struct SweepOptions {
  std::filesystem::path output_root;  ///< where the point directories go
  int jobs = 1;                       ///< `ibrod run` processes at a time (per rank)
  std::string binary;                 ///< the ibrod to spawn ("": /proc/self/exe)
  int rank = 0, ranks = 1;            ///< this rank runs points with index % ranks == rank
  long only_point = -1;               ///< ≥ 0: run this point alone (a job array's task)
  bool handle_signals = true;         ///< SIGINT/SIGTERM: pass on to the runs, wait, return
  std::FILE* log = stdout;            ///< progress lines (nullptr: silent)
};

struct SweepReport {
  int points = 0;     ///< this rank's share
  int skipped = 0;    ///< already finished
  int fresh = 0;      ///< started from the beginning
  int resumed = 0;    ///< continued from a checkpoint
  int completed = 0;  ///< finished by this invocation
  int failed = 0;     ///< failed now or before (blow-up), or stale
  int running = 0;    ///< written by another process (its lock is held): not started
  int signal = 0;     ///< SIGINT/SIGTERM that stopped the sweep (0: none)
  std::vector<std::string> failed_names;
};

/// Runs this rank's points that are not finished, `jobs` at a time, each as
/// `BINARY run configs/NAME.toml -o NAME` or `BINARY run --resume NAME`. A failed point is
/// reported and the others go on. A finished point whose config.toml differs from the sweep's
/// is counted as failed (stale) and left alone. Throws RunError only if the output root cannot
/// be written.
SweepReport run_sweep(const Sweep& sweep, const SweepOptions& opt);

}  // namespace ibrod::driver
