// `ibrod analyze` and `ibrod render` on a run directory (analyze.hpp).
#include "analysis/analyze.hpp"

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/error.hpp"
#include "core/text_file.hpp"
#include "config/toml_error.hpp"
#include "io/atomic_file.hpp"
#include "io/h5md.hpp"
#include "render/image.hpp"
#include "render/render.hpp"

namespace ibrod::analysis {

using namespace ibrod::io;

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace {

FitWindow fit_window(const diag::LineFit& f, std::span<const double> t, double tolerance) {
  return {t[f.first], t[f.first + f.count - 1], f.count, f.r2, f.max_abs_residual,
          f.max_abs_residual <= tolerance};
}

json fit_json(const std::optional<FitWindow>& f) {
  if (!f) return nullptr;
  return json{{"t_start_us", f->t_start_us},
              {"t_end_us", f->t_end_us},
              {"points", f->points},
              {"r2", f->r2},
              {"max_abs_residual", f->max_abs_residual},
              {"within_tolerance", f->within_tolerance}};
}

json optional_json(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

std::string time_label(double t_us) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4f", t_us);
  return buf;
}

}  // namespace

// ---- config

RunInfo read_run_info(const fs::path& dir) {
  RunInfo info;
  const fs::path p = dir / "config.toml";
  if (!fs::exists(p)) return info;
  const toml::table tbl = config::parse_toml(read_text_file(p, "analyze"), p.string(), "analyze");
  info.diameter_A = tbl["steric"]["diameter_A"].value<double>().value_or(info.diameter_A);
  info.excess_link = tbl["rod"]["excess_link"].value<int>().value_or(info.excess_link);
  info.salt_M = tbl["solvent"]["salt_M"].value<double>().value_or(info.salt_M);
  if (!(info.diameter_A > 0))
    throw ConfigError("'" + p.string() + "': steric.diameter_A must be positive");
  return info;
}

// ---- analyze

Analysis analyze_timeseries(const CsvTable& table, const AnalyzeOptions& opt) {
  // rows in strictly increasing time: where time goes back (a run continued from an earlier
  // checkpoint appends rows it had already written), the later rows win
  const auto time = table.column("time_us");
  std::vector<std::size_t> keep;
  for (std::size_t i = table.rows(); i-- > 0;)
    if (std::isfinite(time[i]) && (keep.empty() || time[i] < time[keep.back()])) keep.push_back(i);
  std::reverse(keep.begin(), keep.end());
  CsvTable ts;
  ts.path = table.path;
  ts.names = table.names;
  for (const auto& col : table.columns) {
    ts.columns.emplace_back();
    for (std::size_t i : keep) ts.columns.back().push_back(col[i]);
  }

  const std::size_t n = ts.rows();
  if (n < 2)
    throw ConfigError("'" + ts.path.string() + "' has " + std::to_string(n) +
                      " rows in increasing time; the analysis needs at least 2");
  const auto t = ts.column("time_us");
  const auto wr = ts.column("writhe");
  const auto ek = ts.column("E_kinetic_kT");
  const auto et = ts.column("E_total_kT");
  const auto ca = ts.column("closest_approach_A");
  const std::size_t last = n - 1;
  Analysis a;
  a.rows = n;

  a.writhe_final = wr[last];
  a.writhe_convergence_time_us = diag::writhe_convergence_time(t, wr, opt.writhe_delta);

  if (const auto fit = diag::relaxation_time(t, ek, opt.fit)) {
    a.relaxation_time_us = fit->tau;
    a.relaxation_fit = fit_window(fit->line, t, opt.fit.tolerance);
  }
  for (const auto& s : diag::transients(t, ek, et, opt.transients))
    a.transients.push_back({s.time, s.kinetic, s.total, wr[s.index], s.plateau_start, s.plateau_end});

  a.closest_approach_A = ca[last];
  const auto imin = std::size_t(std::min_element(ca.begin(), ca.end()) - ca.begin());
  a.closest_approach_min_A = ca[imin];
  a.closest_approach_min_time_us = t[imin];

  for (const char* c : {"E_bend_kT", "E_twist_kT", "E_stretch_kT", "E_electro_kT", "dE_electro_kT",
                        "E_steric_kT", "E_kinetic_kT", "E_total_kT"})
    if (ts.has(c)) a.final_energies_kT.emplace_back(c, ts.column(c)[last]);

  double max_wr = 0;
  for (double w : wr) max_wr = std::max(max_wr, std::abs(w));
  a.stays_circular = max_wr < opt.circular_writhe;
  if (a.stays_circular) {
    if (const auto fit = diag::power_law_exponent(t, ek, opt.fit)) {
      a.kinetic_power_law_exponent = fit->exponent;
      a.kinetic_power_law_fit = fit_window(fit->line, t, opt.fit.tolerance);
    }
  }
  return a;
}

namespace {

json to_json(const Analysis& a, const AnalyzeOptions& opt) {
  json j;
  j["writhe_final"] = a.writhe_final;
  j["writhe_convergence_time_us"] = a.writhe_convergence_time_us;
  j["relaxation_time_us"] = optional_json(a.relaxation_time_us);
  j["relaxation_fit"] = fit_json(a.relaxation_fit);
  json tr = json::array();
  for (const auto& s : a.transients)
    tr.push_back(json{{"time_us", s.time_us},
                      {"E_kinetic_kT", s.E_kinetic_kT},
                      {"E_total_kT", s.E_total_kT},
                      {"writhe", s.writhe},
                      {"plateau_start_us", s.plateau_start_us},
                      {"plateau_end_us", s.plateau_end_us}});
  j["transients"] = tr;
  j["closest_approach_A"] = a.closest_approach_A;  // non-finite (no admissible pair): null
  j["closest_approach_min_A"] = a.closest_approach_min_A;
  j["closest_approach_min_time_us"] = a.closest_approach_min_time_us;
  json e = json::object();
  for (const auto& [name, v] : a.final_energies_kT) e[name] = v;
  j["final_energies_kT"] = e;
  j["stays_circular"] = a.stays_circular;
  j["kinetic_power_law_exponent"] = optional_json(a.kinetic_power_law_exponent);
  j["kinetic_power_law_fit"] = fit_json(a.kinetic_power_law_fit);
  j["analysis"] = json{{"source", "timeseries.csv"},
                       {"rows", a.rows},
                       {"writhe_delta", opt.writhe_delta},
                       {"circular_writhe", opt.circular_writhe},
                       {"fit_tolerance_ln", opt.fit.tolerance},
                       {"fit_min_points", opt.fit.min_points},
                       {"transient_min_rise", opt.transients.min_rise},
                       {"transient_plateau_fraction", opt.transients.plateau_fraction}};
  return j;
}

}  // namespace

std::string analysis_json(const Analysis& a, const AnalyzeOptions& opt) {
  return to_json(a, opt).dump(2);
}

Analysis analyze_run(const fs::path& dir, const AnalyzeOptions& opt) {
  if (!fs::is_directory(dir)) throw ConfigError("'" + dir.string() + "' is not a directory");
  const Analysis a = analyze_timeseries(read_csv_table(dir / "timeseries.csv"), opt);
  const fs::path sp = dir / "summary.json";
  json summary = json::object();
  if (fs::exists(sp)) {
    try {
      summary = json::parse(read_text_file(sp, "analyze"));
    } catch (const json::parse_error& e) {
      throw ConfigError("'" + sp.string() + "' is not valid JSON: " + e.what());
    }
    if (!summary.is_object()) throw ConfigError("'" + sp.string() + "' is not a JSON object");
  }
  const json added = to_json(a, opt);
  for (const auto& [k, v] : added.items()) summary[k] = v;
  write_file_atomic(sp, summary.dump(4) + "\n");
  return a;
}

// ---- frames

RodFrame read_final_state(const fs::path& dir) {
  const CsvTable s = read_csv_table(dir / "final_state.csv");
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
  const fs::path sp = dir / "summary.json";
  if (fs::exists(sp)) {
    try {
      const auto j = nlohmann::json::parse(read_text_file(sp, "analyze"));
      if (j.contains("time_us") && j["time_us"].is_number()) f.time_us = j["time_us"].get<double>();
      if (j.contains("steps") && j["steps"].is_number_integer()) f.step = j["steps"].get<std::int64_t>();
    } catch (const nlohmann::json::exception&) {
      // fall through to the time series
    }
  }
  if (!std::isfinite(f.time_us) && fs::exists(dir / "timeseries.csv")) {
    const CsvTable ts = read_csv_table(dir / "timeseries.csv");
    if (ts.rows() > 0) {
      f.time_us = ts.column("time_us").back();
      if (ts.has("step")) f.step = std::int64_t(ts.column("step").back());
    }
  }
  if (!std::isfinite(f.time_us)) f.time_us = 0;
  return f;
}

std::vector<RodFrame> read_trajectory_frames(const fs::path& dir, std::span<const double> times_us) {
  const fs::path p = dir / "trajectory.h5";
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
    if (fs::exists(dir / "trajectory.h5")) {
      frames = read_trajectory_frames(dir, times);
      if (log)
        for (const auto& f : frames)
          std::fprintf(log, "render: frame at t = %s us (step %lld)\n", time_label(f.time_us).c_str(),
                       static_cast<long long>(f.step));
    } else {
      if (log)
        std::fprintf(log, "render: no trajectory.h5 in %s: drawing the final state instead of "
                     "--time\n", dir.c_str());
      want_final = true;
    }
  }
  if (want_final) frames.push_back(read_final_state(dir));

  const RunInfo info = read_run_info(dir);
  const fs::path out = dir / "render";
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw RunError("render: cannot create '" + out.string() + "': " + ec.message());
  std::vector<fs::path> written;
  for (const auto& f : frames) {
    for (const auto& v : views) {
      const render::Image img = render::render_rod(f.X, f.d1, info.diameter_A, v, opt.width, opt.height);
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
