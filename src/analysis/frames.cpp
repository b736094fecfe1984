// The rod's frames of a run directory (final_state.csv, trajectory.h5) and `ibrod render`.
#include "analysis/frames.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/error.hpp"
#include "core/text_file.hpp"
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

std::vector<RodFrame> read_trajectory_frames(const fs::path& dir,
                                             std::span<const double> times_us) {
  const fs::path p = RunDir(dir).trajectory();
  if (!fs::exists(p)) throw ConfigError("'" + p.string() + "' does not exist");
  H5mdSeries pos, d1;
  try {
    pos = read_h5md_series(p, "position");
    d1 = read_h5md_series(p, "d1");
  } catch (const RunError& e) {
    throw ConfigError(std::string("cannot read the trajectory: ") + e.what());
  }
  const std::size_t T = pos.time_us.size();
  if (T == 0 || pos.n < 2 || d1.time_us.size() != T || d1.n != pos.n)
    throw ConfigError("'" + p.string() + "' has no frames (or position and d1 disagree)");
  std::vector<std::size_t> picks;
  for (double want : times_us) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < T; ++i)
      if (std::abs(pos.time_us[i] - want) < std::abs(pos.time_us[best] - want)) best = i;
    picks.push_back(best);
  }
  std::sort(picks.begin(), picks.end());
  picks.erase(std::unique(picks.begin(), picks.end()), picks.end());
  std::vector<RodFrame> frames;
  const std::size_t n = std::size_t(pos.n);
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
  if (!times.empty()) {
    if (fs::exists(RunDir(dir).trajectory())) {
      frames = read_trajectory_frames(dir, times);
      if (log)
        for (const auto& f : frames)
          std::fprintf(log, "render: frame at t = %s us (step %lld)\n",
                       time_label(f.time_us).c_str(), static_cast<long long>(f.step));
    } else {
      if (log)
        std::fprintf(log,
                     "render: no trajectory.h5 in %s: drawing the final state instead of "
                     "--time\n",
                     dir.c_str());
      want_final = true;
    }
  }
  if (want_final) frames.push_back(read_final_state(dir));

  const RunInfo info = read_run_info(dir);
  const fs::path out = RunDir(dir).render_dir();
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw RunError("render: cannot create '" + out.string() + "': " + ec.message());
  std::vector<fs::path> written;
  for (const auto& f : frames) {
    for (const auto& v : views) {
      const render::Image img =
          render::render_rod(f.X, f.d1, info.diameter_A, v, opt.width, opt.height);
      const fs::path file = out / ("rod_" + v.name + "_t" + time_label(f.time_us) + ".png");
      try {
        render::write_png(file.string(), img);
      } catch (const std::runtime_error& e) {
        throw RunError(std::string("render: ") + e.what());
      }
      if (log) std::fprintf(log, "%s\n", file.c_str());
      written.push_back(file);
    }
  }
  return written;
}

}  // namespace ibrod::analysis
