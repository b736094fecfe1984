#include "io/csv.hpp"

#include <cmath>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <utility>

#include "core/error.hpp"
#include "core/text_file.hpp"
#include "diagnostics/topology.hpp"

namespace ibrod::io {

namespace fs = std::filesystem;

namespace {

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, sep)) out.push_back(field);
  if (!line.empty() && line.back() == sep) out.emplace_back();
  return out;
}

}  // namespace

bool parse_double(const std::string& s, double& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  v = std::strtod(s.c_str(), &end);
  while (end && (*end == ' ' || *end == '\r')) ++end;
  return end && *end == '\0' && s.c_str() != end;
}

bool CsvTable::has(const std::string& name) const {
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::span<const double> CsvTable::column(const std::string& name) const {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw ConfigError("'" + path.string() + "' has no column '" + name + "'");
  return columns[std::size_t(it - names.begin())];
}

CsvTable read_csv_table(const fs::path& path) {
  const std::string text = read_text_file(path, "csv");
  CsvTable t;
  t.path = path;
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line)) throw ConfigError("'" + path.string() + "' is empty");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  t.names = split(line, ',');
  t.columns.assign(t.names.size(), {});
  const bool ends_in_newline = !text.empty() && text.back() == '\n';
  std::size_t lineno = 1;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line == "\r") continue;
    const auto fields = split(line, ',');
    std::vector<double> v(fields.size());
    bool ok = fields.size() == t.names.size();
    // an empty field is a value that is not defined (an open rod's writhe and link): NaN; on a
    // last line without its newline it may be a row cut short, which is dropped below
    const bool last_cut = in.peek() == EOF && !ends_in_newline;
    for (std::size_t k = 0; ok && k < fields.size(); ++k) {
      const std::string& f = fields[k];
      if (f.empty() || f == "\r") {
        v[k] = std::numeric_limits<double>::quiet_NaN();
        ok = !last_cut;
      } else {
        ok = parse_double(f, v[k]);
      }
    }
    if (!ok) {
      if (in.peek() == EOF && !ends_in_newline) break;  // a row cut short by a killed run
      throw ConfigError("'" + path.string() + "' line " + std::to_string(lineno) + ": expected " +
                        std::to_string(t.names.size()) + " numbers, got '" + line + "'");
    }
    for (std::size_t k = 0; k < v.size(); ++k) t.columns[k].push_back(v[k]);
  }
  return t;
}

namespace {
// One point's row of final_state.csv (no newline): position and triad columns, 17 digits.
void append_state_row(std::string& out, const Vec3& x, const Mat3& D) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", x[0],
                x[1], x[2], D(0, 0), D(1, 0), D(2, 0), D(0, 1), D(1, 1), D(2, 1), D(0, 2), D(1, 2),
                D(2, 2));
  out += buf;
}
constexpr const char* kStateHeader = "x_A,y_A,z_A,d1x,d1y,d1z,d2x,d2y,d2z,d3x,d3y,d3z\n";
}  // namespace

std::string final_state_csv(const rod::RodState& s) {
  std::string out = kStateHeader;
  for (int k = 0; k < s.size(); ++k) {
    append_state_row(out, s.X[k], s.D[k]);
    out += '\n';
  }
  return out;
}

std::string final_state_csv(const rod::RodState& s, const std::vector<rod::RodRange>& ranges) {
  if (!rod::names_rods(ranges)) return final_state_csv(s);
  std::string out = std::string("rod,") + kStateHeader;  // each row after its rod's number
  rod::for_each_rod(ranges, [&](std::size_t r, const rod::RodRange& g) {
    for (int k = g.offset; k < g.offset + g.n; ++k) {
      out += std::to_string(r) + ",";
      append_state_row(out, s.X[k], s.D[k]);
      out += '\n';
    }
  });
  return out;
}

std::vector<RodColumn> rod_columns(std::span<const rod::RodRange> rods) {
  std::vector<RodColumn> c;
  rod::for_each_rod(rods, [&](std::size_t r, const rod::RodRange&) {
    const std::string k = std::to_string(r);
    using PerRod = sim::Observables::PerRod;
    for (auto [name, member] :
         {std::pair{"writhe_", &PerRod::writhe}, std::pair{"twist_", &PerRod::twist},
          std::pair{"link_", &PerRod::link}})
      c.push_back({name + k, [r, member](const sim::Observables& o) { return o.rod(r).*member; }});
  });
  std::size_t q = 0;  // the pair's place in Observables::pair_links
  rod::for_each_pair(rods, [&](std::size_t a, std::size_t b) {
    // the pairs Simulation::observe fills: both links defined
    if (!diagnostics::link_defined(rods[a]) || !diagnostics::link_defined(rods[b])) return;
    c.push_back(
        {"link_" + std::to_string(a) + "_" + std::to_string(b), [q](const sim::Observables& o) {
           return q < o.pair_links.size() ? o.pair_links[q]
                                          : std::numeric_limits<double>::quiet_NaN();
         }});
    ++q;
  });
  return c;
}

std::string rods_header(std::span<const rod::RodRange> rods) {
  std::string s = "step,time_us";
  for (const RodColumn& c : rod_columns(rods)) s += "," + c.name;
  return s;
}

std::string rods_row(const sim::Observables& o) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%lld,%.10g", static_cast<long long>(o.step), o.time_us);
  std::string s = buf;
  for (const auto& r : o.rods)
    for (double v : {r.writhe, r.twist, r.link}) {
      if (std::isnan(v)) {  // not defined: an open rod's writhe and link
        s += ',';
        continue;
      }
      std::snprintf(buf, sizeof buf, ",%.12g", v);
      s += buf;
    }
  for (double v : o.pair_links) {
    std::snprintf(buf, sizeof buf, ",%.12g", v);
    s += buf;
  }
  return s;
}

std::string timeseries_up_to(const std::string& text, const std::string& header,
                             std::int64_t last_step, const std::string& source) {
  std::string out = header + "\n";
  std::size_t pos = text.find('\n');
  if (pos != std::string::npos && text.substr(0, pos) != header)
    throw RunError("resume: " + source +
                   " has other columns than this ibrod writes; move it away to resume");
  std::int64_t prev = -1;
  while (pos != std::string::npos && pos + 1 < text.size()) {
    const std::size_t end = text.find('\n', pos + 1);
    if (end == std::string::npos) break;  // an incomplete last line (killed mid-write)
    const std::string line = text.substr(pos + 1, end - pos - 1);
    pos = end;
    char* stop = nullptr;
    const long long step = std::strtoll(line.c_str(), &stop, 10);
    if (stop == line.c_str() || *stop != ',' || step > last_step || step <= prev) continue;
    prev = step;
    out += line + "\n";
  }
  return out;
}

}  // namespace ibrod::io
