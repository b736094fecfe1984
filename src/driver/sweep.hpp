#pragma once
// Parameter sweeps (`ibrod sweep SWEEP.toml [-j K]`, docs/sweeps.md): the product of lists of
// config values, one output directory per point with a stable name, run as separate `ibrod run`
// processes (K at a time, or shared among MPI ranks), skipping finished points and resuming
// interrupted ones from their checkpoints.
//
// A sweep file is an ordinary config (sections [grid], [rod], …, on top of an optional
// `base = "file.toml"`, a path relative to the sweep file) plus
//   output_dir = "runs/study"      # optional: the root of the point directories
//   [names]                        # optional: the short name of a key in point names
//   "solvent.salt_M" = "cs"
//   [sweep]                        # key → list of values; the points are the product
//   "rod.excess_link" = [1, 2, 3]  # (rod.excess_link = [...] without quotes is the same)
//   "solvent.salt_M" = [0.01, 0.1]
// The first key varies slowest. A key may also be a sub-key of a table-valued key, e.g.
// "rod.perturbation_random.seed" = [1, 2, 3].
//
// Layout under the output root:
//   points.csv             index,name,<swept keys…>: every point (written once, by rank 0)
//   configs/NAME.toml      the resolved configuration of each point (re-runnable as is)
//   logs/NAME.log          the output of the point's `ibrod run` processes (appended)
//   NAME/                  the point's run directory (README.md: what `ibrod run` writes)
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "config/config.hpp"

namespace ibrod::driver {

struct SweepAxis {
  std::string key;                  ///< config path, "rod.excess_link"
  std::string short_name;           ///< its name in point names, "dlk"
  std::vector<std::string> values;  ///< TOML text of each value, "4", "0.1"
  std::vector<std::string> labels;  ///< each value as it appears in point names
};

struct SweepPoint {
  std::size_t index = 0;  ///< position in the product (first axis slowest)
  std::string name;       ///< directory name: "dlk=4_salt_M=0.1"
  std::vector<std::pair<std::string, std::string>> assignments;  ///< key → TOML value text
  config::Config config;          ///< resolved and validated
};

struct Sweep {
  std::string source;               ///< the sweep file (for messages)
  std::string output_root;          ///< `output_dir = …` of the file ("" if absent)
  std::vector<SweepAxis> axes;
  std::vector<SweepPoint> points;
};

/// Parses a sweep document. dir: the directory that `base = …` is relative to. Throws
/// ConfigError naming the offending key (a [sweep] key that is no config key, a value that is
/// not a list or is empty, a value the config rejects, a point that fails the cross-key checks,
/// two points with the same name).
Sweep parse_sweep(const std::string& text, const std::string& source,
                  const std::filesystem::path& dir);
/// Reads and parses a sweep file.
Sweep load_sweep(const std::filesystem::path& file);

/// A value as a piece of a directory name: numbers in shortest round-trip form ("0.1", "1e-05"),
/// strings as they are; every character outside [A-Za-z0-9._+=,-] becomes '-'.
std::string sanitize_name(const std::string& s);

/// What a point's directory holds.
enum class PointState {
  fresh,        ///< absent or empty: run it
  no_checkpoint,  ///< files but no checkpoint (killed before the first one): run it with --overwrite
  interrupted,  ///< a checkpoint and no final summary: `ibrod run --resume`
  finished,     ///< summary.json says end_time or equilibrium: skip
  failed,       ///< summary.json says blow_up: not run again (delete the directory to retry)
};
PointState point_state(const std::filesystem::path& dir);
const char* to_string(PointState s);

struct SweepOptions {
  std::filesystem::path output_root;  ///< where the point directories go
  int jobs = 1;                       ///< `ibrod run` processes at a time (per rank)
  std::string binary;                 ///< the ibrod to spawn ("": /proc/self/exe)
  int rank = 0, ranks = 1;            ///< this rank runs points with index % ranks == rank
  bool handle_signals = true;         ///< SIGINT/SIGTERM: pass on to the runs, wait, return
  std::FILE* log = stdout;            ///< progress lines (nullptr: silent)
};

struct SweepReport {
  int points = 0;       ///< this rank's share
  int skipped = 0;      ///< already finished
  int fresh = 0;        ///< started from the beginning
  int resumed = 0;      ///< continued from a checkpoint
  int completed = 0;    ///< finished by this invocation
  int failed = 0;       ///< failed now or before (blow-up), or stale
  int signal = 0;       ///< SIGINT/SIGTERM that stopped the sweep (0: none)
  std::vector<std::string> failed_names;
};

/// Runs this rank's points that are not finished, `jobs` at a time, each as
/// `BINARY run configs/NAME.toml -o NAME` or `BINARY run --resume NAME`. A failed point is
/// reported and the others go on. A finished point whose config.toml differs from the sweep's
/// is counted as failed (stale) and left alone. Throws RunError only if the output root cannot
/// be written.
SweepReport run_sweep(const Sweep& sweep, const SweepOptions& opt);

/// points.csv: index,name,<keys> (header and one row per point).
std::string points_csv(const Sweep& sweep);

}  // namespace ibrod::driver
