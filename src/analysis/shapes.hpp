#pragma once
// The shapes and contacts of a run directory for `ibrod analyze` (docs/analysis.md "Shapes" and
// "Relaxation time after the last contact"): the shape of the final state (final_state.csv),
// optionally of every frame of trajectory.h5md, and the number of contact clusters per frame.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "diagnostics/shape.hpp"

namespace ibrod::analysis {

/// The contact distance d_c = D + 3 λ_D (D = steric.diameter_A, λ_D = 1/κ the Debye length at
/// solvent.salt_M; D + 3·100 Å without salt), Å.
double default_contact_distance(double diameter_A, double salt_M);

/// The shape of one configuration at a time.
struct ShapeRecord {
  double time_us = 0;
  diagnostics::Shape shape;
};

/// Contact clusters (diagnostics::contact_clusters at d_c, pairs ≥ 2 d_c apart along the rod) of
/// every frame of trajectory.h5md; empty `time_us` and a `note` when there is none.
struct ContactHistory {
  std::vector<double> time_us;
  std::vector<int> clusters;
  std::string note;    ///< why there is no history ("" when there is one)
  std::string source;  ///< the trajectory's file name (trajectory.h5md, or an old run's .h5)
};

struct ShapeAnalysis {
  double contact_distance_A = 0;
  std::optional<ShapeRecord> final_shape;  ///< none without final_state.csv
  std::vector<ShapeRecord> frames;         ///< every frame, with `every_frame`
  ContactHistory contacts;
};

/// Reads DIR/final_state.csv and DIR/trajectory.h5md (when present) and analyses them with
/// `opt` (its contact_distance_A replaced by `contact_distance_A`). Every frame's shape only
/// when `every_frame`; the contacts of every frame always (they are cheap: O(n²) per frame).
ShapeAnalysis analyze_shapes(const std::filesystem::path& dir, double contact_distance_A,
                             bool every_frame, diagnostics::ShapeOptions opt = {});

}  // namespace ibrod::analysis
