// Shapes and contacts of a run directory (shapes.hpp).
#include "analysis/shapes.hpp"

#include <cmath>

#include "analysis/frames.hpp"
#include "core/error.hpp"
#include "core/units.hpp"
#include "io/h5md.hpp"
#include "io/run_dir.hpp"

namespace ibrod::analysis {

namespace fs = std::filesystem;

double default_contact_distance(double diameter_A, double salt_M) {
  const double debye = salt_M > 0 ? 1.0 / units::debye_kappa(salt_M) : 100.0;
  return diameter_A + 3.0 * debye;
}

namespace {

/// Every frame's positions of DIR/trajectory.h5md (time, X).
std::vector<RodFrame> read_positions(const fs::path& p) {
  io::H5mdSeries pos;
  try {
    pos = io::read_h5md_series(p, "position");
  } catch (const RunError& e) {
    throw ConfigError(std::string("cannot read the trajectory: ") + e.what());
  }
  std::vector<RodFrame> frames(pos.time_us.size());
  const std::size_t n = std::size_t(pos.n);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    frames[i].time_us = pos.time_us[i];
    for (std::size_t k = 0; k < n; ++k) {
      const double* x = &pos.value[3 * (i * n + k)];
      frames[i].X.emplace_back(x[0], x[1], x[2]);
    }
  }
  return frames;
}

}  // namespace

ShapeAnalysis analyze_shapes(const fs::path& dir, double contact_distance_A, bool every_frame,
                             diagnostics::ShapeOptions opt) {
  opt.contact_distance_A = contact_distance_A;
  const double s_min = opt.min_separation_A > 0 ? opt.min_separation_A : 2 * contact_distance_A;
  ShapeAnalysis out;
  out.contact_distance_A = contact_distance_A;
  const io::RunDir rd(dir);
  if (fs::exists(rd.final_state())) {
    const RodFrame f = read_final_state(dir);
    if (f.X.size() >= 8)
      out.final_shape = ShapeRecord{f.time_us, diagnostics::analyze_shape(f.X, opt)};
  }
  if (!fs::exists(rd.trajectory())) {
    out.contacts.note = "no trajectory.h5md (output.frame_every_steps = 0?)";
    return out;
  }
  const auto frames = read_positions(rd.trajectory());
  if (frames.size() < 2) {
    out.contacts.note = rd.trajectory().filename().string() + " holds fewer than 2 frames";
    return out;
  }
  out.contacts.source = rd.trajectory().filename().string();
  for (const RodFrame& f : frames) {
    if (f.X.size() < 8) continue;
    // a continued run may rewrite a stretch: keep times increasing, the later frames win
    while (!out.contacts.time_us.empty() && out.contacts.time_us.back() >= f.time_us) {
      out.contacts.time_us.pop_back();
      out.contacts.clusters.pop_back();
      if (every_frame && !out.frames.empty()) out.frames.pop_back();
    }
    out.contacts.time_us.push_back(f.time_us);
    if (every_frame) {
      out.frames.push_back({f.time_us, diagnostics::analyze_shape(f.X, opt)});
      out.contacts.clusters.push_back(out.frames.back().shape.contact_clusters);
    } else {
      out.contacts.clusters.push_back(
          int(diagnostics::contact_clusters(f.X, contact_distance_A, s_min).size()));
    }
  }
  return out;
}

}  // namespace ibrod::analysis
