// `ibrod compare`: two runs side by side at their common times (compare.hpp).
#include "analysis/compare.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "analysis/analyze.hpp"
#include "core/error.hpp"
#include "io/run_dir.hpp"

namespace ibrod::analysis {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;  // keys in the order written

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// "%.6g", or "nan" when not defined.
std::string num(double v) { return std::isfinite(v) ? fmt("%.6g", v) : std::string("nan"); }

json json_num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

/// The largest |b_j − a_i| over the pairs, and the time of its first occurrence: (NaN, NaN) when
/// no pair has a finite difference.
std::pair<double, double> max_abs_difference(
    const std::vector<std::pair<std::size_t, std::size_t>>& pairs, const std::vector<double>& t,
    const std::vector<double>& a, const std::vector<double>& b) {
  double best = kNaN, at = kNaN;
  for (const auto& [i, j] : pairs) {
    const double d = std::abs(b[j] - a[i]);
    if (std::isfinite(d) && !(d <= best)) {  // !(d <= NaN) takes the first finite one
      best = d;
      at = t[i];
    }
  }
  return {best, at};
}

/// The row of `s` at time t (|time − t| ≤ tol), or none.
std::optional<std::size_t> row_at(const RunSeries& s, double t, double tol) {
  const auto it = std::lower_bound(s.time_us.begin(), s.time_us.end(), t - tol);
  if (it == s.time_us.end() || *it > t + tol) return std::nullopt;
  return std::size_t(it - s.time_us.begin());
}

std::string span_text(const RunSeries& s) {
  if (s.time_us.empty()) return "no rows";
  return std::to_string(s.time_us.size()) + " rows, t = " + num(s.time_us.front()) + " to " +
         num(s.time_us.back()) + " us";
}

std::string shape_text(diagnostics::ShapeClass c, int loops) {
  return std::string(diagnostics::shape_class_name(c)) + "/" + std::to_string(loops);
}

}  // namespace

// ---- the comparison (pure)

RunSeries run_series(const io::CsvTable& table) {
  const io::CsvTable ts = increasing_rows(table);
  RunSeries s;
  const auto copy = [&](const char* name) {
    const auto c = ts.column(name);
    return std::vector<double>(c.begin(), c.end());
  };
  s.time_us = copy("time_us");
  s.writhe = copy("writhe");
  s.E_total_kT = copy("E_total_kT");
  s.closest_approach_A = copy("closest_approach_A");
  return s;
}

std::vector<std::pair<std::size_t, std::size_t>> common_times(std::span<const double> a,
                                                              std::span<const double> b,
                                                              double tolerance_us) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::abs(a[i] - b[j]) <= tolerance_us)
      pairs.emplace_back(i++, j++);
    else if (a[i] < b[j])
      ++i;
    else
      ++j;
  }
  return pairs;
}

std::vector<double> shape_changes(std::span<const ShapeRecord> frames) {
  std::vector<double> t;
  for (std::size_t k = 1; k < frames.size(); ++k)
    if (frames[k].shape.cls != frames[k - 1].shape.cls ||
        frames[k].shape.loops != frames[k - 1].shape.loops)
      t.push_back(frames[k].time_us);
  return t;
}

const char* frame_flag_name(FrameFlag f) {
  switch (f) {
    case FrameFlag::same:
      return "";
    case FrameFlag::guarded:
      return "guard";
    case FrameFlag::mismatch:
      return "MISMATCH";
  }
  return "?";
}

Comparison compare_runs(const RunSeries& a, const RunSeries& b,
                        std::span<const ShapeRecord> frames_a,
                        std::span<const ShapeRecord> frames_b, const CompareOptions& opt) {
  const double tol = opt.time_tolerance_us;
  Comparison c;
  c.rows_a = a.time_us.size();
  c.rows_b = b.time_us.size();
  // ---- the time series at the common rows
  const auto rows = common_times(a.time_us, b.time_us, tol);
  if (rows.empty())
    throw ConfigError("the two runs have no common time (rows whose time_us agree to within " +
                      num(tol) + " us): A has " + span_text(a) + ", B has " + span_text(b));
  c.common_rows = rows.size();
  std::tie(c.max_abs_dwr, c.max_abs_dwr_time_us) =
      max_abs_difference(rows, a.time_us, a.writhe, b.writhe);
  std::tie(c.max_abs_de_kT, c.max_abs_de_time_us) =
      max_abs_difference(rows, a.time_us, a.E_total_kT, b.E_total_kT);
  std::tie(c.max_abs_dclosest_A, c.max_abs_dclosest_time_us) =
      max_abs_difference(rows, a.time_us, a.closest_approach_A, b.closest_approach_A);
  const auto [ia, ib] = rows.back();
  c.final_time_us = a.time_us[ia];
  c.final_dwr = b.writhe[ib] - a.writhe[ia];
  c.final_de_kT = b.E_total_kT[ib] - a.E_total_kT[ia];

  // ---- the shapes at the common frames; a difference within guard_us of a change is allowed
  c.frames_a = frames_a.size();
  c.frames_b = frames_b.size();
  if (frames_a.empty() || frames_b.empty()) {
    c.shapes_note = "a run has no frames";
    return c;
  }
  c.changes_a = shape_changes(frames_a);
  c.changes_b = shape_changes(frames_b);
  const auto near_change = [&](double t) {
    for (const auto* ch : {&c.changes_a, &c.changes_b})
      for (double tc : *ch)
        if (std::abs(t - tc) <= opt.guard_us + tol) return true;
    return false;
  };
  std::vector<double> ta, tb;
  for (const auto& f : frames_a) ta.push_back(f.time_us);
  for (const auto& f : frames_b) tb.push_back(f.time_us);
  for (const auto& [i, j] : common_times(ta, tb, tol)) {
    FrameComparison f;
    f.time_us = ta[i];
    const auto ra = row_at(a, ta[i], tol), rb = row_at(b, tb[j], tol);
    f.writhe_a = ra ? a.writhe[*ra] : kNaN;
    f.E_total_a_kT = ra ? a.E_total_kT[*ra] : kNaN;
    f.writhe_b = rb ? b.writhe[*rb] : kNaN;
    f.E_total_b_kT = rb ? b.E_total_kT[*rb] : kNaN;
    f.class_a = frames_a[i].shape.cls;
    f.loops_a = frames_a[i].shape.loops;
    f.class_b = frames_b[j].shape.cls;
    f.loops_b = frames_b[j].shape.loops;
    if (f.class_a != f.class_b || f.loops_a != f.loops_b) {
      f.flag = near_change(f.time_us) ? FrameFlag::guarded : FrameFlag::mismatch;
      ++(f.flag == FrameFlag::guarded ? c.shape_guarded : c.shape_mismatches);
    }
    c.frames.push_back(f);
  }
  c.shapes_compared = !c.frames.empty();
  if (!c.shapes_compared) c.shapes_note = "no frame at a common time";
  return c;
}

std::vector<std::string> compare_failures(const Comparison& c, const CompareLimits& limits) {
  std::vector<std::string> out;
  if (!limits.any()) return out;
  const auto check = [&](const std::optional<double>& limit, double value, double t,
                         const std::string& what, const char* unit, const char* option) {
    if (!limit) return;
    if (!std::isfinite(value))
      out.push_back(what + " is not defined (" + option + " " + num(*limit) + ")");
    else if (value > *limit)
      out.push_back(what + " = " + num(value) + unit +
                    (std::isfinite(t) ? " at t = " + num(t) + " us" : "") + " > " + option + " " +
                    num(*limit));
  };
  check(limits.max_dwr, c.max_abs_dwr, c.max_abs_dwr_time_us, "max |dWr|", "", "--max-dwr");
  check(limits.max_de_kT, c.max_abs_de_kT, c.max_abs_de_time_us, "max |dE_total|", " kT",
        "--max-de");
  check(limits.max_final_de_kT, std::abs(c.final_de_kT), c.final_time_us,
        "|dE_total| at the last common time", " kT", "--max-final-de");
  if (c.shape_mismatches > 0) {
    std::string s = std::to_string(c.shape_mismatches) +
                    " frame(s) with another shape class or loop count outside the guard: t =";
    for (const auto& f : c.frames)
      if (f.flag == FrameFlag::mismatch) s += " " + num(f.time_us);
    out.push_back(s + " us");
  }
  // both runs have frames, yet none at a common time: the shapes were not checked
  if (!c.shapes_compared && c.frames_a > 0 && c.frames_b > 0)
    out.push_back(
        "no frame of the two runs is at a common time: the shapes were not compared (write the "
        "frames at common times, e.g. output.frame_every_us)");
  return out;
}

// ---- text and JSON

std::string compare_table(const Comparison& c) {
  std::string s;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%10s %9s %9s %11s %11s %11s %11s  %-15s %-15s %s\n", "t_us",
                "Wr_A", "Wr_B", "dWr", "E_A_kT", "E_B_kT", "dE_kT", "class/loops_A",
                "class/loops_B", "flag");
  s += buf;
  const auto col = [](const char* f, double v) { return std::isfinite(v) ? fmt(f, v) : "-"; };
  for (const auto& f : c.frames) {
    std::snprintf(buf, sizeof buf, "%10.6g %9s %9s %11s %11s %11s %11s  %-15s %-15s %s\n",
                  f.time_us, col("%.4f", f.writhe_a).c_str(), col("%.4f", f.writhe_b).c_str(),
                  col("%+.3e", f.writhe_b - f.writhe_a).c_str(),
                  col("%.4f", f.E_total_a_kT).c_str(), col("%.4f", f.E_total_b_kT).c_str(),
                  col("%+.3e", f.E_total_b_kT - f.E_total_a_kT).c_str(),
                  shape_text(f.class_a, f.loops_a).c_str(),
                  shape_text(f.class_b, f.loops_b).c_str(), frame_flag_name(f.flag));
    std::string line = buf;  // no trailing blanks where the flag is empty
    line.erase(line.find_last_not_of(" \n") + 1);
    s += line + "\n";
  }
  return s;
}

std::string compare_summary(const Comparison& c) {
  std::string s =
      "compare: common_rows=" + std::to_string(c.common_rows) +
      " common_frames=" + std::to_string(c.frames.size()) + " max_dWr=" + num(c.max_abs_dwr) +
      " at t=" + num(c.max_abs_dwr_time_us) + " max_dE_kT=" + num(c.max_abs_de_kT) +
      " at t=" + num(c.max_abs_de_time_us) + " final_t=" + num(c.final_time_us) +
      " final_dWr=" + num(c.final_dwr) + " final_dE_kT=" + num(c.final_de_kT) +
      " max_dclosest_A=" + num(c.max_abs_dclosest_A) + " at t=" + num(c.max_abs_dclosest_time_us);
  if (c.shapes_compared)
    s += " shape_mismatches=" + std::to_string(c.shape_mismatches) +
         " guarded=" + std::to_string(c.shape_guarded);
  else
    s += " shape_mismatches=n/a";
  return s;
}

std::string compare_json(const Comparison& c, const CompareLimits& limits,
                         const std::vector<std::string>& failures) {
  const auto opt_json = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  json frames = json::array();
  for (const auto& f : c.frames)
    frames.push_back({{"time_us", f.time_us},
                      {"writhe_a", json_num(f.writhe_a)},
                      {"writhe_b", json_num(f.writhe_b)},
                      {"dWr", json_num(f.writhe_b - f.writhe_a)},
                      {"E_total_a_kT", json_num(f.E_total_a_kT)},
                      {"E_total_b_kT", json_num(f.E_total_b_kT)},
                      {"dE_total_kT", json_num(f.E_total_b_kT - f.E_total_a_kT)},
                      {"class_a", diagnostics::shape_class_name(f.class_a)},
                      {"loops_a", f.loops_a},
                      {"class_b", diagnostics::shape_class_name(f.class_b)},
                      {"loops_b", f.loops_b},
                      {"flag", f.flag == FrameFlag::same      ? "same"
                               : f.flag == FrameFlag::guarded ? "guarded"
                                                              : "mismatch"}});
  json j = {{"run_a", c.run_a},
            {"run_b", c.run_b},
            {"difference", "B - A"},
            {"rows_a", c.rows_a},
            {"rows_b", c.rows_b},
            {"common_rows", c.common_rows},
            {"max_abs_dWr", json_num(c.max_abs_dwr)},
            {"max_abs_dWr_time_us", json_num(c.max_abs_dwr_time_us)},
            {"max_abs_dE_total_kT", json_num(c.max_abs_de_kT)},
            {"max_abs_dE_total_time_us", json_num(c.max_abs_de_time_us)},
            {"max_abs_dclosest_approach_A", json_num(c.max_abs_dclosest_A)},
            {"max_abs_dclosest_approach_time_us", json_num(c.max_abs_dclosest_time_us)},
            {"final_time_us", json_num(c.final_time_us)},
            {"final_dWr", json_num(c.final_dwr)},
            {"final_dE_total_kT", json_num(c.final_de_kT)},
            {"shapes_compared", c.shapes_compared},
            {"shapes_note", c.shapes_note.empty() ? json(nullptr) : json(c.shapes_note)},
            {"contact_distance_a_A", c.contact_distance_a_A},
            {"contact_distance_b_A", c.contact_distance_b_A},
            {"frames_a", c.frames_a},
            {"frames_b", c.frames_b},
            {"shape_changes_a_us", c.changes_a},
            {"shape_changes_b_us", c.changes_b},
            {"common_frames", c.frames.size()},
            {"shape_mismatches", c.shape_mismatches},
            {"shape_guarded", c.shape_guarded},
            {"limits",
             {{"max_dwr", opt_json(limits.max_dwr)},
              {"max_de_kT", opt_json(limits.max_de_kT)},
              {"max_final_de_kT", opt_json(limits.max_final_de_kT)}}},
            {"passed", limits.any() ? json(failures.empty()) : json(nullptr)},
            {"failures", failures},
            {"frames", frames}};
  return j.dump(2) + "\n";
}

// ---- run directories

ComparedRun read_compared_run(const fs::path& dir, double contact_distance_A) {
  if (!fs::is_directory(dir))
    throw ConfigError("compare: '" + dir.string() +
                      "' is not a directory (a run directory of "
                      "`ibrod run` is needed)");
  const io::RunDir rd(dir);
  ComparedRun r;
  r.dir = dir;
  r.series = run_series(read_csv_table(rd.timeseries()));
  if (!fs::exists(rd.config()))
    throw ConfigError("compare: '" + rd.config().string() +
                      "' does not exist (needed for the contact distance of the shapes)");
  const RunInfo info = read_run_info(dir);
  r.contact_distance_A = contact_distance_A > 0
                             ? contact_distance_A
                             : default_contact_distance(info.diameter_A, info.salt_M);
  if (!rod::one_ring(info.rods)) {
    r.shapes_note = rod::names_rods(info.rods)
                        ? "several rods: the shape classes are of one closed rod"
                        : "an open rod: the shape classes are of closed rods";
    return r;
  }
  if (!fs::exists(rd.trajectory()))
    throw ConfigError("compare: '" + rd.trajectory().string() +
                      "' does not exist (the run wrote no frames: output.frame_every_steps = 0?); "
                      "compare needs the frames for the shapes");
  ShapeAnalysis shapes = analyze_shapes(dir, r.contact_distance_A, /*every_frame=*/true);
  r.frames = std::move(shapes.frames);
  if (r.frames.empty())
    r.shapes_note = shapes.contacts.note.empty() ? "no frames" : shapes.contacts.note;
  return r;
}

Comparison compare_run_dirs(const fs::path& a, const fs::path& b, const CompareOptions& opt,
                            double contact_distance_A) {
  const ComparedRun ra = read_compared_run(a, contact_distance_A);
  const ComparedRun rb = read_compared_run(b, contact_distance_A);
  Comparison c;
  try {
    c = compare_runs(ra.series, rb.series, ra.frames, rb.frames, opt);
  } catch (const ConfigError& e) {
    throw ConfigError("compare: '" + io::RunDir(a).timeseries().string() + "' and '" +
                      io::RunDir(b).timeseries().string() + "': " + e.what());
  }
  c.run_a = a.string();
  c.run_b = b.string();
  c.contact_distance_a_A = ra.contact_distance_A;
  c.contact_distance_b_A = rb.contact_distance_A;
  if (!ra.shapes_note.empty() || !rb.shapes_note.empty()) {
    c.shapes_note.clear();
    for (const auto* r : {&ra, &rb})
      if (!r->shapes_note.empty())
        c.shapes_note +=
            (c.shapes_note.empty() ? "" : "; ") + r->dir.string() + ": " + r->shapes_note;
  }
  return c;
}

}  // namespace ibrod::analysis
