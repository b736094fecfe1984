#include "io/observables.hpp"

#include <cmath>
#include <cstdio>

namespace ibrod::io {

const std::vector<ObservableField>& observable_fields() {
  using O = sim::Observables;
  static const std::vector<ObservableField> f = {
      {"E_bend_kT", &O::E_bend_kT, 12},
      {"E_twist_kT", &O::E_twist_kT, 12},
      {"E_stretch_kT", &O::E_stretch_kT, 12},
      {"E_electro_kT", &O::E_electro_kT, 12},
      {"dE_electro_kT", &O::dE_electro_kT, 12},
      {"E_steric_kT", &O::E_steric_kT, 12},
      {"E_kinetic_kT", &O::E_kinetic_kT, 12},
      {"E_total_kT", &O::E_total_kT, 12},
      {"writhe", &O::writhe, 12},
      {"twist", &O::twist, 12},
      {"link", &O::link, 12},
      {"closest_approach_A", &O::closest_approach_A, 10},
      {"bp_spacing_A", &O::bp_spacing_A, 10},
  };
  return f;
}

std::string timeseries_header() {
  std::string s = "step,time_us";
  for (const auto& f : observable_fields()) s += std::string(",") + f.name;
  return s;
}

std::string timeseries_row(const sim::Observables& o) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%lld,%.10g", static_cast<long long>(o.step), o.time_us);
  std::string s = buf;
  for (const auto& f : observable_fields()) {
    // NaN: not defined (an open rod's writhe and link; docs/outputs.md): an empty field
    if (std::isnan(o.*f.member)) {
      s += ',';
      continue;
    }
    std::snprintf(buf, sizeof buf, ",%.*g", f.csv_digits, o.*f.member);
    s += buf;
  }
  return s;
}

}  // namespace ibrod::io
