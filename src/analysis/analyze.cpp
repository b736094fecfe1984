// `ibrod analyze` on a run directory (analyze.hpp).
#include "analysis/analyze.hpp"

#include <toml++/toml.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

#include "config/config.hpp"
#include "config/toml_error.hpp"
#include "core/error.hpp"
#include "core/text_file.hpp"
#include "io/atomic_file.hpp"
#include "io/h5md.hpp"
#include "io/run_dir.hpp"

namespace ibrod::analysis {

using namespace ibrod::io;

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace {

FitWindow fit_window(const diagnostics::LineFit& f, std::span<const double> t, double tolerance) {
  return {t[f.first], t[f.first + f.count - 1], f.count,
          f.r2,       f.max_abs_residual,       f.max_abs_residual <= tolerance};
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

}  // namespace

// ---- config

RunInfo read_run_info(const fs::path& dir) {
  RunInfo info;
  const fs::path p = RunDir(dir).config();
  if (!fs::exists(p)) return info;
  const toml::table tbl = config::parse_toml(read_text_file(p, "analyze"), p.string(), "analyze");
  info.diameter_A = tbl["steric"]["diameter_A"].value<double>().value_or(info.diameter_A);
  info.excess_link = tbl["rod"]["excess_link"].value<int>().value_or(info.excess_link);
  info.salt_M = tbl["solvent"]["salt_M"].value<double>().value_or(info.salt_M);
  const bool closed = tbl["rod"]["closed"].value<bool>().value_or(config::Config().rod_closed);
  const int n = tbl["rod"]["base_pairs"].value<int>().value_or(config::Config().rod_base_pairs);
  const double ds = tbl["rod"]["rise_A"].value<double>().value_or(config::Config().rod_rise_A);
  info.rods = {{0, n, closed, ds}};
  if (tbl.contains("rods")) {
    // [[rods]]: each table resolved on top of [rod], as the run did
    config::Config c;
    config::apply_toml(c, read_text_file(p, "analyze"), p.string());
    info.rods = config::rod_layout(c);
  }
  if (!(info.diameter_A > 0))
    throw ConfigError("'" + p.string() + "': steric.diameter_A must be positive");
  return info;
}

std::vector<rod::RodRange> RunInfo::layout(int n) const {
  if (rod::total_points(rods) == n) return rods;
  rod::RodRange one = rods.front();
  one.offset = 0;
  one.n = n;
  return {one};
}

// ---- analyze

CsvTable increasing_rows(const CsvTable& table) {
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
  return ts;
}

Analysis analyze_timeseries(const CsvTable& table, const AnalyzeOptions& opt) {
  const CsvTable ts = increasing_rows(table);
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
  a.writhe_convergence_time_us = diagnostics::writhe_convergence_time(t, wr, opt.writhe_delta);

  if (const auto fit = diagnostics::relaxation_time(t, ek, opt.fit)) {
    a.relaxation_time_us = fit->tau;
    a.relaxation_fit = fit_window(fit->line, t, opt.fit.tolerance);
  }
  a.local_relaxation = diagnostics::local_relaxation_times(t, ek, opt.tau_window_us);
  a.relaxation_time_table_us = a.relaxation_time_us;
  a.relaxation_time_method = "final_window";
  for (const auto& s : diagnostics::transients(t, ek, et, opt.transients))
    a.transients.push_back(
        {s.time, s.kinetic, s.total, wr[s.index], s.plateau_start, s.plateau_end});

  a.closest_approach_A = ca[last];
  const auto imin = std::size_t(std::min_element(ca.begin(), ca.end()) - ca.begin());
  a.closest_approach_min_A = ca[imin];
  a.closest_approach_min_time_us = t[imin];

  for (const char* c : {"E_bend_kT", "E_twist_kT", "E_stretch_kT", "E_electro_kT", "dE_electro_kT",
                        "E_steric_kT", "E_kinetic_kT", "E_total_kT"})
    if (ts.has(c)) a.final_energies_kT.emplace_back(c, ts.column(c)[last]);

  double max_wr = 0;
  for (double w : wr) max_wr = std::max(max_wr, std::abs(w));
  // an open rod's writhe is not defined (empty fields, NaN): no ring to stay circular
  a.open_rod = std::all_of(wr.begin(), wr.end(), [](double w) { return std::isnan(w); });
  a.stays_circular = !a.open_rod && max_wr < opt.circular_writhe;
  if (a.stays_circular) {
    if (const auto fit = diagnostics::power_law_exponent(t, ek, opt.fit)) {
      a.kinetic_power_law_exponent = fit->exponent;
      a.kinetic_power_law_fit = fit_window(fit->line, t, opt.fit.tolerance);
    }
  }
  return a;
}

void add_contact_relaxation(Analysis& a, const CsvTable& table, ShapeAnalysis shapes,
                            const AnalyzeOptions& opt) {
  const CsvTable ts = increasing_rows(table);
  const auto t = ts.column("time_us");
  const auto ek = ts.column("E_kinetic_kT");
  const ContactHistory& c = shapes.contacts;
  if (c.time_us.empty()) {
    a.relaxation_contacts_note =
        "contacts unknown: " + c.note + "; the tables show the final-window τ (relaxation_time_us)";
  } else {
    const double settled = diagnostics::settled_time(c.time_us, c.clusters);
    a.contacts_settled_time_us = settled;
    if (const auto fit = diagnostics::relaxation_time_from(t, ek, settled, opt.fit.min_points)) {
      a.relaxation_time_contacts_us = fit->tau;
      FitWindow w;
      w.t_start_us = t[fit->line.first];
      w.t_end_us = t.back();
      w.points = fit->line.count;
      w.r2 = fit->line.r2;
      w.max_abs_residual = fit->line.max_abs_residual;
      w.within_tolerance = fit->line.max_abs_residual <= opt.fit.tolerance;
      a.relaxation_contacts_fit = w;
      a.relaxation_time_table_us = fit->tau;
      a.relaxation_time_method = "after_last_contact";
    } else {
      a.relaxation_contacts_note = "E_K does not decay (or fewer than " +
                                   std::to_string(opt.fit.min_points) +
                                   " rows) after the contacts settled";
      a.relaxation_time_table_us.reset();
      a.relaxation_time_method = "after_last_contact";
    }
  }
  a.shapes = std::move(shapes);
}

void require_equilibrium(Analysis& a, const std::string& stop_reason) {
  a.checked = true;
  a.stop_reason = stop_reason;
  a.equilibrium = stop_reason == "equilibrium";
  if (a.equilibrium) return;
  a.not_finished_reason =
      (stop_reason.empty() ? std::string("summary.json has no stop_reason")
                           : "the run stopped by '" + stop_reason + "'") +
      ", not at equilibrium (E_K < time.stop_kinetic_kT): the writhe convergence time, relaxation "
      "times and limiting energies presume one";
  a.writhe_convergence_time_us.reset();
  a.relaxation_time_us.reset();
  a.relaxation_fit.reset();
  a.relaxation_time_contacts_us.reset();
  a.relaxation_contacts_fit.reset();
  a.relaxation_time_table_us.reset();
  a.warnings.push_back("not finished: " + a.not_finished_reason + "; they are null");
}

namespace {

json shape_json(const diagnostics::Shape& s, double time_us) {
  return json{{"time_us", time_us},
              {"class", diagnostics::shape_class_name(s.cls)},
              {"crossings", s.crossings},
              {"crossings_direction", {s.direction.x(), s.direction.y(), s.direction.z()}},
              {"crossings_mode", s.crossings_mode},
              {"lobes", s.lobes},
              {"loops", s.loops},
              {"interwound_length_A", s.interwound_length_A},
              {"interwound_runs", s.interwound_runs},
              {"contact_clusters", s.contact_clusters}};
}

json to_json(const Analysis& a, const AnalyzeOptions& opt) {
  json j;
  j["writhe_final"] = a.writhe_final;
  const json reason = a.not_finished_reason.empty() ? json(nullptr) : json(a.not_finished_reason);
  j["equilibrium_reached"] = a.checked ? json(a.equilibrium) : json(nullptr);
  j["not_finished_reason"] = reason;
  j["writhe_convergence_time_us"] = optional_json(a.writhe_convergence_time_us);
  j["relaxation_time_us"] = optional_json(a.relaxation_time_us);
  j["relaxation_fit"] = fit_json(a.relaxation_fit);
  j["contacts_settled_time_us"] = optional_json(a.contacts_settled_time_us);
  j["relaxation_time_contacts_us"] = optional_json(a.relaxation_time_contacts_us);
  j["relaxation_contacts_fit"] = fit_json(a.relaxation_contacts_fit);
  j["relaxation_contacts_note"] =
      a.relaxation_contacts_note.empty() ? json(nullptr) : json(a.relaxation_contacts_note);
  j["relaxation_time_table_us"] = optional_json(a.relaxation_time_table_us);
  j["relaxation_time_method"] = a.relaxation_time_method;
  json local = json::array();
  for (const auto& w : a.local_relaxation)
    local.push_back(json{
        {"t_start_us", w.t_start}, {"t_end_us", w.t_end}, {"tau_us", w.tau}, {"points", w.points}});
  j["relaxation_time_local_us"] = local;
  j["relaxation_time_local_window_us"] = opt.tau_window_us;
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
  j["limiting_energies_kT"] = a.equilibrium ? e : json(nullptr);
  const ShapeAnalysis& sh = a.shapes;
  // the shape classes are of closed curves (docs/analysis.md): null for an open rod
  j["shape"] = sh.final_shape && !a.open_rod && a.one_ring
                   ? shape_json(sh.final_shape->shape, sh.final_shape->time_us)
                   : json(nullptr);
  // null without --frames, so that an earlier analysis's frames do not outlive a new one
  json fr = opt.every_frame ? json::array() : json(nullptr);
  if (!a.open_rod && a.one_ring)
    for (const auto& f : sh.frames) fr.push_back(shape_json(f.shape, f.time_us));
  j["shape_frames"] = fr;
  json contacts{{"distance_A", sh.contact_distance_A}};
  if (sh.contacts.time_us.empty()) {
    contacts["source"] = nullptr;
    contacts["note"] = sh.contacts.note;
  } else {
    contacts["source"] = sh.contacts.source;
    contacts["frames"] = sh.contacts.time_us.size();
    json changes = json::array();
    for (std::size_t i = 1; i < sh.contacts.time_us.size(); ++i)
      if (sh.contacts.clusters[i] != sh.contacts.clusters[i - 1])
        changes.push_back(
            json{{"time_us", sh.contacts.time_us[i]}, {"clusters", sh.contacts.clusters[i]}});
    contacts["initial_clusters"] = sh.contacts.clusters.front();
    contacts["changes"] = changes;
  }
  j["contacts"] = contacts;
  j["stays_circular"] = a.open_rod ? json(nullptr) : json(a.stays_circular);
  j["kinetic_power_law_exponent"] = optional_json(a.kinetic_power_law_exponent);
  j["kinetic_power_law_fit"] = fit_json(a.kinetic_power_law_fit);
  j["analysis"] = json{{"source", "timeseries.csv"},
                       {"rows", a.rows},
                       {"writhe_delta", opt.writhe_delta},
                       {"circular_writhe", opt.circular_writhe},
                       {"fit_tolerance_ln", opt.fit.tolerance},
                       {"fit_min_points", opt.fit.min_points},
                       {"transient_min_rise", opt.transients.min_rise},
                       {"transient_plateau_fraction", opt.transients.plateau_fraction},
                       {"contact_distance_A", a.shapes.contact_distance_A},
                       {"every_frame", opt.every_frame}};
  return j;
}

}  // namespace

std::string analysis_json(const Analysis& a, const AnalyzeOptions& opt) {
  return to_json(a, opt).dump(2);
}

Analysis analyze_run(const fs::path& dir, const AnalyzeOptions& opt) {
  if (!fs::is_directory(dir)) throw ConfigError("'" + dir.string() + "' is not a directory");
  const CsvTable table = read_csv_table(RunDir(dir).timeseries());
  Analysis a = analyze_timeseries(table, opt);
  const RunInfo info = read_run_info(dir);
  a.one_ring = rod::one_ring(info.rods);
  const double dc = opt.contact_distance_A > 0
                        ? opt.contact_distance_A
                        : default_contact_distance(info.diameter_A, info.salt_M);
  add_contact_relaxation(a, table, analyze_shapes(dir, dc, opt.every_frame), opt);
  const fs::path sp = RunDir(dir).summary();
  json summary = json::object();
  if (fs::exists(sp)) {
    try {
      summary = json::parse(read_text_file(sp, "analyze"));
    } catch (const json::parse_error& e) {
      throw ConfigError("'" + sp.string() + "' is not valid JSON: " + e.what());
    }
    if (!summary.is_object()) throw ConfigError("'" + sp.string() + "' is not a JSON object");
  }
  std::string stop_reason;
  if (summary.contains("stop_reason") && summary["stop_reason"].is_string())
    stop_reason = summary["stop_reason"].get<std::string>();
  require_equilibrium(a, stop_reason);
  const json added = to_json(a, opt);
  for (const auto& [k, v] : added.items()) summary[k] = v;
  write_file_atomic(sp, summary.dump(4) + "\n");
  return a;
}

// ---- frames

}  // namespace ibrod::analysis
