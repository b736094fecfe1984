#pragma once
// The rod's configurations in a run directory — the final state (final_state.csv) and the frames
// of trajectory.h5md — and `ibrod render`, which draws them into DIR/render/*.png.
// Missing or malformed input files throw ConfigError (exit status 2), failed writes RunError (3).
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "analysis/analyze.hpp"
#include "core/types.hpp"

namespace ibrod::analysis {

/// One configuration of the rod.
struct RodFrame {
  std::int64_t step = -1;  ///< −1: unknown
  double time_us = 0;
  std::vector<Vec3> X;   ///< [n], Å
  std::vector<Vec3> d1;  ///< [n], unit
};

/// The final state of a run: DIR/final_state.csv, at the time of summary.json (or the last row
/// of timeseries.csv).
RodFrame read_final_state(const std::filesystem::path& dir);

/// The frames of DIR/trajectory.h5md nearest to each of `times_us` (each frame once, in time
/// order). ConfigError if the file is missing or has no frames.
/// span_us (if given): the first and last frame times.
std::vector<RodFrame> read_trajectory_frames(const std::filesystem::path& dir,
                                             std::span<const double> times_us,
                                             std::pair<double, double>* span_us = nullptr);
/// Every frame of DIR/trajectory.h5md, in time order (ConfigError as above).
std::vector<RodFrame> read_all_trajectory_frames(const std::filesystem::path& dir);

struct RenderOptions {
  std::vector<std::string> times;  ///< µs, or "final"; empty: the final state
  std::vector<std::string> views{"top", "side", "oblique"};
  int width = 800;
  int height = 800;
  bool force = false;  ///< replace pictures that exist (else ConfigError naming the file)
  bool movie = false;  ///< every frame of the trajectory, one view (movie_<view>/, + MP4)
  bool labels = true;  ///< time, Wr, ΔLk and Cs at the top left and a scale bar in Å
  std::string colour = "stripe";  ///< "stripe" | "along" (index along the rod) | "height" (z)
                                  ///< | "twist" (twist density, render::twist_density)
};

/// Parses "WxH" (e.g. "800x600") into width and height; ConfigError if malformed or not in
/// [16, 8192].
void parse_size(const std::string& text, int& width, int& height);

/// Renders the rod of DIR at the requested times (frames of DIR/trajectory.h5md; without one, the
/// final state, with a note on `log`) from each view into DIR/render/rod_<view>_t<time>.png,
/// time in µs with 4 decimals, tube diameter steric.diameter_A of DIR/config.toml. A time
/// outside the trajectory's span is drawn at the nearest frame with a warning on stderr. A
/// picture that exists is not replaced without opt.force (ConfigError naming it, before anything
/// is written). opt.movie: every frame from the first view, all at one scale, into
/// DIR/render/movie_<view>/frame_<i>.png, then DIR/render/rod_<view>.mp4 with ffmpeg if it is
/// on PATH (else a note says so). Prints each file written to `log` (nullptr: silent). Returns
/// the files written.
std::vector<std::filesystem::path> render_run(const std::filesystem::path& dir,
                                              const RenderOptions& opt, std::FILE* log = stdout);

}  // namespace ibrod::analysis
