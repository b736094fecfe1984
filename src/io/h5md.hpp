#pragma once
// Trajectory in HDF5 after the H5MD 1.1 conventions (https://www.nongnu.org/h5md/h5md.html),
// readable with h5py alone. Layout (T: frames so far, R: time-series rows so far, n rod points):
//
//   /h5md                         attribute version = [1, 1]
//   /h5md/author                  attribute name ($USER)
//   /h5md/creator                 attributes name = "ibrod", version
//   /particles/trajectory         soft link to /particles/rod (MDAnalysis counts atoms there)
//   /particles/rod/box            attributes dimension = 3, boundary = ["periodic" × 3];
//                                 edges: step, time, value [T, 3, 3] f64, Å (the box vectors as
//                                 rows; [T, 3] in older files, which are extended so)
//   /particles/rod/position       step [T] i64, time [T] f64 (µs), value [T, n, 3] f64 (Å,
//                                 unwrapped: never folded into the box)
//   /particles/rod/d1, d2, d3     step, time, value [T, n, 3]: the triad columns D¹, D², D³
//   /particles/rod/species        [n] i32, several rods only: each point's rod (0, 1, …)
//   /observables/<column>         step [R] i64, time [R] f64 (µs), value [R] f64, one group per
//                                 timeseries.csv column other than step and time_us
//   /parameters/config_toml       scalar string: config.toml of the run
//
// Every time-dependent dataset is chunked and extendible along its first axis; value datasets
// hold one frame per chunk. Strings are variable-length UTF-8. The file is flushed (H5Fflush)
// after every frame and row, so a killed run leaves a readable file up to its last flush.
// HDF5 errors become RunError with HDF5's own description (e.g. "No space left on device").
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "rod/rod.hpp"
#include "sim/simulation.hpp"

namespace ibrod::io {

class H5mdWriter {
 public:
  /// Creates `path` (replacing any file there) with the layout above and no frames.
  /// `species` (several rods: each point's rod, n values) is written as the time-independent
  /// /particles/rod/species [n] (int32, H5MD's element for a particle's kind); none when empty.
  static std::unique_ptr<H5mdWriter> create(const std::filesystem::path& path, int n, double box_A,
                                            const std::string& config_toml,
                                            const std::vector<int>& species = {});
  /// Opens an existing file to continue a run: every frame and row with step > last_step is
  /// dropped, and /parameters/config_toml is set to config_toml. Throws RunError if the file
  /// cannot be opened or does not have the layout for n points.
  static std::unique_ptr<H5mdWriter> reopen(const std::filesystem::path& path, int n, double box_A,
                                            std::int64_t last_step, const std::string& config_toml);
  ~H5mdWriter();
  H5mdWriter(const H5mdWriter&) = delete;
  H5mdWriter& operator=(const H5mdWriter&) = delete;

  /// Appends one frame (positions and triads at `step`, time in µs) and flushes.
  void write_frame(std::int64_t step, double time_us, const rod::RodState& s);
  /// Appends one row to every /observables group and flushes.
  void write_observables(const sim::Observables& o);
  /// Frames in the file.
  std::int64_t frames() const { return frames_; }

 private:
  H5mdWriter() = default;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::int64_t frames_ = 0;
};

/// One element of /particles/rod, every frame (analysis::read_trajectory_frames reads frames so).
struct H5mdSeries {
  std::vector<std::int64_t> step;  ///< [T]
  std::vector<double> time_us;     ///< [T]
  std::vector<double> value;       ///< [T × n × 3], row-major
  int n = 0;
};

/// Reads /particles/rod/<element> ("position", "d1", "d2" or "d3"). Throws RunError.
H5mdSeries read_h5md_series(const std::filesystem::path& path, const std::string& element);

}  // namespace ibrod::io
