#pragma once
// The files of a run directory that grow while it runs — timeseries.csv, trajectory.h5md, rod.pvd
// (+ fluid.pvd) — and the ones written at its end (summary.json); driver::Run's writers.
#include <sys/stat.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "config/config.hpp"
#include "core/error.hpp"
#include "core/text_file.hpp"
#include "driver/dir_lock.hpp"
#include "driver/progress.hpp"
#include "driver/run.hpp"
#include "io/atomic_file.hpp"
#include "io/checkpoint.hpp"
#include "io/csv.hpp"
#include "io/h5md.hpp"
#include "io/observables.hpp"
#include "io/run_dir.hpp"
#include "io/vtk.hpp"
#include "sim/simulation.hpp"

namespace ibrod::driver {

/// Makes the output directory of a fresh run and takes its lock (into `lock`; ConfigError if
/// another process writes it): refuses a non-directory or (without overwrite) a directory that
/// holds files; with overwrite removes every file an earlier run left (RunDir::run_files), so
/// that stale frames or checkpoints never mix with the new run.
void prepare_output_dir(const io::RunDir& dir, bool overwrite, std::optional<DirLock>& lock);

/// summary.json of a run that stopped (stop_reason) or failed (error non-empty); link_defined:
/// the collection's link is defined (Simulation::link_defined: every rod closed), written as
/// summary.json's "closed".
std::string summary_json(const config::Config& c, bool link_defined, const RunResult& r,
                         const io::CheckpointMeta& meta, std::int64_t frames,
                         const std::string& stop_reason, const std::string& error);

// Only rank 0 of a distributed run holds one.
class RunFiles {
 public:
  // resume_step < 0: a fresh run (create everything); otherwise continue the files, dropping
  // rows after resume_step and frames after frame_step (−1: resume_step).
  RunFiles(const io::RunDir& dir, const config::Config& c, const sim::Simulation& sim,
           std::int64_t resume_step, const std::string& config_text, Progress& progress,
           std::int64_t frame_step = -1)
      : dir_(dir),
        ranges_(sim.rod_ranges()),
        vti_(c.output_fluid_vti),
        frames_on_(sim.params().output.frames > 0),
        rod_pvd_(dir.root(), io::RunDir::kRodSeries, "vtp"),
        fluid_pvd_(dir.root(), io::RunDir::kFluidSeries, "vti") {
    const std::filesystem::path ts = dir.timeseries();
    const int n = sim.rod().size();
    for (const rod::RodParams& r : sim.rods()) rod_ds_.push_back(r.ds);
    // rods.csv and each point's rod (the H5MD species) where the files name the rods
    const bool several = rod::names_rods(ranges_);
    const std::string rods_header = io::rods_header(ranges_);
    if (resume_step < 0) {
      io::write_file_atomic(ts, io::timeseries_header() + "\n");
      if (several) io::write_file_atomic(dir.rods(), rods_header + "\n");
      std::vector<int> species;
      if (several)
        rod::for_each_rod(ranges_, [&](std::size_t r, const rod::RodRange& g) {
          species.insert(species.end(), std::size_t(g.n), int(r));
        });
      if (frames_on_)
        h5_ = io::H5mdWriter::create(dir.trajectory(), n, c.grid_box_A, config_text, species);
    } else {
      // a file of the run that is gone (deleted by hand) starts again at the checkpoint: said,
      // since every row or frame before it is lost
      const auto missing = [&](const std::filesystem::path& f, const std::string& what) {
        std::error_code ec;
        if (std::filesystem::exists(f, ec)) return;
        progress.message("ibrod: warning: " + f.string() +
                         " is missing (deleted?); it starts again at the checkpoint (step " +
                         std::to_string(resume_step) + "), so the " + what + " before it are lost");
      };
      missing(ts, "time-series rows");
      if (several) missing(dir.rods(), "rows");
      if (frames_on_) missing(dir.trajectory(), "frames");
      io::write_file_atomic(
          ts, io::timeseries_up_to(try_read_text_file(ts).value_or(""), io::timeseries_header(),
                                   resume_step, ts.string()));
      if (several)
        io::write_file_atomic(dir.rods(),
                              io::timeseries_up_to(try_read_text_file(dir.rods()).value_or(""),
                                                   rods_header, resume_step, dir.rods().string()));
      if (frame_step < 0) frame_step = resume_step;
      if (frames_on_)
        reopen_trajectory(dir.trajectory(), n, c.grid_box_A, frame_step, config_text, progress);
      if (frames_on_) rod_pvd_.resume(frame_step);
      if (frames_on_ && vti_) fluid_pvd_.resume(frame_step);
    }
    // the directory as it is now: one deleted or moved under the running process is noticed
    struct stat st {};
    if (::stat(dir.root().c_str(), &st) == 0) {
      dev_ = st.st_dev;
      ino_ = st.st_ino;
    }
    ts_ = std::fopen(ts.c_str(), "a");
    if (!ts_)
      throw RunError("output: cannot open " + ts.string() + ": " + io::io_error_text(errno));
    if (several) {
      rods_ = std::fopen(dir.rods().c_str(), "a");
      if (!rods_)
        throw RunError("output: cannot open " + dir.rods().string() + ": " +
                       io::io_error_text(errno));
    }
  }
  ~RunFiles() {
    if (ts_) std::fclose(ts_);
    if (rods_) std::fclose(rods_);
  }
  RunFiles(const RunFiles&) = delete;
  RunFiles& operator=(const RunFiles&) = delete;

  /// Throws RunError if the device of the output directory has less than `bytes` free: a full
  /// disk is better met before a write than in the middle of one (HDF5 cannot always recover a
  /// file whose write failed half-way).
  /// has_checkpoint: the run has written a checkpoint, so `--resume` can continue it (otherwise
  /// the advice is to start it again with --overwrite).
  void ensure_space(std::uintmax_t bytes, bool has_checkpoint) const {
    std::error_code ec;
    const std::filesystem::space_info space = std::filesystem::space(dir_.root(), ec);
    if (!ec && space.available < bytes)
      throw RunError("output: only " + std::to_string(space.available >> 20) +
                     " MiB left on the "
                     "device of " +
                     dir_.root().string() +
                     " (disk full?); stopped before writing, so "
                     "every file is intact: free space and " +
                     (has_checkpoint ? "continue with --resume " + dir_.root().string()
                                     : "start the run again with --overwrite (it stopped before "
                                       "its first checkpoint)"));
  }

  /// Throws RunError if the run directory is no longer where it was (deleted, moved, replaced):
  /// every write after that would go into deleted files or a stranger's directory, so the run
  /// stops, saying where its files may be (a moved directory continues with --resume where it
  /// now is; a deleted one has nothing left to continue).
  void check_directory(std::int64_t step) const {
    struct stat st {};
    if (::stat(dir_.root().c_str(), &st) == 0 && st.st_dev == dev_ && st.st_ino == ino_) return;
    throw RunError(directory_gone(dir_.root(), step));
  }
  /// The message of check_directory (also for a write that failed while the directory was being
  /// deleted, before it was gone).
  static std::string directory_gone(const std::filesystem::path& root, std::int64_t step) {
    return "output: the run directory " + root.string() +
           " was deleted or moved while the run was writing it (noticed at step " +
           std::to_string(step) +
           "); the run stops here rather than write where nobody would find it. If it "
           "was moved, continue it where it is now with --resume NEWDIR; if it was "
           "deleted, there is no checkpoint left to --resume from: start the run again";
  }

  void row(const sim::Observables& o) {
    check_directory(o.step);
    // flushed row by row: a killed run loses nothing already computed
    if (std::fprintf(ts_, "%s\n", io::timeseries_row(o).c_str()) < 0 || std::fflush(ts_) != 0)
      throw RunError("output: cannot write " + dir_.timeseries().string() + ": " +
                     io::io_error_text(errno));
    if (rods_ &&
        (std::fprintf(rods_, "%s\n", io::rods_row(o).c_str()) < 0 || std::fflush(rods_) != 0))
      throw RunError("output: cannot write " + dir_.rods().string() + ": " +
                     io::io_error_text(errno));
    if (h5_) h5_->write_observables(o);
  }

  // u: the whole fluid velocity (Stepper::whole_velocity), read only with output.fluid_vti
  void frame(const sim::Simulation& sim, std::array<const double*, 3> u) {
    if (!frames_on_) return;
    check_directory(sim.step_count());
    const double t_us = sim.time() / 1e-6;
    h5_->write_frame(sim.step_count(), t_us, sim.rod());
    rod_pvd_.add(sim.step_count(), t_us, io::rod_vtp(sim.rod(), rod_ds_, ranges_));
    if (vti_) fluid_pvd_.add(sim.step_count(), t_us, io::fluid_vti(sim.params().stepper.grid, u));
  }

  std::int64_t frames() const { return h5_ ? h5_->frames() : 0; }

 private:
  io::RunDir dir_;
  std::vector<rod::RodRange> ranges_;
  std::vector<double> rod_ds_;  // each rod's Δs, Å
  bool vti_, frames_on_;
  dev_t dev_ = 0;  // the run directory's device and inode when the run opened it
  ino_t ino_ = 0;
  std::FILE* ts_ = nullptr;
  std::FILE* rods_ = nullptr;  // rods.csv (several rods)
  std::unique_ptr<io::H5mdWriter> h5_;
  io::PvdSeries rod_pvd_, fluid_pvd_;

  void reopen_trajectory(const std::filesystem::path& path, int n, double box_A, std::int64_t last,
                         const std::string& config_text, Progress& progress) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      h5_ = io::H5mdWriter::create(path, n, box_A, config_text);
      return;
    }
    try {
      h5_ = io::H5mdWriter::reopen(path, n, box_A, last, config_text);
    } catch (const RunError& e) {
      // a run killed in the middle of an HDF5 write can leave the file unreadable: keep it for
      // inspection and start a new one, rather than refuse to resume
      const std::filesystem::path aside = dir_.damaged_trajectory(last);
      std::filesystem::rename(path, aside, ec);
      progress.message(std::string("ibrod: warning: ") + e.what() + "; moved it to " +
                       aside.string() + "; trajectory.h5md restarts at step " +
                       std::to_string(last + 1));
      h5_ = io::H5mdWriter::create(path, n, box_A, config_text);
    }
  }
};

// ---------------------------------------------------------------------------------------------

}  // namespace ibrod::driver
