#pragma once
// One time-series row as a JSON object (summary.json's initial/final, the checkpoint's initial
// row): step, time_us, then every column of observable_fields() (NaN and Inf become null).
#include <nlohmann/json.hpp>

#include "io/observables.hpp"

namespace ibrod::io {

inline nlohmann::ordered_json observables_json(const sim::Observables& o) {
  nlohmann::ordered_json j;
  j["step"] = o.step;
  j["time_us"] = o.time_us;
  for (const auto& f : observable_fields()) j[f.name] = o.*f.member;
  return j;
}

}  // namespace ibrod::io
