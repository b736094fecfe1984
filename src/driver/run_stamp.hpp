#pragma once
// What identifies a run beyond its keys, kept where --resume can compare it: the run's id (drawn
// when the run starts) and the CRC-32 of each input file its keys name (rod.moduli_file,
// rod.intrinsic_file; with [[rods]] each rod's). Written after the keys of config.toml as TOML
// comments (so the file stays re-runnable as is) and thereby into the checkpoint's copy of it:
//
//   # run_id = 3f9c0a1b2c4d5e6f
//   # input rod.moduli_file = "moduli.csv" crc32 0a1b2c3d
//
// --resume refuses a checkpoint whose run id is not config.toml's (another run's checkpoint),
// and lists an input file whose content changed as it lists a changed key.
#include <string>
#include <utility>
#include <vector>

#include "config/config.hpp"

namespace ibrod::driver {

struct RunStamp {
  std::string run_id;  ///< 16 hex digits ("" for a run written before ids)
  /// (key, "\"path\" crc32 xxxxxxxx") of each input file, in key order
  std::vector<std::pair<std::string, std::string>> inputs;
};

/// A new run id: 16 hex digits from the clock, the PID and std::random_device.
std::string new_run_id();

/// The input files of c with the CRC-32 of their content now ("unreadable" in place of the CRC if
/// a file cannot be read: to_params then refuses it, naming why).
std::vector<std::pair<std::string, std::string>> input_checksums(const config::Config& c);

/// The comment lines of a stamp (appended to config.toml's text).
std::string stamp_text(const RunStamp& s);

/// The stamp in a config.toml text (or a checkpoint's copy of it); empty fields where absent.
RunStamp read_stamp(const std::string& config_text);

/// "key (its content, CRC-32): old → new" for each input file in both whose content differs,
/// joined by "; " ("" if none, or if `old` has no inputs recorded).
std::string input_differences(const RunStamp& old, const RunStamp& now);

}  // namespace ibrod::driver
