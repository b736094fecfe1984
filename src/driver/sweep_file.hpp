#pragma once
// Sweep files (`ibrod sweep SWEEP.toml`, docs/sweeps.md): the product of lists of config values,
// one point per combination with a stable name; driver/sweep_runner.hpp runs them.
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
// The layout of the output root: driver/sweep_runner.hpp (SweepDir).
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
  config::Config config;                                         ///< resolved and validated
};

struct Sweep {
  std::string source;       ///< the sweep file (for messages)
  std::string output_root;  ///< `output_dir = …` of the file ("" if absent)
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

/// points.csv: index,name,<keys> (header and one row per point).
std::string points_csv(const Sweep& sweep);

}  // namespace ibrod::driver
