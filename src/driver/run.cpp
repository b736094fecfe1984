#include "driver/run.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"
#include "fluid/distributed_fluid.hpp"
#include "fluid/fftw_wisdom.hpp"
#include "io/atomic_file.hpp"
#include "io/checkpoint.hpp"
#include "io/h5md.hpp"
#include "driver/mpi_env.hpp"
#include "io/npy.hpp"
#include "driver/progress.hpp"
#include "sim/rod_problem.hpp"
#include "io/vtk.hpp"

namespace ibrod::driver {

using namespace ibrod::config;
using namespace ibrod::io;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

// ---------------------------------------------------------------------------------------------
// Signals: SIGINT/SIGTERM set a flag that the loop reads after each step. SA_RESETHAND: a second
// signal gets the default action (every file is consistent at any instant: atomic renames, rows
// flushed one by one). SIGXFSZ is ignored for the rest of the process, so that a file-size limit
// is a write error with a message, not a kill (HDF5 may still write while it shuts down).

volatile std::sig_atomic_t g_signal = 0;
void on_stop_signal(int s) { g_signal = s; }

class SignalGuard {
 public:
  explicit SignalGuard(bool stop_signals) : stop_(stop_signals) {
    g_signal = 0;
    struct sigaction sa {};
    sigemptyset(&sa.sa_mask);
    sa.sa_handler = SIG_IGN;
    sigaction(SIGXFSZ, &sa, nullptr);
    if (stop_) {
      sa.sa_handler = on_stop_signal;
      sa.sa_flags = SA_RESETHAND | SA_RESTART;
      sigaction(SIGINT, &sa, &old_int_);
      sigaction(SIGTERM, &sa, &old_term_);
    }
  }
  ~SignalGuard() {
    if (stop_) {
      sigaction(SIGINT, &old_int_, nullptr);
      sigaction(SIGTERM, &old_term_, nullptr);
    }
  }
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;
  int pending() const { return int(g_signal); }

 private:
  bool stop_;
  struct sigaction old_int_ {}, old_term_ {};
};

const char* signal_name(int s) {
  return s == SIGINT ? "SIGINT" : s == SIGTERM ? "SIGTERM" : "a signal";
}

// ---------------------------------------------------------------------------------------------
// Under MPI (opt.ranks > 1) rank 0 alone writes files. What it writes may fail (disk full, an
// output directory in the way) while the other ranks carry on into the next collective and wait
// forever: on_root runs f on rank 0 only and then every rank throws what rank 0 threw (the same
// type, ConfigError, RunError or std::runtime_error, and message), so that all ranks stop at the
// same point with the same exit status. One broadcast per call; without MPI it is f().

void on_root(const RunOptions& opt, const std::function<void()>& f) {
  if (opt.ranks <= 1) {
    f();
    return;
  }
  long long kind = 0;
  std::string what;
  if (opt.rank == 0) {
    try {
      f();
    } catch (const ConfigError& e) {
      kind = 2;
      what = e.what();
    } catch (const RunError& e) {
      kind = 3;
      what = e.what();
    } catch (const std::exception& e) {
      kind = 1;
      what = e.what();
    }
  }
  kind = mpi::broadcast(kind);
  if (kind == 0) return;
  what = mpi::broadcast(what);
  if (kind == 2) throw ConfigError(what);
  if (kind == 3) throw RunError(what);
  throw std::runtime_error(what);
}

// ---------------------------------------------------------------------------------------------
// Small helpers

std::string hms(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return buf;
}

std::string fmt_g(double v, int digits = 6) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string final_state_csv(const rod::RodState& s) {
  std::string out = "x_A,y_A,z_A,d1x,d1y,d1z,d2x,d2y,d2z,d3x,d3y,d3z\n";
  char buf[512];
  for (int k = 0; k < s.size(); ++k) {
    const Vec3& x = s.X[k];
    const Mat3& D = s.D[k];
    std::snprintf(buf, sizeof buf,
                  "%.12g,%.12g,%.12g,%.15g,%.15g,%.15g,%.15g,%.15g,%.15g,%.15g,%.15g,%.15g\n", x[0],
                  x[1], x[2], D(0, 0), D(1, 0), D(2, 0), D(0, 1), D(1, 1), D(2, 1), D(0, 2),
                  D(1, 2), D(2, 2));
    out += buf;
  }
  return out;
}

nlohmann::ordered_json observables_json(const sim::Observables& o) {
  nlohmann::ordered_json j;
  j["step"] = o.step;
  j["time_us"] = o.time_us;
  for (const auto& f : observable_fields()) j[f.name] = o.*f.member;  // NaN/Inf → null
  return j;
}

// The files a run writes besides config.toml, summary.json and final_state.csv.
const char* const kRunFiles[] = {"timeseries.csv", "trajectory.h5",   "rod.pvd",
                                 "fluid.pvd",      "checkpoint.bin",  "fftw.wisdom",
                                 "final_state.csv", "summary.json",   "config.toml",
                                 "velocity.npy"};

void prepare_output_dir(const fs::path& dir, bool overwrite) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec))
      throw ConfigError("output: '" + dir.string() + "' exists and is not a directory");
    if (!fs::is_empty(dir, ec) && !overwrite)
      throw ConfigError("output: directory '" + dir.string() +
                        "' already holds files; choose another -o DIR, pass --overwrite, or "
                        "continue a stopped run with --resume " + dir.string());
    if (overwrite) {
      // stale frames or a stale checkpoint of an earlier run must not mix with this one
      for (const char* f : kRunFiles) fs::remove(dir / f, ec);
      fs::remove_all(dir / "vtk", ec);
    }
  }
  fs::create_directories(dir, ec);
  if (ec) throw RunError("output: cannot create '" + dir.string() + "': " + ec.message());
}

// "key: old → new" for every key whose value differs ("" if none).
std::string config_differences(const std::string& old_toml, const Config& now,
                               const std::string& source) {
  Config old;
  try {
    apply_toml(old, old_toml, source);
  } catch (const ConfigError& e) {
    return std::string("the checkpoint's configuration cannot be read by this ibrod (") +
           e.what() + ")";
  }
  std::istringstream a(describe(old)), b(describe(now));
  std::string la, lb, out;
  auto strip = [](const std::string& l) { return l.substr(0, l.find(" #")); };
  while (std::getline(a, la) && std::getline(b, lb)) {
    la = strip(la);
    lb = strip(lb);
    while (!la.empty() && la.back() == ' ') la.pop_back();
    while (!lb.empty() && lb.back() == ' ') lb.pop_back();
    if (la == lb) continue;
    const auto eq = la.find(" = ");
    out += (out.empty() ? "" : "; ") + la.substr(0, eq) + ": " + la.substr(eq + 3) + " → " +
           lb.substr(lb.find(" = ") + 3);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Output files that grow during the run: timeseries.csv, trajectory.h5, rod.pvd (+ fluid.pvd).

class RunFiles {
 public:
  // resume_step < 0: a fresh run (create everything); otherwise continue the files, dropping
  // rows and frames after resume_step.
  RunFiles(const fs::path& dir, const Config& c, const sim::Simulation& sim,
           std::int64_t resume_step, const std::string& config_text, Progress& progress)
      : dir_(dir),
        ds_(c.rod_rise_A),
        vti_(c.output_fluid_vti),
        frames_on_(frame_every(c) > 0),
        rod_pvd_(dir, "rod", "vtp"),
        fluid_pvd_(dir, "fluid", "vti") {
    const fs::path ts = dir / "timeseries.csv";
    const int n = sim.rod().size();
    if (resume_step < 0) {
      write_file_atomic(ts, timeseries_header() + "\n");
      if (frames_on_)
        h5_ = H5mdWriter::create(dir / "trajectory.h5", n, c.grid_box_A, config_text);
    } else {
      truncate_timeseries(ts, resume_step);
      if (frames_on_) reopen_trajectory(dir / "trajectory.h5", n, c.grid_box_A, resume_step,
                                        config_text, progress);
      if (frames_on_) rod_pvd_.resume(resume_step);
      if (frames_on_ && vti_) fluid_pvd_.resume(resume_step);
    }
    ts_ = std::fopen(ts.c_str(), "a");
    if (!ts_) throw RunError("output: cannot open " + ts.string() + ": " + io_error_text(errno));
  }
  ~RunFiles() {
    if (ts_) std::fclose(ts_);
  }
  RunFiles(const RunFiles&) = delete;
  RunFiles& operator=(const RunFiles&) = delete;

  /// Throws RunError if the device of the output directory has less than `bytes` free: a full
  /// disk is better met before a write than in the middle of one (HDF5 cannot always recover a
  /// file whose write failed half-way).
  void ensure_space(std::uintmax_t bytes) const {
    std::error_code ec;
    const fs::space_info sp = fs::space(dir_, ec);
    if (!ec && sp.available < bytes)
      throw RunError("output: only " + std::to_string(sp.available >> 20) + " MiB left on the "
                     "device of " + dir_.string() + " (disk full?); stopped before writing, so "
                     "every file is intact: free space and continue with --resume " +
                     dir_.string());
  }

  void row(const sim::Observables& o) {
    // flushed row by row: a killed run loses nothing already computed
    if (std::fprintf(ts_, "%s\n", timeseries_row(o).c_str()) < 0 || std::fflush(ts_) != 0)
      throw RunError("output: cannot write " + (dir_ / "timeseries.csv").string() + ": " +
                     io_error_text(errno));
    if (h5_) h5_->write_observables(o);
  }

  // u: the whole fluid velocity (Stepper::whole_velocity), read only with output.fluid_vti
  void frame(const sim::Simulation& sim, std::array<const double*, 3> u) {
    if (!frames_on_) return;
    const double t_us = sim.time() / 1e-6;
    h5_->write_frame(sim.step_count(), t_us, sim.rod());
    rod_pvd_.add(sim.step_count(), t_us, rod_vtp(sim.rod(), ds_));
    if (vti_) fluid_pvd_.add(sim.step_count(), t_us, fluid_vti(sim.params().stepper.grid, u));
  }

  std::int64_t frames() const { return h5_ ? h5_->frames() : 0; }

 private:
  fs::path dir_;
  double ds_;
  bool vti_, frames_on_;
  std::FILE* ts_ = nullptr;
  std::unique_ptr<H5mdWriter> h5_;
  PvdSeries rod_pvd_, fluid_pvd_;

  // Keeps the header and the complete rows with step <= last (increasing), atomically.
  static void truncate_timeseries(const fs::path& ts, std::int64_t last) {
    const std::string text = slurp(ts);
    std::string out = timeseries_header() + "\n";
    std::size_t pos = text.find('\n');
    if (pos != std::string::npos && text.substr(0, pos) != timeseries_header())
      throw RunError("resume: " + ts.string() +
                     " has other columns than this ibrod writes; move it away to resume");
    std::int64_t prev = -1;
    while (pos != std::string::npos && pos + 1 < text.size()) {
      const std::size_t end = text.find('\n', pos + 1);
      if (end == std::string::npos) break;  // an incomplete last line (killed mid-write)
      const std::string line = text.substr(pos + 1, end - pos - 1);
      pos = end;
      char* stop = nullptr;
      const long long step = std::strtoll(line.c_str(), &stop, 10);
      if (stop == line.c_str() || *stop != ',' || step > last || step <= prev) continue;
      prev = step;
      out += line + "\n";
    }
    write_file_atomic(ts, out);
  }

  void reopen_trajectory(const fs::path& path, int n, double box_A, std::int64_t last,
                         const std::string& config_text, Progress& progress) {
    std::error_code ec;
    if (!fs::exists(path, ec)) {
      h5_ = H5mdWriter::create(path, n, box_A, config_text);
      return;
    }
    try {
      h5_ = H5mdWriter::reopen(path, n, last, config_text);
    } catch (const RunError& e) {
      // a run killed in the middle of an HDF5 write can leave the file unreadable: keep it for
      // inspection and start a new one, rather than refuse to resume
      const fs::path aside = dir_ / ("trajectory.damaged-" + std::to_string(last) + ".h5");
      fs::rename(path, aside, ec);
      progress.message(std::string("ibrod: warning: ") + e.what() + "; moved it to " +
                       aside.string() + "; trajectory.h5 restarts at step " +
                       std::to_string(last + 1));
      h5_ = H5mdWriter::create(path, n, box_A, config_text);
    }
  }
};

// ---------------------------------------------------------------------------------------------

std::string summary_json(const Config& c, const RunResult& r, const CheckpointMeta& meta,
                         std::int64_t frames, const std::string& stop_reason,
                         const std::string& error) {
  nlohmann::ordered_json j;
  j["steps"] = r.steps;
  j["time_us"] = r.time_us;
  j["stop_reason"] = stop_reason;
  j["excess_link"] = c.rod_excess_link;
  j["link_drift"] = r.final.link - r.initial.link;
  j["max_link_drift"] = meta.max_link_drift;
  j["self_passage_warning"] = meta.self_passage_warning;
  j["self_passage_step"] = meta.self_passage_step >= 0
                               ? nlohmann::ordered_json(meta.self_passage_step)
                               : nlohmann::ordered_json(nullptr);
  j["wall_time_s"] = r.wall_s;
  j["ms_per_step"] = r.ms_per_step;
  j["total_wall_time_s"] = meta.wall_s;
  j["threads"] = meta.threads;
  j["resumed_from_step"] =
      r.resumed_from >= 0 ? nlohmann::ordered_json(r.resumed_from) : nlohmann::ordered_json(nullptr);
  j["resumes"] = meta.resumes;
  j["checkpoint_step"] = r.checkpoint_step >= 0 ? nlohmann::ordered_json(r.checkpoint_step)
                                                : nlohmann::ordered_json(nullptr);
  j["frames"] = frames;
  j["error"] = error.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(error);
  j["initial"] = observables_json(r.initial);
  j["final"] = observables_json(r.final);
  return j.dump(2) + "\n";
}

}  // namespace

RunResult run(const Config& c_user, const RunOptions& opt) {
  validate(c_user);
  const auto t0 = Clock::now();
  const fs::path dir(opt.output_dir);
  const std::string config_text = to_toml(c_user);
  Config c = c_user;
  // under MPI: rank 0 alone prints and writes; every rank steps (see RunOptions::rank)
  const bool root = opt.rank == 0;
  const bool distributed = opt.ranks > 1;
  Progress progress(root ? opt.log : nullptr, opt.tty);
  auto say = [&](const std::string& s) { progress.message(s); };
  if (distributed && c.grid_n % opt.ranks != 0)
    throw ConfigError("run: grid.n = " + std::to_string(c.grid_n) + " cannot be split over " +
                      std::to_string(opt.ranks) + " MPI ranks: each rank holds grid.n/K x-planes "
                      "of the fluid, so the rank count K of `mpirun -np K` must divide grid.n");
  if (distributed && !fluid::distributed_available())
    throw ConfigError("run: this ibrod was built without FFTW MPI; run it without mpirun");

  if (!opt.fftw_wisdom.empty() && !fluid::import_wisdom(opt.fftw_wisdom))
    throw ConfigError("run: cannot read FFTW wisdom from '" + opt.fftw_wisdom + "'");

  // ---- the checkpoint to continue from, or a fresh output directory
  std::optional<Checkpoint> ck;
  bool config_changed = false;
  if (opt.resume) {
    const fs::path cp = dir / "checkpoint.bin";
    std::error_code ec;
    if (!fs::exists(cp, ec))
      throw ConfigError("resume: " + cp.string() +
                        " does not exist (the run stopped before its first checkpoint, or '" +
                        dir.string() + "' is not an ibrod output directory); start it again "
                        "with --overwrite");
    ck = read_checkpoint(cp);
    if (ck->grid_n != c.grid_n || ck->rod.size() != c.rod_base_pairs)
      throw ConfigError("resume: " + cp.string() + " holds a " + std::to_string(ck->grid_n) +
                        "³ grid and " + std::to_string(ck->rod.size()) +
                        " rod points; the configuration asks for grid.n = " +
                        std::to_string(c.grid_n) + " and rod.base_pairs = " +
                        std::to_string(c.rod_base_pairs) + ": incompatible, even with --force");
    const std::string diff = config_differences(ck->meta.config_toml, c_user, cp.string());
    config_changed = !diff.empty();
    if (config_changed && !opt.force)
      throw ConfigError("resume: the configuration differs from the one " + cp.string() +
                        " was written with (" + diff +
                        "); pass --force to continue with the new values (the continued run is "
                        "then not the uninterrupted run of either configuration)");
    if (config_changed) say("ibrod: warning: resuming with a changed configuration (--force): " + diff);
    if (ck->meta.stop_reason != "none" && !config_changed) {
      say("ibrod: the run in " + dir.string() + " already stopped (" + ck->meta.stop_reason +
          ") at step " + std::to_string(ck->meta.step) + "; nothing to do");
      RunResult r;
      r.already_finished = true;
      r.steps = ck->meta.step;
      r.initial = ck->meta.initial;
      r.resumed_from = r.checkpoint_step = ck->meta.step;
      r.reason = ck->meta.stop_reason == "equilibrium" ? sim::StopReason::equilibrium
                                                        : sim::StopReason::end_time;
      return r;
    }
    // the same threads as the run that wrote the checkpoint: the same round-off
    if (c.run_threads == 0) c.run_threads = ck->meta.threads;
    if (config_changed) on_root(opt, [&] { write_file_atomic(dir / "config.toml", config_text); });
  } else {
    on_root(opt, [&] {
      prepare_output_dir(dir, opt.overwrite);
      write_file_atomic(dir / "config.toml", config_text);
    });
  }

  SignalGuard signals(opt.handle_signals);

  // ---- FFTW plans: import the run's own wisdom on resume, so that FFTW_MEASURE picks the plans
  // of the first segment (different plans round differently)
  const fs::path wisdom = dir / "fftw.wisdom";
  if (ck && c.run_fftw_measure) {
    std::error_code ec;
    if (!fs::exists(wisdom, ec) || !fluid::import_wisdom(wisdom.string()))
      say("ibrod: warning: cannot read " + wisdom.string() +
          "; FFTW may choose other plans than before, so the continued run may differ from an "
          "uninterrupted one in the last bits");
  }
  sim::SimParams sp = to_params(c);
  sp.stepper.distributed = distributed;
  std::optional<sim::Simulation> sim_holder;
  try {
    sim_holder.emplace(sp);
  } catch (const std::invalid_argument& e) {
    if (!distributed) throw;
    // the distributed fluid checks what every rank sees alike: a bad input on every rank
    throw ConfigError(std::string("run: ") + e.what());
  }
  sim::Simulation& sim = *sim_holder;
  on_root(opt, [&] {  // distributed: rank 0 holds every rank's plans (fftw_mpi_gather_wisdom)
    const fs::path tmp = wisdom.string() + ".tmp";
    if (!fluid::export_wisdom(tmp.string()) || std::rename(tmp.c_str(), wisdom.c_str()) != 0) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw RunError("output: cannot write " + wisdom.string() + " (disk full?)");
    }
  });
  const auto& p = sim.params();
  const double dt = p.stepper.fluid.dt;
  const auto total_steps = std::int64_t(std::ceil(p.t_end / dt - 0.5));
  const int grid_n = p.stepper.grid.n;

  CheckpointMeta meta;
  RunResult r;
  if (ck) {
    meta = ck->meta;
    ++meta.resumes;
    sim.rod() = ck->rod;
    const std::size_t n3 = sp.stepper.grid.size();
    const double* v = ck->velocity.data();
    sim.stepper().set_whole_velocity({v, v + n3, v + 2 * n3});
    sim.restore_step_count(ck->meta.step);
    r.initial = meta.initial;
    r.resumed_from = r.checkpoint_step = meta.step;
    ck.reset();  // the state lives in sim now; free the copy
  }
  meta.config_toml = config_text;
  meta.threads = sim.stepper().fluid_threads();
  meta.stop_reason = "none";
  const double wall_before = meta.wall_s;

  std::unique_ptr<RunFiles> files;  // rank 0 only
  on_root(opt, [&] {
    files = std::make_unique<RunFiles>(dir, c, sim, r.resumed_from, config_text, progress);
  });
  // distributed: the whole velocity gathered on rank 0 for checkpoints, .vti frames, .npy
  std::vector<double> gathered;
  const bool frames_on = frame_every(c) > 0;
  auto write_frame = [&] {
    if (!frames_on) return;
    std::array<const double*, 3> u{};
    if (c.output_fluid_vti) u = sim.stepper().whole_velocity(gathered);
    on_root(opt, [&] { files->frame(sim, u); });
  };
  auto ensure_space = [&](std::uintmax_t bytes) {
    on_root(opt, [&] { files->ensure_space(bytes); });
  };
  const auto loop_start = Clock::now();
  const std::int64_t start_step = sim.step_count();
  auto seconds_since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  auto write_ckpt = [&](const std::string& stop_reason) {
    meta.step = sim.step_count();
    meta.stop_reason = stop_reason;
    meta.wall_s = wall_before + seconds_since(t0);
    const auto u = sim.stepper().whole_velocity(gathered);
    on_root(opt, [&] { write_checkpoint(dir / "checkpoint.bin", meta, sim.rod(), grid_n, u); });
    r.checkpoint_step = meta.step;
  };
  auto finish = [&](const sim::Observables& o, const std::string& stop_reason,
                    const std::string& error) {
    r.steps = sim.step_count();
    r.time_us = sim.time() / 1e-6;
    r.final = o;
    r.wall_s = seconds_since(t0);
    r.ms_per_step = 1e3 * seconds_since(loop_start) /
                    double(std::max<std::int64_t>(sim.step_count() - start_step, 1));
    r.link_drift = o.link - r.initial.link;
    r.max_link_drift = meta.max_link_drift;
    r.self_passage_warning = meta.self_passage_warning;
    const bool npy = error.empty() && stop_reason != "interrupted" && c.output_fluid_velocity;
    std::array<const double*, 3> u{};
    if (npy) u = sim.stepper().whole_velocity(gathered);
    on_root(opt, [&] {
      if (error.empty()) write_file_atomic(dir / "final_state.csv", final_state_csv(sim.rod()));
      if (npy) write_velocity_npy(dir / "velocity.npy", grid_n, u[0], u[1], u[2]);
      write_file_atomic(dir / "summary.json",
                        summary_json(c_user, r, meta, files->frames(), stop_reason, error));
    });
  };
  auto progress_line = [&](const sim::Observables& o) {
    const double ms = 1e3 * seconds_since(loop_start) /
                      double(std::max<std::int64_t>(sim.step_count() - start_step, 1));
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "step %lld/%lld  t = %.4f us  Wr = %+.4f  Lk = %+.4f  E_K = %.3e kT  "
                  "%.3f ms/step  ETA %s",
                  static_cast<long long>(sim.step_count()), static_cast<long long>(total_steps),
                  sim.time() / 1e-6, o.writhe, o.link, o.E_kinetic_kT, ms,
                  hms(1e-3 * ms * double(total_steps - sim.step_count())).c_str());
    return std::string(buf);
  };

  if (opt.log) {
    char buf[512];
    if (r.resumed_from >= 0)
      std::snprintf(buf, sizeof buf,
                    "ibrod: resuming %s at step %lld/%lld (%d threads, checkpoint every %lld "
                    "steps)",
                    dir.c_str(), static_cast<long long>(r.resumed_from),
                    static_cast<long long>(total_steps), meta.threads,
                    static_cast<long long>(c.output_checkpoint_every_steps));
    else
      std::snprintf(buf, sizeof buf,
                    "ibrod: %lld steps of %.4g ns on %d³, %d rod points, ΔLk = %d, %d threads -> %s",
                    static_cast<long long>(total_steps), dt / 1e-9, grid_n, p.stepper.rod.n,
                    p.circle.excess_link, meta.threads, dir.c_str());
    say(buf);
    if (distributed)
      say("ibrod: the fluid grid is split over " + std::to_string(opt.ranks) + " MPI ranks (" +
          std::to_string(grid_n / opt.ranks) + " x-planes each, " + std::to_string(meta.threads) +
          " threads per rank); rank 0 writes the output");
  }

  // ---- the blow-up guard: stop with a diagnosis, keep the last good checkpoint
  sim::Observables o;
  auto blow_up = [&](const std::string& what) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "run: blow-up at step %lld (t = %.6g µs): ",
                  static_cast<long long>(sim.step_count()), sim.time() / 1e-6);
    std::string msg = buf + what +
                      ". The time step is probably too large for the stretch/shear stiffness "
                      "(time.dt_ns = " + fmt_g(c.time_dt_ns) +
                      "): try a smaller time.dt_ns, or check the moduli and forces.";
    if (r.checkpoint_step >= 0)
      msg += " The last good checkpoint (step " + std::to_string(r.checkpoint_step) +
             ") is kept in " + (dir / "checkpoint.bin").string() + ".";
    try {
      finish(o, "blow_up", msg);
    } catch (const RunError&) {
      // the blow-up is the error to report
    }
    throw RunError(msg);
  };
  auto observe_checked = [&]() {
    sim::Observables ob = sim.observe();
    // E_total includes E_K = ½ρΣ|u|²h³, so a NaN/Inf anywhere in the fluid shows here (the rod
    // itself is checked after every step by rod_problem)
    if (!std::isfinite(ob.E_total_kT))
      blow_up("the fluid velocity or an energy is not finite (E_total = " +
              fmt_g(ob.E_total_kT) + " kT, E_K = " + fmt_g(ob.E_kinetic_kT) + " kT)");
    return ob;
  };
  auto check_link = [&](const sim::Observables& ob) {
    const double drift = std::abs(ob.link - r.initial.link);
    meta.max_link_drift = std::max(meta.max_link_drift, drift);
    if (drift > kLinkDriftWarning && !meta.self_passage_warning) {
      meta.self_passage_warning = true;
      meta.self_passage_step = ob.step;
      char buf[320];
      std::snprintf(buf, sizeof buf,
                    "ibrod: warning: at step %lld the linking number Lk = %.4f drifted by %.3g from "
                    "its initial %.4f (more than %.1f): the rod has probably passed through "
                    "itself (steric.stiffness or steric.diameter_A too small, or Δt too large); "
                    "recorded in summary.json",
                    static_cast<long long>(ob.step), ob.link, ob.link - r.initial.link,
                    r.initial.link, kLinkDriftWarning);
      say(buf);
    }
  };

  // free space kept in hand: a checkpoint (written beside the previous one), a few frames
  // (H5MD + .vtp, ~300 B per point, + the .vti) and 16 MiB of slack
  const std::uintmax_t reserve_bytes =
      std::uintmax_t(24) * std::uintmax_t(grid_n) * grid_n * grid_n +
      std::uintmax_t(4) * (300u * std::uintmax_t(p.stepper.rod.n) +
                           (c.output_fluid_vti ? 48u * std::uintmax_t(grid_n) * grid_n * grid_n
                                               : 0u)) +
      (std::uintmax_t(16) << 20);
  const std::int64_t every = c.output_every_steps;
  const std::int64_t fevery = frame_every(c);
  const std::int64_t cevery = c.output_checkpoint_every_steps;
  try {
    ensure_space(reserve_bytes);
    if (r.resumed_from < 0) {
      if (const std::string bad = sim::rod_problem(sim.rod(), c.rod_rise_A); !bad.empty())
        blow_up("the initial state is not sane: " + bad);
      o = observe_checked();
      r.initial = meta.initial = o;
      on_root(opt, [&] { files->row(o); });
      write_frame();
      write_ckpt("none");
    } else {
      o = sim.observe();
    }

    sim::StopReason reason = sim::StopReason::none;
    for (;;) {
      // distributed: the ranks agree on a signal (each may see it after another step)
      if (const int sig = distributed ? int(mpi::max(signals.pending())) : signals.pending()) {
        // the end of the current step: save it, then stop
        if (r.checkpoint_step != sim.step_count()) write_ckpt("none");
        progress.finish_line();
        r.signal = sig;
        finish(o, "interrupted", "");
        char buf[256];
        std::snprintf(buf, sizeof buf, "ibrod: interrupted by %s at step %lld (t = %.4f us)",
                      signal_name(sig), static_cast<long long>(sim.step_count()),
                      sim.time() / 1e-6);
        say(buf);
        return r;
      }
      sim.step();
      if (const std::string bad = sim::rod_problem(sim.rod(), c.rod_rise_A); !bad.empty()) blow_up(bad);
      const std::int64_t step = sim.step_count();
      const bool at_end = step >= total_steps;
      const bool output_step = step % every == 0 || at_end;
      if (output_step) {
        o = observe_checked();
        on_root(opt, [&] { files->row(o); });
        check_link(o);
        reason = sim.stop_reason(o);
        if (at_end && reason == sim::StopReason::none) reason = sim::StopReason::end_time;
      }
      const bool stop = reason != sim::StopReason::none;
      const bool frame_step = fevery > 0 && (step % fevery == 0 || stop);
      const bool ckpt_step = (cevery > 0 && step % cevery == 0) || stop;
      if (frame_step) write_frame();
      if (ckpt_step) write_ckpt(stop ? sim::to_string(reason) : "none");
      // before the next step's writes: room for a new checkpoint beside the old one, frames
      if (!stop && (output_step || frame_step || ckpt_step)) ensure_space(reserve_bytes);
      const double now = seconds_since(loop_start);
      if (stop) {
        progress.update(progress_line(o), now, /*last=*/true);
        break;
      }
      // the first line at the first output step or after one interval, whichever comes first,
      // then by the clock (with the latest row: ms/step and ETA are current, the observables are
      // those of the last output step)
      if ((output_step && !progress.started()) || progress.due(now))
        progress.update(progress_line(o), now);
    }
    r.reason = reason;
    finish(o, sim::to_string(reason), "");
  } catch (const RunError& e) {
    // leave a summary that says why the run stopped, if the disk still takes one
    const std::string what = e.what();
    if (what.rfind("run: blow-up", 0) != 0) {
      try {
        finish(o, "error", what);
      } catch (const RunError&) {
      }
    }
    progress.finish_line();
    throw;
  }

  char buf[512];
  std::snprintf(buf, sizeof buf,
                "ibrod: stopped (%s) after %lld steps, t = %.4f us, Wr = %.4f, Tw = %.4f, "
                "Lk = %.4f; %.1f s wall, %.3f ms/step",
                sim::to_string(r.reason).c_str(), static_cast<long long>(r.steps), r.time_us,
                o.writhe, o.twist, o.link, r.wall_s, r.ms_per_step);
  say(buf);
  return r;
}

}  // namespace ibrod::driver
