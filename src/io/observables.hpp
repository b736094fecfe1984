#pragma once
// The time-series columns (sim::Observables) as one table, so that timeseries.csv, the H5MD
// /observables groups, summary.json and checkpoints name and order them the same way.
#include <string>
#include <vector>

#include "sim/simulation.hpp"

namespace ibrod::io {

/// One time-series column other than step and time_us.
struct ObservableField {
  const char* name;  ///< column name with its unit (E_bend_kT, closest_approach_A, …)
  double sim::Observables::*member;
  int csv_digits;  ///< significant digits in timeseries.csv
};

/// Every column after step and time_us, in CSV order.
const std::vector<ObservableField>& observable_fields();

/// The header row of timeseries.csv: step,time_us, then observable_fields().
std::string timeseries_header();
/// One row of timeseries.csv (no newline).
std::string timeseries_row(const sim::Observables& o);

}  // namespace ibrod::io
