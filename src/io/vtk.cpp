#include "io/vtk.hpp"
#include "io/run_dir.hpp"

#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace ibrod::io {
namespace fs = std::filesystem;

namespace {

void append_fmt(std::string& out, const char* fmt, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, a);
  out += buf;
}

// One DataArray of `comps` components: values(k, c) for k < count.
template <class F>
void data_array(std::string& out, const char* type, const char* name, int comps, std::size_t count,
                F&& value, const char* fmt = "%.10g") {
  out += "        <DataArray type=\"";
  out += type;
  out += "\"";
  if (name) {
    out += " Name=\"";
    out += name;
    out += "\"";
  }
  out += " NumberOfComponents=\"" + std::to_string(comps) + "\" format=\"ascii\">\n";
  for (std::size_t k = 0; k < count; ++k) {
    out += "         ";
    for (int c = 0; c < comps; ++c) {
      out += ' ';
      append_fmt(out, fmt, value(k, c));
    }
    out += '\n';
  }
  out += "        </DataArray>\n";
}

// Ω³ at the half point k+½ (MODEL §4 strains): (D¹_{k+1} − D¹_k)/Δs · D²_{k+½}, rad/Å.
double twist_density(const Mat3& Dk, const Mat3& Dk1, double ds) {
  const Mat3 Dh = rod::half_point_triad(Dk, Dk1);
  return ((Dk1.col(0) - Dk.col(0)) / ds).dot(Dh.col(1));
}

}  // namespace

namespace {
// The .vtp of rods laid end to end (one polyline each); `rod_array`: the point array `rod`.
std::string rods_vtp(const rod::RodState& s, const std::vector<double>& ds_A,
                     const std::vector<rod::RodRange>& ranges, bool rod_array) {
  const int n = s.size();
  std::vector<double> omega(n), strain(n), rod_of(n);
  std::size_t lines = 0;  // connectivity entries
  rod::for_each_rod(ranges, [&](std::size_t r, const rod::RodRange& g) {
    const double ds = ds_A.at(r);
    std::vector<double> om(g.n), st(g.n);  // per half point k+½ of this rod
    for (int k = 0; k < rod::half_points(g.n, g.closed); ++k) {
      const int a = g.offset + k, b = g.offset + (k + 1 == g.n ? 0 : k + 1);
      om[k] = twist_density(s.D[a], s.D[b], ds);
      st[k] = (s.X[b] - s.X[a]).norm() / ds - 1.0;
    }
    if (!g.closed && g.n >= 2) {
      om[g.n - 1] = om[g.n - 2];
      st[g.n - 1] = st[g.n - 2];
    }
    for (int k = 0; k < g.n; ++k) {
      omega[g.offset + k] =
          (!g.closed && k == 0) ? om[0] : 0.5 * (om[k] + om[k == 0 ? g.n - 1 : k - 1]);
      strain[g.offset + k] = st[k];
      rod_of[g.offset + k] = double(r);
    }
    lines += std::size_t(g.n) + (g.closed ? 1 : 0);
  });
  std::vector<double> connectivity, offsets;
  connectivity.reserve(lines);
  for (const rod::RodRange& g : ranges) {
    for (int k = 0; k < g.n; ++k) connectivity.push_back(g.offset + k);
    if (g.closed) connectivity.push_back(g.offset);  // the first point again: a closed polyline
    offsets.push_back(double(connectivity.size()));
  }
  std::string out;
  out.reserve(std::size_t(n) * 280 + 1024);
  out +=
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n"
      "  <PolyData>\n";
  out += "    <Piece NumberOfPoints=\"" + std::to_string(n) +
         "\" NumberOfVerts=\"0\" NumberOfLines=\"" + std::to_string(offsets.size()) +
         "\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
  out += "      <PointData Scalars=\"twist_density_rad_per_A\" Vectors=\"d3\">\n";
  const char* const triad_names[3] = {"d1", "d2", "d3"};
  for (int c = 0; c < 3; ++c)
    data_array(out, "Float64", triad_names[c], 3, n,
               [&](std::size_t k, int i) { return s.D[k](i, c); });
  data_array(out, "Float64", "twist_density_rad_per_A", 1, n,
             [&](std::size_t k, int) { return omega[k]; });
  data_array(out, "Float64", "stretch_strain", 1, n, [&](std::size_t k, int) { return strain[k]; });
  if (rod_array)
    data_array(
        out, "Int32", "rod", 1, n, [&](std::size_t k, int) { return rod_of[k]; }, "%.0f");
  out += "      </PointData>\n      <Points>\n";
  data_array(out, "Float64", "Points", 3, n, [&](std::size_t k, int i) { return s.X[k][i]; });
  out += "      </Points>\n      <Lines>\n";
  data_array(
      out, "Int64", "connectivity", 1, connectivity.size(),
      [&](std::size_t k, int) { return connectivity[k]; }, "%.0f");
  data_array(
      out, "Int64", "offsets", 1, offsets.size(), [&](std::size_t k, int) { return offsets[k]; },
      "%.0f");
  out += "      </Lines>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  return out;
}
}  // namespace

std::string rod_vtp(const rod::RodState& s, double ds_A, bool closed) {
  return rods_vtp(s, {ds_A}, {{0, s.size(), closed}}, false);
}

std::string rod_vtp(const rod::RodState& s, const std::vector<double>& ds_A,
                    const std::vector<rod::RodRange>& ranges) {
  return rods_vtp(s, ds_A, ranges, rod::names_rods(ranges));
}

std::string fluid_vti(const GridSpec& g, std::array<const double*, 3> u) {
  const int n = g.n;
  const double h = g.h();
  char hdr[512];
  std::snprintf(hdr, sizeof hdr,
                "<?xml version=\"1.0\"?>\n"
                "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" "
                "header_type=\"UInt64\">\n"
                "  <ImageData WholeExtent=\"0 %d 0 %d 0 %d\" Origin=\"0 0 0\" "
                "Spacing=\"%.17g %.17g %.17g\">\n"
                "    <Piece Extent=\"0 %d 0 %d 0 %d\">\n"
                "      <PointData Vectors=\"velocity_A_per_ns\">\n",
                n - 1, n - 1, n - 1, h, h, h, n - 1, n - 1, n - 1);
  std::string out = hdr;
  out.reserve(g.size() * 3 * 16 + 1024);
  // VTK image order: x fastest; ibrod's grid: z fastest (GridSpec::index)
  data_array(
      out, "Float64", "velocity_A_per_ns", 3, g.size(),
      [&](std::size_t p, int c) {
        const int i = int(p % std::size_t(n));
        const int j = int((p / std::size_t(n)) % std::size_t(n));
        const int k = int(p / (std::size_t(n) * std::size_t(n)));
        return u[c][g.index(i, j, k)] * 1e-9;  // Å/s → Å/ns
      },
      "%.8g");
  out +=
      "      </PointData>\n      <CellData>\n      </CellData>\n    </Piece>\n"
      "  </ImageData>\n</VTKFile>\n";
  return out;
}

PvdSeries::PvdSeries(fs::path dir, std::string prefix, std::string ext)
    : dir_(std::move(dir)), prefix_(std::move(prefix)), ext_(std::move(ext)) {}

void PvdSeries::resume(std::int64_t last_step) {
  entries_.clear();
  const std::regex file_re(prefix_ + "_([0-9]+)\\." + ext_ + "$");
  std::ifstream in(dir_ / (prefix_ + ".pvd"));
  const std::regex line_re("<DataSet timestep=\"([^\"]*)\"[^>]*file=\"([^\"]*)\"");
  std::string line;
  std::smatch m, f;
  while (std::getline(in, line)) {
    if (!std::regex_search(line, m, line_re)) continue;
    const std::string file = m[2];
    if (!std::regex_search(file, f, file_re)) continue;
    const std::int64_t step = std::stoll(f[1]);
    if (step > last_step || (!entries_.empty() && step <= entries_.back().step)) continue;
    if (!fs::exists(dir_ / file)) continue;
    entries_.push_back({step, std::strtod(std::string(m[1]).c_str(), nullptr), file});
  }
  // files of later frames would be stale
  std::error_code ec;
  if (fs::is_directory(dir_ / RunDir::kVtkDir, ec))
    for (const auto& e : fs::directory_iterator(dir_ / RunDir::kVtkDir, ec)) {
      const std::string name = e.path().filename().string();
      if (std::regex_match(name, f, std::regex(prefix_ + "_([0-9]+)\\." + ext_)) &&
          std::stoll(f[1]) > last_step)
        fs::remove(e.path(), ec);
    }
  write_pvd();
}

void PvdSeries::add(std::int64_t step, double time_us, const std::string& xml) {
  char name[96];
  std::snprintf(name, sizeof name, "vtk/%s_%06lld.%s", prefix_.c_str(),
                static_cast<long long>(step), ext_.c_str());
  std::error_code ec;
  fs::create_directories(dir_ / RunDir::kVtkDir, ec);
  write_file_atomic(dir_ / name, xml);
  entries_.push_back({step, time_us, name});
  write_pvd();
}

void PvdSeries::write_pvd() const {
  std::string out =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  char buf[256];
  for (const Entry& e : entries_) {
    std::snprintf(buf, sizeof buf,
                  "    <DataSet timestep=\"%.12g\" group=\"\" part=\"0\" file=\"%s\"/>\n",
                  e.time_us, e.file.c_str());
    out += buf;
  }
  out += "  </Collection>\n</VTKFile>\n";
  write_file_atomic(dir_ / (prefix_ + ".pvd"), out);
}

}  // namespace ibrod::io
