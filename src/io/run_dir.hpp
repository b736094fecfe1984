#pragma once
// The names of every file of a run directory, in one place (docs/outputs.md describes each):
//   config.toml        the resolved configuration (every key)
//   timeseries.csv     one row per output step (io/observables.hpp: timeseries_header())
//   trajectory.h5md    H5MD trajectory: frames, observables, config (io/h5md.hpp); the
//                      extension is H5MD's, so that MDAnalysis and other readers know the
//                      format by name. Older run directories have trajectory.h5
//                      (the same layout): read, resumed and extended under that name
//   rod.pvd, vtk/      ParaView series of the rod (.vtp), with every frame (io/vtk.hpp)
//   fluid.pvd          ParaView series of the fluid velocity (.vti; output.fluid_vti)
//   checkpoint.bin     the full state at the latest checkpoint (io/checkpoint.hpp)
//   fftw.wisdom        the FFTW plans of the run (imported by --resume: same plans, same bits)
//   final_state.csv    one row per rod point (io/csv.hpp: final_state_csv())
//   summary.json       steps, simulated time, why it stopped, link drift, observables, timing
//   velocity.npy       the final fluid velocity (output.fluid_velocity; io/npy.hpp)
//   render/            pictures of `ibrod render`
//   ibrod.lock         the writer's lock: the PID of the process writing the directory
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace ibrod::io {

class RunDir {
 public:
  explicit RunDir(std::filesystem::path root) : root_(std::move(root)) {}
  const std::filesystem::path& root() const { return root_; }

  std::filesystem::path config() const { return root_ / "config.toml"; }
  std::filesystem::path timeseries() const { return root_ / "timeseries.csv"; }
  /// several rods: each rod's writhe, twist and link at every row (docs/outputs.md)
  std::filesystem::path rods() const { return root_ / "rods.csv"; }
  /// The run's H5MD trajectory: trajectory.h5md, or the legacy trajectory.h5 of an older run
  /// when that one exists and trajectory.h5md does not (so an old run is read and resumed in
  /// place, never split over two files).
  std::filesystem::path trajectory() const {
    std::error_code ec;
    const std::filesystem::path current = root_ / kTrajectory, legacy = root_ / kLegacyTrajectory;
    if (!std::filesystem::exists(current, ec) && std::filesystem::exists(legacy, ec)) return legacy;
    return current;
  }
  static constexpr const char* kTrajectory = "trajectory.h5md";
  static constexpr const char* kLegacyTrajectory = "trajectory.h5";
  /// where a trajectory that cannot be reopened on resume is moved (kept for inspection)
  std::filesystem::path damaged_trajectory(std::int64_t step) const {
    return root_ / ("trajectory.damaged-" + std::to_string(step) + ".h5md");
  }
  std::filesystem::path checkpoint() const { return root_ / "checkpoint.bin"; }
  std::filesystem::path wisdom() const { return root_ / "fftw.wisdom"; }
  std::filesystem::path final_state() const { return root_ / "final_state.csv"; }
  std::filesystem::path summary() const { return root_ / "summary.json"; }
  std::filesystem::path velocity() const { return root_ / "velocity.npy"; }
  std::filesystem::path render_dir() const { return root_ / "render"; }
  /// held (flock) by the one process that writes the directory (driver/dir_lock.hpp)
  std::filesystem::path lock() const { return root_ / "ibrod.lock"; }
  /// the ParaView series: "<prefix>.pvd" and vtk/<prefix>_<step>.<ext>
  static constexpr const char* kRodSeries = "rod";
  static constexpr const char* kFluidSeries = "fluid";
  static constexpr const char* kVtkDir = "vtk";

  /// Every file a run writes at the top of the directory (what --overwrite removes before a new
  /// run, with the frames of vtk/ that is_frame_file names; nothing else: a file of the user's
  /// in the directory or in vtk/ is kept).
  std::vector<std::filesystem::path> run_files() const {
    return {config(),          timeseries(),        root_ / kTrajectory, root_ / kLegacyTrajectory,
            root_ / "rod.pvd", root_ / "fluid.pvd", checkpoint(),        wisdom(),
            final_state(),     summary(),           velocity(),          rods()};
  }
  /// Whether `name` (a file name in vtk/) is a frame a run writes: rod_<step>.vtp or
  /// fluid_<step>.vti (or such a file's ".tmp" of a write cut off).
  static bool is_frame_file(std::string name) {
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".tmp") == 0)
      name.resize(name.size() - 4);
    const auto is_frame = [&](const std::string& prefix, const std::string& ext) {
      if (name.size() <= prefix.size() + ext.size() + 1 || name.rfind(prefix + "_", 0) != 0 ||
          name.compare(name.size() - ext.size(), ext.size(), ext) != 0)
        return false;
      for (std::size_t i = prefix.size() + 1; i < name.size() - ext.size(); ++i)
        if (name[i] < '0' || name[i] > '9') return false;
      return true;
    };
    return is_frame(kRodSeries, ".vtp") || is_frame(kFluidSeries, ".vti");
  }

 private:
  std::filesystem::path root_;
};

}  // namespace ibrod::io
