#pragma once
// The one small configuration of the integration tests: a 100-point ring (r0 ≈ 54 Å) in a 200 Å
// box on a 16³ grid (h = 12.5 Å, close to the reference 11.3 Å), so that a run of a few thousand
// steps takes seconds. Tests that start the real binary write it with config::to_toml after
// changing what they need.
#include <filesystem>
#include <fstream>
#include <string>

#include "config/config.hpp"

namespace ibrod::test {

inline config::Config small_config(int excess_link) {
  config::Config c;
  c.grid_n = 16;
  c.grid_box_A = 200;
  c.rod_base_pairs = 100;
  c.rod_excess_link = excess_link;
  c.time_dt_ns = 0.1;
  c.time_t_end_us = 0.2;
  c.output_every_steps = 100;
  c.run_fftw_measure = false;
  return c;
}

/// small_config as the TOML document `ibrod run CONFIG` reads.
inline std::string small_config_toml(const config::Config& c) { return config::to_toml(c); }

/// Writes c (as small_config_toml) to d/name; returns that path.
inline std::filesystem::path write_config(const std::filesystem::path& d, const config::Config& c,
                                          const std::string& name) {
  const std::filesystem::path p = d / name;
  std::ofstream(p) << small_config_toml(c);
  return p;
}

}  // namespace ibrod::test
