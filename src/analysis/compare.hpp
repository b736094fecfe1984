#pragma once
// `ibrod compare RUN_A RUN_B` (issue 24 item 4; docs/analysis.md "Comparing two runs"): two runs
// of one system side by side — typically the implicit scheme against the explicit reference — at
// the times both wrote: the largest |ΔWr|, |ΔE_total| and |Δ closest approach| over the common
// rows of timeseries.csv, the last common row's ΔWr and ΔE_total, and the shape class and loop
// count of the frames at common times, with the differences that are not within a guard time of
// a change of shape in either run (shape_mismatches). Every Δ is B − A.
// The comparison itself (run_series … compare_json) is pure functions of the data;
// read_compared_run / compare_run_dirs read a run directory. Missing or malformed input throws
// ConfigError naming the file (exit status 2).
#include <cstddef>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "analysis/shapes.hpp"
#include "diagnostics/shape.hpp"
#include "io/csv.hpp"

namespace ibrod::analysis {

/// The columns of one run's time series that a comparison needs, in strictly increasing time.
struct RunSeries {
  std::vector<double> time_us;             ///< µs
  std::vector<double> writhe;              ///< NaN where not defined (an open rod)
  std::vector<double> E_total_kT;          ///< kT
  std::vector<double> closest_approach_A;  ///< Å
};

/// The series of timeseries.csv's time_us, writhe, E_total_kT and closest_approach_A, rows in
/// increasing time (increasing_rows: a rewritten stretch's later rows win). ConfigError naming
/// the file if a column is missing.
RunSeries run_series(const io::CsvTable& table);

struct CompareOptions {
  double time_tolerance_us = 1e-6;  ///< two times are common when they differ by at most this
  double guard_us = 0.5;            ///< a shape difference within this of a change in either run is
                          ///< not a mismatch (the two runs need not change at the same frame)
};

/// The common times of two increasing time lists: pairs (i, j) with |a_i − b_j| ≤ tolerance, in
/// increasing time, each index in at most one pair (a merge of the two lists: O(|a| + |b|)).
std::vector<std::pair<std::size_t, std::size_t>> common_times(std::span<const double> a,
                                                              std::span<const double> b,
                                                              double tolerance_us);

/// The times at which a run's shape changes: the time of every frame whose class or loop count
/// differs from the frame before it (the first frame that shows the new shape). Frames in
/// increasing time.
std::vector<double> shape_changes(std::span<const ShapeRecord> frames);

/// How the shapes of the two runs compare at one frame.
enum class FrameFlag {
  same,      ///< same class and loop count
  guarded,   ///< they differ, within guard_us of a shape change of either run
  mismatch,  ///< they differ, farther than guard_us from every change
};
/// "", "guard", "MISMATCH".
const char* frame_flag_name(FrameFlag f);

/// One frame at a common time, with the time series' values at that time (NaN when a run wrote
/// no row there).
struct FrameComparison {
  double time_us = 0;
  double writhe_a = 0, writhe_b = 0;          ///< NaN: no row at this time
  double E_total_a_kT = 0, E_total_b_kT = 0;  ///< NaN: no row at this time
  diagnostics::ShapeClass class_a = diagnostics::ShapeClass::other;
  diagnostics::ShapeClass class_b = diagnostics::ShapeClass::other;
  int loops_a = 0, loops_b = 0;
  FrameFlag flag = FrameFlag::same;
};

/// The comparison of run B against run A. Maxima are of |B − A| over the common rows, with the
/// (first) time where they occur; NaN (and time NaN) when no common row has a finite difference
/// (an open rod has no writhe). The final values are signed, B − A, at the last common row.
struct Comparison {
  std::string run_a, run_b;  ///< the directories (empty for compare_runs on data)
  std::size_t rows_a = 0, rows_b = 0;
  std::size_t common_rows = 0;
  double max_abs_dwr = 0, max_abs_dwr_time_us = 0;
  double max_abs_de_kT = 0, max_abs_de_time_us = 0;
  double max_abs_dclosest_A = 0, max_abs_dclosest_time_us = 0;
  double final_time_us = 0;
  double final_dwr = 0, final_de_kT = 0;
  // shapes
  bool shapes_compared = false;  ///< false: neither frames nor mismatches (shapes_note says why)
  std::string shapes_note;
  double contact_distance_a_A = 0, contact_distance_b_A = 0;  ///< d_c of each run's shapes
  std::size_t frames_a = 0, frames_b = 0;
  std::vector<double> changes_a, changes_b;  ///< shape_changes of each run, µs
  std::vector<FrameComparison> frames;       ///< every frame at a common time
  std::size_t shape_mismatches = 0;          ///< frames flagged mismatch
  std::size_t shape_guarded = 0;             ///< frames flagged guarded
};

/// Compares the series and the frames' shapes of run B with those of run A (frames in increasing
/// time). With no frame in either run the shapes are not compared. ConfigError if the series
/// have no common time (the message names the time spans).
Comparison compare_runs(const RunSeries& a, const RunSeries& b,
                        std::span<const ShapeRecord> frames_a,
                        std::span<const ShapeRecord> frames_b, const CompareOptions& opt = {});

/// The limits of `ibrod compare`'s verdict; none given: no verdict.
struct CompareLimits {
  std::optional<double> max_dwr;          ///< on max |ΔWr| over the common rows
  std::optional<double> max_de_kT;        ///< on max |ΔE_total| over the common rows, kT
  std::optional<double> max_final_de_kT;  ///< on |ΔE_total| at the last common row, kT
  bool any() const { return max_dwr || max_de_kT || max_final_de_kT; }
};

/// Why `c` fails `limits`, one sentence each; empty when it passes or no limit is given. With a
/// limit given, every shape mismatch is a failure too, and a maximum that is not defined (NaN)
/// fails its limit.
std::vector<std::string> compare_failures(const Comparison& c, const CompareLimits& limits);

/// The per-frame table: a header, then per frame t, Wr_A, Wr_B, ΔWr, E_A, E_B, ΔE, class/loops
/// of A and of B and the flag ("" / "guard" / "MISMATCH"); "-" where a run wrote no row.
std::string compare_table(const Comparison& c);

/// One line: "compare: common_rows=… common_frames=… max_dWr=… at t=… max_dE_kT=… at t=…
/// final_t=… final_dWr=… final_dE_kT=… max_dclosest_A=… at t=… shape_mismatches=… guarded=…"
/// (no newline; shape_mismatches=n/a when the shapes were not compared).
std::string compare_summary(const Comparison& c);

/// The same numbers, the limits (null when not given), the verdict (`passed`: null without
/// limits) with its failures, and the per-frame table, as a JSON document.
std::string compare_json(const Comparison& c, const CompareLimits& limits,
                         const std::vector<std::string>& failures);

// ---- run directories

/// What a comparison reads of one run directory.
struct ComparedRun {
  std::filesystem::path dir;
  RunSeries series;
  std::vector<ShapeRecord> frames;  ///< every frame's shape (empty: see shapes_note)
  double contact_distance_A = 0;
  std::string shapes_note;  ///< why there are no frames ("" when there are)
};

/// Reads DIR/timeseries.csv, DIR/config.toml and the frames of DIR's trajectory (io::RunDir
/// names every file) and classifies every frame (analyze_shapes, d_c = contact_distance_A, or
/// D + 3 λ_D of config.toml when 0). ConfigError naming the directory or file if it is missing or
/// malformed; an open rod or several rods have no shapes to compare (shapes_note), a closed ring
/// without a trajectory is an error.
ComparedRun read_compared_run(const std::filesystem::path& dir, double contact_distance_A = 0);

/// read_compared_run of both, then compare_runs; the shapes are compared only when both runs
/// have frames.
Comparison compare_run_dirs(const std::filesystem::path& a, const std::filesystem::path& b,
                            const CompareOptions& opt = {}, double contact_distance_A = 0);

}  // namespace ibrod::analysis
