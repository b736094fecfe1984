#include "io/rod_shape.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>

#include "core/error.hpp"
#include "io/csv.hpp"
#include "io/h5md.hpp"

namespace ibrod::io {

namespace {

// "PATH@FRAME" with FRAME an integer: true and both parts; anything else is a plain path.
bool split_frame(const std::string& spec, std::string& path, long long& frame) {
  const auto at = spec.rfind('@');
  if (at == std::string::npos || at == 0 || at + 1 == spec.size()) return false;
  const std::string f = spec.substr(at + 1);
  char* end = nullptr;
  const long long v = std::strtoll(f.c_str(), &end, 10);
  if (end != f.c_str() + f.size()) return false;
  path = spec.substr(0, at);
  frame = v;
  return true;
}

rod::RodState from_csv(const std::string& path, const std::string& key, int rod_index) {
  const CsvTable t = read_csv_table(path);
  static const char* names[12] = {"x_A", "y_A", "z_A", "d1x", "d1y", "d1z",
                                  "d2x", "d2y", "d2z", "d3x", "d3y", "d3z"};
  for (const char* n : names)
    if (!t.has(n))
      throw ConfigError(key + " = '" + path + "': the file has no column " + n +
                        " (expected the columns of final_state.csv: x_A,y_A,z_A,d1x,d1y,d1z,"
                        "d2x,d2y,d2z,d3x,d3y,d3z)");
  // the rows to take: all, or a file of several rods' rows of rod `rod_index`
  std::vector<std::size_t> rows;
  if (t.has("rod")) {
    const auto rod = t.column("rod");
    double most = 0;
    for (double v : rod) most = std::max(most, v);
    const int want = rod_index < 0 ? 0 : rod_index;
    if (rod_index < 0 && most > 0)
      throw ConfigError(key + " = '" + path + "': the file holds " + std::to_string(int(most) + 1) +
                        " rods (a run of several rods); a [[rods]] table's rod.initial_shape takes "
                        "its own rod from it, a run of one rod cannot");
    for (std::size_t k = 0; k < rod.size(); ++k)
      if (rod[k] == want) rows.push_back(k);
    if (rows.empty())
      throw ConfigError(key + " = '" + path + "': the file has no rows of rod " +
                        std::to_string(want) + " (it holds rods 0 to " + std::to_string(int(most)) +
                        ")");
  } else {
    for (std::size_t k = 0; k < t.rows(); ++k) rows.push_back(k);
  }
  const std::size_t n = rows.size();
  rod::RodState s;
  s.X.resize(n);
  s.D.resize(n);
  for (int c = 0; c < 3; ++c) {
    const auto x = t.column(names[c]);
    for (std::size_t k = 0; k < n; ++k) s.X[k][c] = x[rows[k]];
    for (int col = 0; col < 3; ++col) {
      const auto d = t.column(names[3 + 3 * col + c]);
      for (std::size_t k = 0; k < n; ++k) s.D[k](c, col) = d[rows[k]];
    }
  }
  return s;
}

rod::RodState from_h5md(const std::string& path, long long frame, const std::string& key) {
  const std::string what = key + " = '" + path + "@" + std::to_string(frame) + "'";
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw ConfigError(what + ": no such file");
  H5mdSeries e[4];
  try {
    const char* names[4] = {"position", "d1", "d2", "d3"};
    for (int i = 0; i < 4; ++i) e[i] = read_h5md_series(path, names[i]);
  } catch (const RunError& err) {
    throw ConfigError(what + ": " + err.what());
  }
  const long long T = static_cast<long long>(e[0].step.size());
  const long long f = frame < 0 ? T + frame : frame;
  if (f < 0 || f >= T)
    throw ConfigError(what + ": the file has " + std::to_string(T) + " frames (FRAME from 0 to " +
                      std::to_string(T - 1) + ", or -1 for the last)");
  const int n = e[0].n;
  rod::RodState s;
  s.X.resize(n);
  s.D.resize(n);
  const std::size_t off = std::size_t(f) * std::size_t(n) * 3;
  for (int k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c) {
      s.X[k][c] = e[0].value[off + 3 * k + c];
      for (int col = 0; col < 3; ++col) s.D[k](c, col) = e[1 + col].value[off + 3 * k + c];
    }
  return s;
}

}  // namespace

rod::RodState read_rod_shape(const std::string& spec, const std::string& key, int rod_index) {
  std::string path;
  long long frame = -1;
  if (split_frame(spec, path, frame)) return from_h5md(path, frame, key);
  const auto ends_with = [&spec](const std::string& tail) {
    return spec.size() > tail.size() &&
           spec.compare(spec.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (ends_with(".h5md") || ends_with(".h5")) return from_h5md(spec, -1, key);
  std::error_code ec;
  if (!std::filesystem::exists(spec, ec))
    throw ConfigError(key + " = '" + spec + "': no such file");
  try {
    return from_csv(spec, key, rod_index);
  } catch (const ConfigError& err) {
    const std::string m = err.what();
    if (m.rfind(key, 0) == 0) throw;
    throw ConfigError(key + " = '" + spec + "': " + m);
  }
}

}  // namespace ibrod::io
