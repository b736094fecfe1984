#pragma once
// Post-processing of a run directory (the files `ibrod run` writes): `ibrod analyze` adds the
// time-series analysis of MODEL §6 to summary.json (the rod's frames and `ibrod render`:
// analysis/frames.hpp). The numbers and the fit method are explained in docs/analysis.md.
// Missing or malformed input files throw ConfigError (exit status 2), failed writes RunError (3).
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "analysis/shapes.hpp"
#include "core/types.hpp"
#include "diagnostics/relaxation.hpp"
#include "io/csv.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::analysis {

using io::CsvTable;
using io::read_csv_table;

/// The keys of config.toml that post-processing needs (read leniently: other keys are ignored,
/// so directories written by other versions still work).
struct RunInfo {
  double diameter_A = 20.0;  ///< steric.diameter_A: the tube diameter in pictures
  int excess_link = 0;       ///< rod.excess_link
  double salt_M = 0;         ///< solvent.salt_M
  /// each rod's layout (rod::RodRange), in the state's order: the [[rods]] tables resolved on
  /// top of [rod] (config::rod_layout), else the one rod of [rod] (rod.base_pairs, rod.closed,
  /// rod.rise_A; their defaults without config.toml: layout() then fits the frames)
  std::vector<rod::RodRange> rods{{0, 600, true, 3.4}};
  /// The rods of a frame of n points: `rods`, or where they do not cover n points (no config.toml,
  /// or one of another run) one rod of all n points, of the first rod's kind and Δs.
  std::vector<rod::RodRange> layout(int n) const;
};
/// Reads DIR/config.toml; defaults (diameter 20 Å) for a missing file or key. A file that is not
/// TOML throws ConfigError.
RunInfo read_run_info(const std::filesystem::path& dir);

struct AnalyzeOptions {
  double writhe_delta = 0.01;      ///< δ of the writhe convergence time
  double circular_writhe = 0.05;   ///< a run "stays circular" while |Wr| < this throughout
  diagnostics::WindowOptions fit;  ///< final-window fits (ln E_K; tolerance in ln units)
  diagnostics::TransientOptions transients;
  double contact_distance_A = 0;  ///< d_c of contacts and plies; 0: D + 3 λ_D of config.toml
  bool every_frame = false;       ///< `--frames`: the shape of every frame of trajectory.h5md
  double tau_window_us = 1.0;     ///< width of the windows of τ(t)
};

/// The window and quality of a final-window fit (diagnostics::fit_final_linear_window).
struct FitWindow {
  double t_start_us = 0, t_end_us = 0;
  std::size_t points = 0;
  double r2 = 0;
  double max_abs_residual = 0;  ///< in ln E_K
  bool within_tolerance = false;
};

/// A transient state (diagnostics::transients) with the writhe at its E_K minimum.
struct TransientState {
  double time_us = 0, E_kinetic_kT = 0, E_total_kT = 0, writhe = 0;
  double plateau_start_us = 0, plateau_end_us = 0;
};

/// The analysis of one time series; each field is the summary.json key of the same name.
struct Analysis {
  std::size_t rows = 0;
  // did the run reach equilibrium (summary.json stop_reason == "equilibrium")? Set by
  // require_equilibrium; analyze_timeseries alone leaves `checked` false
  bool checked = false;
  bool equilibrium = false;
  std::string stop_reason;  ///< summary.json's, "" when unknown
  std::string
      not_finished_reason;  ///< why the equilibrium quantities are null ("" if they are not)
  std::vector<std::string> warnings;
  double writhe_final = 0;
  std::optional<double> writhe_convergence_time_us;  ///< null for an unfinished run
  std::optional<double> relaxation_time_us;  ///< τ of E_K ∝ exp(−2t/τ) on the final tolerance
                                             ///< window; none if E_K does not decay
  std::optional<FitWindow> relaxation_fit;
  // τ after the last contact formed (docs/analysis.md): contacts from trajectory.h5md
  std::optional<double> contacts_settled_time_us;
  std::optional<double> relaxation_time_contacts_us;
  std::optional<FitWindow> relaxation_contacts_fit;
  std::string relaxation_contacts_note;            ///< why it is null ("" when it is not)
  std::optional<double> relaxation_time_table_us;  ///< the τ the report's tables show
  std::string relaxation_time_method;  ///< which: "after_last_contact" or "final_window"
  std::vector<diagnostics::LocalRelaxation> local_relaxation;  ///< τ(t), windows in µs
  ShapeAnalysis shapes;                                        ///< filled by analyze_run
  std::vector<TransientState> transients;
  double closest_approach_A = 0;      ///< at the last row
  double closest_approach_min_A = 0;  ///< over the run
  double closest_approach_min_time_us = 0;
  std::vector<std::pair<std::string, double>> final_energies_kT;  ///< column name, last row
  bool stays_circular = false;  ///< |Wr| < AnalyzeOptions::circular_writhe throughout
  bool open_rod = false;        ///< no writhe in the time series (rod.closed = false): null for the
                                ///< ring's measures (stays_circular, shape, the power law)
  bool one_ring = true;  ///< the rods are one closed curve (rod::one_ring); else the shape classes
                         ///< (of one closed curve) are null
  std::optional<double> kinetic_power_law_exponent;  ///< only for runs that stay circular
  std::optional<FitWindow> kinetic_power_law_fit;
};

/// The rows of `table` in strictly increasing time_us: where time goes back (a run continued
/// from an earlier checkpoint appends rows it had already written), the later rows win; rows with
/// a non-finite time are dropped.
CsvTable increasing_rows(const CsvTable& table);

/// The analysis of timeseries.csv's columns (time_us, writhe, E_kinetic_kT, E_total_kT,
/// closest_approach_A are needed; ConfigError otherwise, or with fewer than 2 rows). Rows whose
/// time is not below that of every later row (a continued run that rewrote a stretch) are
/// dropped: the later rows win.
Analysis analyze_timeseries(const CsvTable& table, const AnalyzeOptions& opt = {});

/// Adds the contact-based relaxation time and τ(t) to `a` from the time series and the contact
/// history `shapes.contacts` (stored in a.shapes): τ fitted on every row from the first frame
/// after the last change of the number of contact clusters; without a history, a note and the
/// final-window τ as the table's number.
void add_contact_relaxation(Analysis& a, const CsvTable& table, ShapeAnalysis shapes,
                            const AnalyzeOptions& opt = {});

/// The honest part (issue 15 item 4): with stop_reason other than "equilibrium" every quantity
/// that presumes equilibrium (writhe convergence time, relaxation times, limiting energies) is
/// set to none, `not_finished_reason` says why and a warning is added.
void require_equilibrium(Analysis& a, const std::string& stop_reason);

/// The analysis as the JSON object of keys `ibrod analyze` adds to summary.json:
/// writhe_final, writhe_convergence_time_us, relaxation_time_us, relaxation_fit, transients,
/// closest_approach_A, closest_approach_min_A, closest_approach_min_time_us, final_energies_kT,
/// stays_circular, kinetic_power_law_exponent, kinetic_power_law_fit, and analysis (the options
/// used and the number of rows). Absent values are null.
std::string analysis_json(const Analysis& a, const AnalyzeOptions& opt = {});

/// Reads DIR/timeseries.csv and adds analysis_json's keys to DIR/summary.json (replacing earlier
/// ones, keeping every other key; created if missing), written atomically (temporary file +
/// rename). Returns the analysis.
Analysis analyze_run(const std::filesystem::path& dir, const AnalyzeOptions& opt = {});

}  // namespace ibrod::analysis
