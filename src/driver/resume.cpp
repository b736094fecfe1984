// What continues a run from its checkpoint (driver::Run, `--resume`): the checks that the
// checkpoint fits the configuration, the state put back into the Simulation, and a run that
// stopped but lost its final files.
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "core/text_file.hpp"
#include "driver/run_state.hpp"

namespace ibrod::driver {

namespace fs = std::filesystem;

// Whether every final file of a run that stopped for `stop_reason` is there: summary.json with
// that stop_reason, final_state.csv, velocity.npy if asked for.
bool Run::State::final_files_complete(const std::string& stop_reason) const {
  const auto summary = try_read_text_file(dir.summary());
  if (!summary || summary->find("\"stop_reason\": \"" + stop_reason + "\"") == std::string::npos)
    return false;
  std::error_code ec;
  if (!fs::exists(dir.final_state(), ec)) return false;
  if (c.output_fluid_velocity && !fs::exists(dir.velocity(), ec)) return false;
  return true;
}

// --resume: the checkpoint must fit the configuration (the grid and the rod exactly; any other
// key only with --force). A run that already stopped and is resumed unchanged has nothing to do.
void Run::State::open_checkpoint() {
  const fs::path cp = dir.checkpoint();
  std::error_code ec;
  // one writer: the lock before the checkpoint is read (a run still writing it is refused)
  if (fs::is_directory(dir.root(), ec)) on_root([&] { lock.emplace(dir.root()); });
  if (!fs::exists(cp, ec))
    throw ConfigError("resume: " + cp.string() +
                      " does not exist (the run stopped before its first checkpoint, or '" +
                      dir.root().string() +
                      "' is not an ibrod output directory); start it again "
                      "with --overwrite");
  checkpoint = io::read_checkpoint(cp);
  const io::Checkpoint& ck = *checkpoint;
  if (ck.grid_n != c.grid_n || ck.rod.size() != config::point_count(c))
    throw ConfigError(
        "resume: " + cp.string() + " holds a " + std::to_string(ck.grid_n) + "³ grid and " +
        std::to_string(ck.rod.size()) + " rod points; the configuration asks for grid.n = " +
        std::to_string(c.grid_n) + " and " + std::to_string(config::point_count(c)) +
        " rod points (rod.base_pairs, [[rods]])" + ": incompatible, even with --force");
  {
    // a closed ring and an open rod are different structures: never continued into each other
    config::Config old;
    bool read = true;
    try {
      config::apply_toml(old, ck.meta.config_toml, cp.string());
    } catch (const ConfigError&) {
      read = false;  // reported below by config_differences
    }
    // the same rods, each of the same size and kind
    if (const std::string why = read ? config::rods_incompatibility(old, c) : ""; !why.empty())
      throw ConfigError("resume: " + cp.string() + " holds " + why +
                        ": incompatible, even with --force");
  }
  // the run's own checkpoint: its id is config.toml's (a checkpoint copied in from another run
  // directory would continue that run's state under this one's files)
  const RunStamp ck_stamp = read_stamp(ck.meta.config_toml);
  const RunStamp dir_stamp = read_stamp(try_read_text_file(dir.config()).value_or(""));
  if (!ck_stamp.run_id.empty() && !dir_stamp.run_id.empty() && ck_stamp.run_id != dir_stamp.run_id)
    throw ConfigError("resume: " + cp.string() + " belongs to another run (run id " +
                      ck_stamp.run_id + ") than " + dir.config().string() + " (run id " +
                      dir_stamp.run_id +
                      "): a checkpoint copied from another run directory is not continued, even "
                      "with --force; put this run's own checkpoint back, or start the run again "
                      "with --overwrite");
  stamp.run_id = !dir_stamp.run_id.empty()  ? dir_stamp.run_id
                 : !ck_stamp.run_id.empty() ? ck_stamp.run_id
                                            : new_run_id();
  restamp();
  // an input file whose content changed is a changed key (rod.moduli_file, rod.intrinsic_file)
  const std::string inputs_diff = input_differences(ck_stamp, stamp);
  std::string diff = config::config_differences(ck.meta.config_toml, user, cp.string());
  if (!inputs_diff.empty()) diff += (diff.empty() ? "" : "; ") + inputs_diff;
  config_changed = !diff.empty();
  // a later t_end alone extends the run: the continuation is the uninterrupted longer run
  extension = config_changed && inputs_diff.empty() &&
              config::only_end_time_extended(ck.meta.config_toml, user, cp.string());
  if (extension) say("ibrod: extending the run in " + dir.root().string() + " (" + diff + ")");
  extended_from_end = extension && ck.meta.stop_reason == to_string(StopReason::end_time);
  if (config_changed && !opt.force && !extension)
    throw ConfigError("resume: the configuration differs from the one " + cp.string() +
                      " was written with (" + diff +
                      "); pass --force to continue with the new values (the continued run is "
                      "then not the uninterrupted run of either configuration)");
  if (config_changed && !extension)
    say("ibrod: warning: resuming with a changed configuration (--force): " + diff);
  // the time is state: a run never goes back (a shorter t_end than the checkpoint's time is an
  // error, not a run that stops "at step 60/50")
  const double dt = c.time_dt_ns * 1e-9, t_end = c.time_t_end_us * 1e-6;
  const double time_ck = ck.meta.time_s >= 0 ? ck.meta.time_s : double(ck.meta.step) * dt;
  if (t_end < time_ck - 0.5 * dt) {
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "resume: time.t_end_us = %.6g is before the time of the checkpoint %s "
                  "(%.6g us, step %lld): a run cannot go back; give a later time.t_end_us",
                  c.time_t_end_us, cp.c_str(), time_ck / 1e-6,
                  static_cast<long long>(ck.meta.step));
    throw ConfigError(buf);
  }
  if (ck.meta.stop_reason != "none" && !config_changed &&
      !final_files_complete(ck.meta.stop_reason)) {
    // killed after its final checkpoint, before its final files: write them now
    say("ibrod: the run in " + dir.root().string() + " stopped (" + ck.meta.stop_reason +
        ") at step " + std::to_string(ck.meta.step) +
        " but its final files are incomplete; "
        "writing them");
    complete_only = true;
    stopped_reason = sim::stop_reason_from(ck.meta.stop_reason);
  } else if (ck.meta.stop_reason != "none" && !config_changed) {
    say("ibrod: the run in " + dir.root().string() + " already stopped (" + ck.meta.stop_reason +
        ") at step " + std::to_string(ck.meta.step) + "; nothing to do");
    result.already_finished = true;
    result.steps = ck.meta.step;
    result.initial = ck.meta.initial;
    result.resumed_from = result.checkpoint_step = ck.meta.step;
    result.reason = sim::stop_reason_from(ck.meta.stop_reason);
    throw AlreadyFinished{};
  }
  // the same threads as the run that wrote the checkpoint: the same round-off
  if (c.run_threads == 0) c.run_threads = ck.meta.threads;
}

void Run::State::restore_state() {
  if (checkpoint) {
    meta = checkpoint->meta;
    ++meta.resumes;
    // the checkpoint's Snapshot: rod, fluid velocity, clock, implicit controller
    sim->restore(io::snapshot_of(std::move(*checkpoint), sim->dt()));
    result.initial = meta.initial;
    result.resumed_from = result.checkpoint_step = meta.step;
    checkpoint.reset();  // the state lives in sim now; free the copy
  }
  meta.config_toml = config_text;
  meta.threads = sim->system().fluid_threads();
  meta.stop_reason = to_string(StopReason::none);
  wall_before = meta.wall_s;
}

RunResult Run::State::complete() {
  loop_start = Clock::now();
  start_step = sim->step_count();
  last_row = sim->observe();
  result.reason = stopped_reason;
  meta.stop_reason = to_string(stopped_reason);
  finish(last_row, to_string(stopped_reason), "");
  return result;
}

}  // namespace ibrod::driver
