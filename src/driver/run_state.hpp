#pragma once
// driver::Run's state between its steps (driver-internal: run.cpp has the loop, resume.cpp what
// continues a run from its checkpoint).
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "driver/dir_lock.hpp"
#include "driver/mpi_env.hpp"
#include "driver/progress.hpp"
#include "driver/run.hpp"
#include "driver/run_files.hpp"
#include "driver/run_stamp.hpp"
#include "driver/signals.hpp"
#include "io/checkpoint.hpp"
#include "io/run_dir.hpp"
#include "sim/simulation.hpp"

namespace ibrod::driver {

using Clock = std::chrono::steady_clock;
using sim::StopReason;

inline double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

/// A run that has already stopped, resumed without a change: nothing to do.
struct AlreadyFinished {};

// Everything one run holds between its steps. Under MPI (ranks > 1) rank 0 alone writes (files
// is null elsewhere); every write goes through on_root so that a failure there stops every rank.
struct Run::State {
  config::Config user;  // as given (config.toml is written from it)
  config::Config c;     // as run (threads resolved on resume)
  RunOptions opt;
  io::RunDir dir;
  std::string config_text;  // config.toml: to_toml(user) and the stamp (restamp())
  RunStamp stamp;           // the run's id and its input files' checksums
  Clock::time_point t0 = Clock::now();
  bool distributed = false;
  Progress progress;
  std::optional<DirLock> lock;  // rank 0: held while the run writes dir

  std::optional<io::Checkpoint> checkpoint;  // the one to continue from, until it is applied
  bool config_changed = false;
  bool extension = false;          // --resume with a later time.t_end_us alone
  bool extended_from_end = false;  // ... of a run that had stopped at its end time
  // a run that stopped but was killed before its final files were all written: --resume only
  // writes them (the reason it stopped, from the checkpoint)
  bool complete_only = false;
  StopReason stopped_reason = StopReason::none;
  std::optional<sim::Simulation> sim;
  std::unique_ptr<RunFiles> files;  // rank 0 only
  std::vector<double> gathered;     // distributed: the whole velocity on rank 0
  io::CheckpointMeta meta;
  RunResult result;
  double wall_before = 0;  // wall time of the earlier segments, s
  Clock::time_point loop_start;
  std::int64_t start_step = 0;
  std::uintmax_t reserve_bytes = 0;
  sim::Observables last_row;                             // the row of the latest output step
  std::vector<std::optional<rod::RodState>> rod_shapes;  // each rod's rod.initial_shape, or none
  bool begun = false;                  // the first segment's step 0 (or the resumed row) is done
  std::vector<sim::Observables> rows;  // opt.keep_rows

  State(const config::Config& cfg, const RunOptions& o)
      : user(cfg),
        c(cfg),
        opt(o),
        dir(o.output_dir),
        config_text(config::to_toml(cfg)),
        distributed(o.ranks > 1),
        progress(o.rank == 0 ? o.log : nullptr, o.tty) {}

  void say(const std::string& s) { progress.message(s); }
  /// config_text from user and stamp (after either changes)
  void restamp() { config_text = config::to_toml(user) + stamp_text(stamp); }
  void on_root(const std::function<void()>& f) { mpi::on_root(opt.rank, opt.ranks, f); }
  /// Whether the run writes its directory (RunOptions::write_files).
  bool writes() const { return opt.write_files; }
  /// f on rank 0 when the run writes files, else nothing.
  void on_disk(const std::function<void()>& f) {
    if (writes()) on_root(f);
  }
  void record_row() {
    on_disk([&] { files->row(last_row); });
    if (opt.keep_rows) rows.push_back(last_row);
  }

  void check_launch() const;
  void open_checkpoint();
  void prepare_directory();
  void build_simulation();
  void restore_state();
  void open_files();
  void announce();

  double ms_per_step() const {
    return 1e3 * seconds_since(loop_start) /
           double(std::max<std::int64_t>(sim->step_count() - start_step, 1));
  }
  std::string progress_line(const sim::Observables& o) const;
  void write_frame();
  void ensure_space() {
    on_disk([&] { files->ensure_space(reserve_bytes, result.checkpoint_step >= 0); });
  }
  void write_checkpoint(StopReason reason);
  void finish(const sim::Observables& o, const std::string& stop_reason, const std::string& error);
  [[noreturn]] void blow_up(const std::string& what);
  sim::Observables observe_checked();
  void check_link(const sim::Observables& o);
  StopReason test_stability(StopReason candidate);
  bool final_files_complete(const std::string& stop_reason) const;
  RunResult complete();
  RunResult loop(const std::function<int()>& pending, std::int64_t max_steps);
};

}  // namespace ibrod::driver
