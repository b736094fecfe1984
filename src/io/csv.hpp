#pragma once
// The run directory's CSV files: one reader (CsvTable: timeseries.csv, final_state.csv) and the
// writers of final_state.csv and of a time series cut back to a checkpoint's step.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "rod/rod.hpp"
#include "rod/rod_set.hpp"
#include "sim/simulation.hpp"

namespace ibrod::io {

/// A CSV file with a header row and numeric fields, by column.
struct CsvTable {
  std::filesystem::path path;
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  ///< [names.size()][rows]

  std::size_t rows() const { return columns.empty() ? 0 : columns.front().size(); }
  bool has(const std::string& name) const;
  /// The column called `name`; ConfigError naming the file if there is none.
  std::span<const double> column(const std::string& name) const;
};

/// Reads a CSV file of numbers with a header row (timeseries.csv, final_state.csv). A final line
/// cut short (a run killed while writing it) is dropped; any other malformed line throws
/// ConfigError naming the file and line.
CsvTable read_csv_table(const std::filesystem::path& path);

/// A whole field as a number (surrounding blanks and a trailing '\r' allowed): false if it is
/// empty or not entirely a number.
bool parse_double(const std::string& s, double& v);

/// final_state.csv: the header x_A,y_A,z_A,d1x,d1y,d1z,d2x,d2y,d2z,d3x,d3y,d3z and one row per
/// rod point (positions and triad columns D¹, D², D³ to 17 significant digits: read back, the
/// numbers are the state's bit for bit; rod.initial_shape starts a run from them).
std::string final_state_csv(const rod::RodState& s);
/// The same for several rods (rod::RodRange, in order): a first column `rod` (0, 1, …) before
/// the others. One range: exactly final_state_csv(s).
std::string final_state_csv(const rod::RodState& s, const std::vector<rod::RodRange>& ranges);

/// A per-rod column of rods.csv: its name and its value in a time-series row (NaN where the row
/// has none).
struct RodColumn {
  std::string name;
  std::function<double(const sim::Observables&)> value;
};
/// The per-rod columns of rods.csv, after step,time_us: writhe_r, twist_r, link_r for each rod r
/// (an open rod's writhe and link NaN), then link_a_b, the linking number of each pair a < b of
/// closed rods. The one list rods.csv and the Python module's run columns take.
std::vector<RodColumn> rod_columns(std::span<const rod::RodRange> rods);

/// rods.csv of a run whose rods rod::names_rods (docs/outputs.md): step,time_us, then the names
/// of rod_columns(rods).
std::string rods_header(std::span<const rod::RodRange> rods);
/// One row of rods.csv from a time-series row (Observables::rods), no newline.
std::string rods_row(const sim::Observables& o);

/// timeseries.csv cut back to the rows with step <= last_step, in increasing step order, after
/// `header` (an incomplete last line — a run killed while writing it — and any row out of order
/// are dropped). Throws RunError if `text`'s header is not `header`.
std::string timeseries_up_to(const std::string& text, const std::string& header,
                             std::int64_t last_step, const std::string& source);

}  // namespace ibrod::io
