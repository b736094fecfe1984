// The rod's frames of a run directory (final_state.csv, trajectory.h5md) and `ibrod render`.
#include "analysis/frames.hpp"

#include <toml++/toml.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>

#include "config/config.hpp"
#include "config/toml_error.hpp"
#include "core/error.hpp"
#include "core/text_file.hpp"
#include "diagnostics/topology.hpp"
#include "io/csv.hpp"
#include "io/h5md.hpp"
#include "io/run_dir.hpp"
#include "render/image.hpp"
#include "render/render.hpp"

namespace ibrod::analysis {

using namespace ibrod::io;

namespace fs = std::filesystem;

namespace {

std::string time_label(double t_us) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4f", t_us);
  return buf;
}

// The frames frame_%05d.png of `frames_dir` as an H.264 MP4 at 10 frames/s with ffmpeg, if it is
// on PATH: the file written, or "" without ffmpeg. A failed ffmpeg is a RunError.
std::string encode_movie(const fs::path& frames_dir, const fs::path& mp4) {
  if (std::system("command -v ffmpeg >/dev/null 2>&1") != 0) return "";
  const std::string cmd = "ffmpeg -y -loglevel error -framerate 10 -i '" + frames_dir.string() +
                          "/frame_%05d.png' -vf 'scale=trunc(iw/2)*2:trunc(ih/2)*2' -pix_fmt "
                          "yuv420p '" +
                          mp4.string() + "' </dev/null";
  if (frames_dir.string().find('\'') != std::string::npos ||
      mp4.string().find('\'') != std::string::npos)
    throw RunError("render: cannot pass a path with a quote (') to ffmpeg: " + mp4.string());
  if (std::system(cmd.c_str()) != 0) throw RunError("render: ffmpeg failed: " + cmd);
  return mp4.string();
}

}  // namespace

RodFrame read_final_state(const fs::path& dir) {
  const CsvTable s = read_csv_table(RunDir(dir).final_state());
  RodFrame f;
  const auto x = s.column("x_A"), y = s.column("y_A"), z = s.column("z_A");
  const auto a = s.column("d1x"), b = s.column("d1y"), c = s.column("d1z");
  for (std::size_t k = 0; k < s.rows(); ++k) {
    f.X.emplace_back(x[k], y[k], z[k]);
    f.d1.emplace_back(a[k], b[k], c[k]);
  }
  if (f.X.size() < 2) throw ConfigError("'" + s.path.string() + "' holds fewer than 2 points");
  // a file cut short (a copy broken off, a disk that filled) is no shape to draw: its last line
  // whole, and its rows the run's rod points where config.toml gives their number (a run's
  // config.toml has every key; a hand-made one may not)
  int points = -1;
  const fs::path cfg = RunDir(dir).config();
  if (fs::exists(cfg)) {
    try {
      const std::string ct = read_text_file(cfg, "render");
      const toml::table tbl = config::parse_toml(ct, cfg.string(), "render");
      if (tbl["rod"]["base_pairs"] || tbl["rods"])
        points = config::point_count(config::load_config(cfg.string()));
    } catch (const ConfigError&) {
      // a config.toml that cannot be read: only the file's own shape is checked
    }
  }
  const std::string text = read_text_file(s.path, "render");
  const bool cut = text.empty() || text.back() != '\n';
  if ((points > 0 && int(f.X.size()) != points) || cut)
    throw ConfigError("'" + s.path.string() + "' is truncated or damaged: it holds " +
                      std::to_string(f.X.size()) + " whole rows" +
                      (points > 0
                           ? ", the run has " + std::to_string(points) + " rod points (config.toml)"
                           : std::string()) +
                      (cut ? ", and its last line is cut off" : std::string()));
  // its time: summary.json, else the last row of timeseries.csv
  f.time_us = std::numeric_limits<double>::quiet_NaN();
  const fs::path sp = RunDir(dir).summary();
  if (fs::exists(sp)) {
    try {
      const auto j = nlohmann::json::parse(read_text_file(sp, "analyze"));
      if (j.contains("time_us") && j["time_us"].is_number()) f.time_us = j["time_us"].get<double>();
      if (j.contains("steps") && j["steps"].is_number_integer())
        f.step = j["steps"].get<std::int64_t>();
    } catch (const nlohmann::json::exception&) {
      // fall through to the time series
    }
  }
  if (!std::isfinite(f.time_us) && fs::exists(RunDir(dir).timeseries())) {
    const CsvTable ts = read_csv_table(RunDir(dir).timeseries());
    if (ts.rows() > 0) {
      f.time_us = ts.column("time_us").back();
      if (ts.has("step")) f.step = std::int64_t(ts.column("step").back());
    }
  }
  if (!std::isfinite(f.time_us)) f.time_us = 0;
  return f;
}

namespace {

// Frames i of the series (pos, d1), in the order given.
std::vector<RodFrame> frames_of(const H5mdSeries& pos, const H5mdSeries& d1,
                                const std::vector<std::size_t>& picks) {
  std::vector<RodFrame> frames;
  const std::size_t n = std::size_t(pos.n), T = pos.time_us.size();
  for (std::size_t i : picks) {
    RodFrame f;
    f.step = pos.step.size() == T ? pos.step[i] : -1;
    f.time_us = pos.time_us[i];
    for (std::size_t k = 0; k < n; ++k) {
      const double* x = &pos.value[3 * (i * n + k)];
      const double* d = &d1.value[3 * (i * n + k)];
      f.X.emplace_back(x[0], x[1], x[2]);
      f.d1.emplace_back(d[0], d[1], d[2]);
    }
    frames.push_back(std::move(f));
  }
  return frames;
}

void read_series(const fs::path& dir, H5mdSeries& pos, H5mdSeries& d1) {
  const fs::path p = RunDir(dir).trajectory();
  if (!fs::exists(p)) throw ConfigError("'" + p.string() + "' does not exist");
  try {
    pos = read_h5md_series(p, "position");
    d1 = read_h5md_series(p, "d1");
  } catch (const RunError& e) {
    throw ConfigError(std::string("cannot read the trajectory: ") + e.what());
  }
  const std::size_t T = pos.time_us.size();
  if (T == 0 || pos.n < 2 || d1.time_us.size() != T || d1.n != pos.n)
    throw ConfigError("'" + p.string() + "' has no frames (or position and d1 disagree)");
}

}  // namespace

std::vector<RodFrame> read_all_trajectory_frames(const fs::path& dir) {
  H5mdSeries pos, d1;
  read_series(dir, pos, d1);
  std::vector<std::size_t> all(pos.time_us.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return frames_of(pos, d1, all);
}

std::vector<RodFrame> read_trajectory_frames(const fs::path& dir, std::span<const double> times_us,
                                             std::pair<double, double>* span_us) {
  H5mdSeries pos, d1;
  read_series(dir, pos, d1);
  const std::size_t T = pos.time_us.size();
  if (span_us) *span_us = {pos.time_us.front(), pos.time_us.back()};
  std::vector<std::size_t> picks;
  for (double want : times_us) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < T; ++i)
      if (std::abs(pos.time_us[i] - want) < std::abs(pos.time_us[best] - want)) best = i;
    picks.push_back(best);
  }
  std::sort(picks.begin(), picks.end());
  picks.erase(std::unique(picks.begin(), picks.end()), picks.end());
  return frames_of(pos, d1, picks);
}

// ---- render

void parse_size(const std::string& text, int& width, int& height) {
  const auto x = text.find_first_of("xX");
  int w = 0, h = 0;
  bool ok = x != std::string::npos;
  if (ok) {
    char* end = nullptr;
    const std::string a = text.substr(0, x), b = text.substr(x + 1);
    w = int(std::strtol(a.c_str(), &end, 10));
    ok = !a.empty() && *end == '\0';
    h = int(std::strtol(b.c_str(), &end, 10));
    ok = ok && !b.empty() && *end == '\0';
  }
  if (!ok || w < 16 || h < 16 || w > 8192 || h > 8192)
    throw ConfigError("--size '" + text + "': expected WxH with 16 ≤ W, H ≤ 8192, e.g. 800x600");
  width = w;
  height = h;
}

std::vector<fs::path> render_run(const fs::path& dir, const RenderOptions& opt, std::FILE* log) {
  if (!fs::is_directory(dir)) throw ConfigError("'" + dir.string() + "' is not a directory");
  if (opt.width < 1 || opt.height < 1) throw ConfigError("render: the image size must be positive");
  std::vector<render::View> views;
  for (const auto& v : opt.views) {
    try {
      views.push_back(render::standard_view(v));
    } catch (const std::invalid_argument& e) {
      throw ConfigError(std::string("--views: ") + e.what());
    }
  }
  if (views.empty()) throw ConfigError("--views: no view given");

  // which states: "final" and times in µs
  bool want_final = opt.times.empty();
  std::vector<double> times;
  for (const auto& s : opt.times) {
    double v = 0;
    if (s == "final") {
      want_final = true;
    } else if (io::parse_double(s, v) && std::isfinite(v) && v >= 0) {
      times.push_back(v);
    } else {
      throw ConfigError("--time '" + s + "': expected a time in µs (≥ 0) or 'final'");
    }
  }
  std::vector<RodFrame> frames;
  if (opt.movie) {
    frames = read_all_trajectory_frames(dir);
  } else if (!times.empty()) {
    if (fs::exists(RunDir(dir).trajectory())) {
      std::pair<double, double> span;
      frames = read_trajectory_frames(dir, times, &span);
      // a time outside the trajectory is drawn at its nearest end: say so (to stderr)
      const double slack = 1e-9 + 1e-9 * std::abs(span.second);
      for (double t : times)
        if (t < span.first - slack || t > span.second + slack)
          std::fprintf(stderr,
                       "ibrod render: warning: --time %s us is outside the trajectory (t = %s to "
                       "%s us): drawing the frame at t = %s us\n",
                       time_label(t).c_str(), time_label(span.first).c_str(),
                       time_label(span.second).c_str(),
                       time_label(t < span.first ? span.first : span.second).c_str());
      if (log)
        for (const auto& f : frames)
          std::fprintf(log, "render: frame at t = %s us (step %lld)\n",
                       time_label(f.time_us).c_str(), static_cast<long long>(f.step));
    } else {
      if (log)
        std::fprintf(log,
                     "render: no trajectory.h5md in %s: drawing the final state instead of "
                     "--time\n",
                     dir.c_str());
      want_final = true;
    }
  }
  if (want_final && !opt.movie) frames.push_back(read_final_state(dir));

  const RunInfo info = read_run_info(dir);
  const fs::path out = RunDir(dir).render_dir();
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw RunError("render: cannot create '" + out.string() + "': " + ec.message());
  // the files, checked before anything is drawn: an existing picture is never silently replaced
  std::vector<std::pair<fs::path, std::size_t>> jobs;  // file, frame (× view below)
  std::vector<render::View> job_view;
  const fs::path movie_dir = out / ("movie_" + views.front().name);
  if (opt.movie) {
    for (std::size_t i = 0; i < frames.size(); ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05zu.png", i);
      jobs.push_back({movie_dir / name, i});
      job_view.push_back(views.front());
    }
  } else {
    for (std::size_t i = 0; i < frames.size(); ++i)
      for (const auto& v : views) {
        jobs.push_back(
            {out / ("rod_" + v.name + "_t" + time_label(frames[i].time_us) + ".png"), i});
        job_view.push_back(v);
      }
  }
  const fs::path movie_file = out / ("rod_" + views.front().name + ".mp4");
  const fs::path apng_file = out / ("rod_" + views.front().name + ".apng");
  if (!opt.force) {
    for (const auto& [file, i] : jobs)
      if (fs::exists(file))
        throw ConfigError("render: '" + file.string() +
                          "' exists (an earlier render, perhaps at another --size); give "
                          "--force to replace it, or move it away");
    for (const fs::path& m : {movie_file, apng_file})
      if (opt.movie && fs::exists(m))
        throw ConfigError("render: '" + m.string() +
                          "' exists; give --force to replace it, or move it away");
  }
  if (opt.movie) {
    fs::create_directories(movie_dir, ec);
    if (ec) throw RunError("render: cannot create '" + movie_dir.string() + "': " + ec.message());
    // a frame left from a longer earlier movie would join this one
    for (const auto& e : fs::directory_iterator(movie_dir))
      if (e.path().extension() == ".png") fs::remove(e.path());
  }
  // a movie keeps one scale and centre: every frame's points frame every picture
  std::vector<Vec3> all_points;
  if (opt.movie)
    for (const auto& f : frames) all_points.insert(all_points.end(), f.X.begin(), f.X.end());

  render::Style style;
  if (opt.colour == "along")
    style.colouring = render::Colouring::along;
  else if (opt.colour == "height")
    style.colouring = render::Colouring::height;
  else if (opt.colour == "twist")
    style.colouring = render::Colouring::twist;
  else if (opt.colour != "stripe")
    throw ConfigError("--colour '" + opt.colour + "': expected stripe, along, height or twist");
  // labels need about 50 px of height and 130 of width (font 5×7 px): smaller pictures go without
  const bool labels = opt.labels && opt.height >= 120 && opt.width >= 160;
  if (opt.labels && !labels && log)
    std::fprintf(log, "render: no labels or scale bar below 160x120 pixels\n");
  style.scale_bar = style.axis_triad = labels;

  std::vector<fs::path> written;
  // the movie as an animated PNG too (any browser plays it; no ffmpeg needed), 10 frames/s
  std::optional<render::ApngWriter> apng;
  if (opt.movie) {
    try {
      apng.emplace(apng_file.string(), opt.width, opt.height, int(jobs.size()), 10);
    } catch (const std::runtime_error& e) {
      throw RunError(std::string("render: ") + e.what());
    }
  }
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    const auto& [file, i] = jobs[j];
    const RodFrame& f = frames[i];
    const std::vector<rod::RodRange> rods = info.layout(int(f.X.size()));
    if (labels) {
      char wr[192], lk[96];
      // each rod's writhe where it is defined (an open rod's twist: docs/model.md "Open rods"),
      // in order
      std::string w;
      for (const rod::RodRange& g : rods) {
        const auto at = std::size_t(g.offset), m = std::size_t(g.n);
        const std::span<const Vec3> x = std::span<const Vec3>(f.X).subspan(at, m);
        const std::span<const Vec3> d = std::span<const Vec3>(f.d1).subspan(at, m);
        const bool wr = diagnostics::link_defined(g);
        char one[40];
        std::snprintf(one, sizeof one, "%s%s = %.3f", w.empty() ? "" : "  ", wr ? "Wr" : "Tw",
                      wr ? diagnostics::writhe(x) : diagnostics::twist_open(x, d));
        w += one;
      }
      std::snprintf(wr, sizeof wr, "%s", w.substr(0, sizeof wr - 1).c_str());
      // the collection (rods named: their count), or the ring's excess link
      if (rod::names_rods(rods))
        std::snprintf(lk, sizeof lk, "%s   Cs = %g M", rod::count_label(rods).c_str(), info.salt_M);
      else if (rod::one_ring(rods))
        std::snprintf(lk, sizeof lk, "ΔLk = %d   Cs = %g M", info.excess_link, info.salt_M);
      else
        std::snprintf(lk, sizeof lk, "Cs = %g M", info.salt_M);
      style.labels = {"t = " + time_label(f.time_us) + " µs", wr, lk};
    }
    render::Image img;
    try {
      img = render::render_rods(f.X, f.d1, rods, info.diameter_A, job_view[j], opt.width,
                                opt.height, style, all_points);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(std::string("render: ") + e.what() + " (a larger --size, or --no-labels)");
    }
    try {
      render::write_png(file.string(), img);
      if (apng) apng->add(img);
    } catch (const std::runtime_error& e) {
      throw RunError(std::string("render: ") + e.what());
    }
    if (log && !opt.movie) std::fprintf(log, "%s\n", file.c_str());
    if (log && !opt.movie && style.colouring == render::Colouring::twist) {
      const auto tw = render::twist_density(f.X, f.d1);  // rad/Å, per segment
      const auto [lo, hi] = std::minmax_element(tw.begin(), tw.end());
      constexpr double deg_per_nm = 10 * 180 / std::numbers::pi;
      std::fprintf(log, "render: twist colour from %.3g (blue) to %.3g (red) deg/nm\n",
                   *lo * deg_per_nm, *hi * deg_per_nm);
    }
    written.push_back(file);
  }
  if (opt.movie) {
    if (log)
      std::fprintf(log, "render: %zu frames (t = %s to %s us) in %s\n", frames.size(),
                   time_label(frames.front().time_us).c_str(),
                   time_label(frames.back().time_us).c_str(), movie_dir.c_str());
    try {
      apng->finish();
    } catch (const std::runtime_error& e) {
      throw RunError(std::string("render: ") + e.what());
    }
    if (log) std::fprintf(log, "%s\n", apng_file.c_str());
    written.push_back(apng_file);
    if (const std::string mp4 = encode_movie(movie_dir, movie_file); !mp4.empty()) {
      if (log) std::fprintf(log, "%s\n", mp4.c_str());
      written.push_back(mp4);
    } else if (log) {
      std::fprintf(log,
                   "render: ffmpeg not found on PATH (Debian package ffmpeg), so no MP4: the "
                   "animated PNG above is the movie (or, later, ffmpeg -framerate 10 -i "
                   "%s/frame_%%05d.png -pix_fmt yuv420p %s)\n",
                   movie_dir.c_str(), movie_file.c_str());
    }
  }
  return written;
}

}  // namespace ibrod::analysis
