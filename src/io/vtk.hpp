#pragma once
// ParaView/VTK output (VTK XML formats, ASCII, readable by ParaView ≥ 5 and VTK's XML readers):
//   DIR/rod.pvd                 collection: one DataSet per trajectory frame, timestep in µs
//   DIR/vtk/rod_<step>.vtp      PolyData: the rod as one closed polyline
//   DIR/fluid.pvd, DIR/vtk/fluid_<step>.vti   ImageData: the fluid velocity (output.fluid_vti)
// <step> is the time step, zero-padded to at least 6 digits.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/grid.hpp"
#include "rod/rod.hpp"
#include "rod/rod_set.hpp"

namespace ibrod::io {

/// The rod as VTK XML PolyData: n points (Å, unwrapped), one closed polyline (connectivity
/// 0, 1, …, n−1, 0) and per-point data
///   d1, d2, d3                 triad columns D¹, D², D³ (3 components each)
///   twist_density_rad_per_A    Ω³, rad/Å: mean of the half points k−½ and k+½ (MODEL §4 strains)
///   stretch_strain             |X_{k+1} − X_k|/Δs − 1 of the segment from point k to k+1
/// ds_A: the rest spacing Δs, Å. closed = false (an open rod): an open polyline (connectivity
/// 0 … n−1, no closing segment); the end points' twist density is their one half point's, and
/// the last point's stretch_strain that of the segment before it.
std::string rod_vtp(const rod::RodState& s, double ds_A, bool closed = true);
/// The same for several rods laid end to end (rod::RodRange, in order; each its own Δs in
/// ds_A): one polyline cell per rod, the twist density and strain of each rod's own links, and
/// a point array `rod` (0, 1, …) to colour them by. One range: exactly rod_vtp(s, ds, closed).
std::string rod_vtp(const rod::RodState& s, const std::vector<double>& ds_A,
                    const std::vector<rod::RodRange>& ranges);

/// The fluid velocity as VTK XML ImageData on the grid points (origin 0, spacing h in Å), point
/// data velocity_A_per_ns (3 components, Å/ns). u: the three components in Å/s, GridSpec::index
/// layout.
std::string fluid_vti(const GridSpec& g, std::array<const double*, 3> u);

/// A .pvd collection of files DIR/vtk/<prefix>_<step>.<ext>, rewritten (atomically) with every
/// frame, so that it is always complete.
class PvdSeries {
 public:
  /// dir: the run directory; prefix: "rod" or "fluid"; ext: "vtp" or "vti".
  PvdSeries(std::filesystem::path dir, std::string prefix, std::string ext);
  /// Continues an existing series: keeps the entries of DIR/<prefix>.pvd with step <= last_step
  /// and deletes DIR/vtk/<prefix>_* files of later steps.
  void resume(std::int64_t last_step);
  /// Writes `xml` to DIR/vtk/<prefix>_<step>.<ext> and adds it to the collection.
  void add(std::int64_t step, double time_us, const std::string& xml);
  std::size_t size() const { return entries_.size(); }

 private:
  struct Entry {
    std::int64_t step;
    double time_us;
    std::string file;  // relative to dir
  };
  std::filesystem::path dir_;
  std::string prefix_, ext_;
  std::vector<Entry> entries_;
  void write_pvd() const;
};

}  // namespace ibrod::io
