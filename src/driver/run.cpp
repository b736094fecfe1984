#include "driver/run.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <vector>

#include <omp.h>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "driver/run_state.hpp"
#include "fluid/distributed_fluid.hpp"
#include "fluid/fftw_wisdom.hpp"
#include "io/atomic_file.hpp"
#include "io/csv.hpp"
#include "io/npy.hpp"
#include "io/rod_shape.hpp"
#include "rod/rod_set.hpp"
#include "sim/rod_problem.hpp"
#include "sim/stability.hpp"

namespace ibrod::driver {

namespace fs = std::filesystem;

namespace {

/// "H:MM:SS" of a duration in seconds ("?" if unknown).
std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return buf;
}

std::string format_g(double v, int digits = 6) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

}  // namespace

void Run::State::check_launch() const {
  if (distributed && c.grid_n % opt.ranks != 0)
    throw ConfigError("run: grid.n = " + std::to_string(c.grid_n) + " cannot be split over " +
                      std::to_string(opt.ranks) +
                      " MPI ranks: each rank holds grid.n/K x-planes "
                      "of the fluid, so the rank count K of `mpirun -np K` must divide grid.n");
  if (distributed && !fluid::distributed_available())
    throw ConfigError("run: this ibrod was built without FFTW MPI; run it without mpirun");
  if (!opt.fftw_wisdom.empty() && !fluid::import_wisdom(opt.fftw_wisdom))
    throw ConfigError("run: cannot read FFTW wisdom from '" + opt.fftw_wisdom + "'");
}

void Run::State::prepare_directory() {
  if (checkpoint) {
    if (config_changed) on_root([&] { io::write_file_atomic(dir.config(), config_text); });
    return;
  }
  on_disk([&] {
    prepare_output_dir(dir, opt.overwrite, lock);
    io::write_file_atomic(dir.config(), config_text);
  });
}

void Run::State::build_simulation() {
  // FFTW plans: import the run's own wisdom on resume, so that FFTW_MEASURE picks the plans of
  // the first segment (different plans round differently)
  if (checkpoint && c.run_fftw_measure) {
    std::error_code ec;
    if (!fs::exists(dir.wisdom(), ec) || !fluid::import_wisdom(dir.wisdom().string()))
      say("ibrod: warning: cannot read " + dir.wisdom().string() +
          "; FFTW may choose other plans than before, so the continued run may differ from an "
          "uninterrupted one in the last bits");
  }
  sim::SimParams params = config::to_params(c);
  params.stepper.distributed = distributed;
  try {
    sim.emplace(params);
  } catch (const std::invalid_argument& e) {
    if (!distributed) throw;
    // the distributed fluid checks what every rank sees alike: a bad input on every rank
    throw ConfigError(std::string("run: ") + e.what());
  }
  const bool any_shape =
      std::any_of(rod_shapes.begin(), rod_shapes.end(), [](const auto& r) { return bool(r); });
  if (any_shape && !checkpoint) {
    // each rod with rod.initial_shape takes its shape from its file (checked in Run::Run), in its
    // range
    rod::RodState whole = sim->rod();
    for (std::size_t r = 0; r < rod_shapes.size(); ++r) {
      if (!rod_shapes[r]) continue;
      const rod::RodRange& g = sim->rod_ranges()[r];
      for (int k = 0; k < g.n; ++k) {
        whole.X[g.offset + k] = rod_shapes[r]->X[k];
        whole.D[g.offset + k] = rod_shapes[r]->D[k];
      }
    }
    sim->set_rod_state(std::move(whole), "rod.initial_shape");
    rod_shapes.clear();
  }
  if (!checkpoint)
    if (const std::string bad = sim->start_problem(); !bad.empty())
      throw ConfigError("the initial state: " + bad);
  // distributed: rank 0 holds every rank's plans (fftw_mpi_gather_wisdom)
  on_disk([&] {
    const std::string wisdom = fluid::wisdom_text();
    if (wisdom.empty()) throw RunError("output: cannot export the FFTW plans");
    io::write_file_atomic(dir.wisdom(), wisdom);
  });
}

void Run::State::open_files() {
  // extending an implicit run: its last step was shortened to land on the old t_end, which the
  // longer run steps over unless the old t_end is a multiple of an interval in simulated time
  // (where the longer run lands too; docs/large_dt.md)
  if (extension && extended_from_end && sim->implicit()) {
    const sim::OutputSchedule& out = sim->params().output;
    bool lands = false;
    for (double every : {out.rows_every, out.frames_every, out.checkpoints_every})
      if (every > 0) {
        const double k = std::round(sim->time() / every);
        lands = lands || std::abs(sim->time() - k * every) <= 1e-9 * every;
      }
    if (!lands)
      say("ibrod: warning: this extension of an implicit run is not bit for bit the uninterrupted "
          "longer run: the run's last step was shortened to land on its old end time, " +
          format_g(sim->time() / 1e-6) +
          " us, which is no multiple of an output interval in simulated time (the longer run "
          "steps over it); it agrees to the scheme's accuracy. For bitwise extensions schedule "
          "the rows in simulated time (output.every_us) and end on their multiples "
          "(docs/large_dt.md)");
  }
  on_disk([&] {
    // extending a run that stopped at its end time: its last row and frame were written because
    // it stopped, not by the schedule; the uninterrupted longer run has them only if on schedule
    std::int64_t rows_to = result.resumed_from, frames_to = result.resumed_from;
    if (extension && result.resumed_from > 0) {
      if (!sim->row_on_schedule()) --rows_to;
      const sim::OutputSchedule& out = sim->params().output;
      if ((out.frames > 0 || out.frames_every > 0) && !sim->frame_on_schedule()) --frames_to;
    }
    files = std::make_unique<RunFiles>(dir, c, *sim, rows_to, config_text, progress, frames_to);
  });
  // free space kept in hand: a checkpoint (written beside the previous one), a few frames
  // (H5MD + .vtp, ~300 B per point, + the .vti) and 16 MiB of slack
  const std::uintmax_t n = std::uintmax_t(c.grid_n);
  reserve_bytes = 24 * n * n * n +
                  4 * (300u * std::uintmax_t(config::point_count(c)) +
                       (c.output_fluid_vti ? 48u * n * n * n : 0u)) +
                  (std::uintmax_t(16) << 20);
}

void Run::State::announce() {
  if (!opt.log) return;
  char buf[512];
  const auto& p = sim->params();
  if (result.resumed_from >= 0)
    std::snprintf(buf, sizeof buf,
                  "ibrod: resuming %s at step %lld/%lld (%d threads, checkpoint every %lld steps)",
                  dir.root().c_str(), static_cast<long long>(result.resumed_from),
                  static_cast<long long>(sim->end_step()), meta.threads,
                  static_cast<long long>(p.output.checkpoints));
  else {
    int excess_link = 0;  // the rods' together
    for (const sim::SimParams::Shape& shape : p.shapes) excess_link += shape.circle.excess_link;
    std::snprintf(
        buf, sizeof buf, "ibrod: %lld steps of %.4g ns on %d³, %s, ΔLk = %d, %d threads -> %s",
        static_cast<long long>(sim->end_step()), sim->dt() / 1e-9, p.stepper.grid.n,
        rod::describe(sim->rod_ranges()).c_str(), excess_link, meta.threads, dir.root().c_str());
  }
  say(buf);
  if (distributed)
    say("ibrod: the fluid grid is split over " + std::to_string(opt.ranks) + " MPI ranks (" +
        std::to_string(p.stepper.grid.n / opt.ranks) + " x-planes each, " +
        std::to_string(meta.threads) + " threads per rank); rank 0 writes the output");
}

std::string Run::State::progress_line(const sim::Observables& o) const {
  const double ms = ms_per_step();
  const std::int64_t end = sim->end_step();
  char buf[320];
  if (sim->link_defined())
    std::snprintf(buf, sizeof buf,
                  "step %lld/%lld  t = %.4f us  Wr = %+.4f  Lk = %+.4f  E_K = %.3e kT  "
                  "%.3f ms/step  ETA %s",
                  static_cast<long long>(sim->step_count()), static_cast<long long>(end),
                  sim->time() / 1e-6, o.writhe, o.link, o.E_kinetic_kT, ms,
                  format_duration(1e-3 * ms * double(end - sim->step_count())).c_str());
  else  // an open rod: no writhe or link (docs/model.md "Open rods")
    std::snprintf(buf, sizeof buf,
                  "step %lld/%lld  t = %.4f us  Tw = %+.4f  E_el = %.4g kT  E_K = %.3e kT  "
                  "%.3f ms/step  ETA %s",
                  static_cast<long long>(sim->step_count()), static_cast<long long>(end),
                  sim->time() / 1e-6, o.twist, o.E_bend_kT + o.E_twist_kT + o.E_stretch_kT,
                  o.E_kinetic_kT, ms,
                  format_duration(1e-3 * ms * double(end - sim->step_count())).c_str());
  if (sim->step_count() == start_step) {
    // before the first step of this process: the state's values, no timing yet
    std::string line(buf);
    return line.substr(0, line.find("kT  ") + 2) + "  (starting)";
  }
  return buf;
}

void Run::State::write_frame() {
  if (sim->params().output.frames <= 0 || !writes()) return;
  std::array<const double*, 3> u{};
  if (c.output_fluid_vti) u = sim->system().whole_velocity(gathered);
  on_root([&] { files->frame(*sim, u); });
}

void Run::State::write_checkpoint(StopReason reason) {
  // the state a resume puts back (Simulation::snapshot; the velocity only if it is written:
  // collective, gathered to rank 0 under MPI)
  const sim::Snapshot state = sim->snapshot(writes());
  io::record_state(meta, state);
  sim->checkpoint_taken();  // the resumed run starts the same way (bitwise resume)
  meta.stop_reason = to_string(reason);
  meta.wall_s = wall_before + seconds_since(t0);
  result.checkpoint_step = meta.step;
  if (!writes()) return;
  on_root([&] {
    files->check_directory(meta.step);
    io::write_checkpoint(dir.checkpoint(), meta, state, sim->params().stepper.grid.n);
  });
}

void Run::State::finish(const sim::Observables& o, const std::string& stop_reason,
                        const std::string& error) {
  RunResult& r = result;
  r.steps = sim->step_count();
  r.time_us = sim->time() / 1e-6;
  r.final = o;
  r.wall_s = seconds_since(t0);
  r.ms_per_step = ms_per_step();
  if (const integrate::ImplicitIntegrator* imp = sim->implicit()) {
    r.implicit_factorizations = imp->stepper().timings().factorizations;
    r.implicit_early_refreshes = imp->stepper().timings().moved_refreshes;
    r.implicit_stokes_solves = imp->stepper().timings().stokes_solves;
  }
  r.link_drift = o.link - r.initial.link;
  r.max_link_drift = meta.max_link_drift;
  r.self_passage_warning = meta.self_passage_warning;
  const bool npy = writes() && error.empty() && stop_reason != to_string(StopReason::interrupted) &&
                   c.output_fluid_velocity;
  std::array<const double*, 3> u{};
  if (npy) u = sim->system().whole_velocity(gathered);
  on_disk([&] {
    files->check_directory(r.steps);
    if (error.empty())
      io::write_file_atomic(dir.final_state(), io::final_state_csv(sim->rod(), sim->rod_ranges()));
    if (npy) io::write_velocity_npy(dir.velocity(), c.grid_n, u[0], u[1], u[2]);
    io::write_file_atomic(dir.summary(), summary_json(user, sim->link_defined(), r, meta,
                                                      files->frames(), stop_reason, error));
  });
}

// The blow-up guard: stop with a diagnosis, keep the last good checkpoint.
void Run::State::blow_up(const std::string& what) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "run: blow-up at step %lld (t = %.6g µs): ",
                static_cast<long long>(sim->step_count()), sim->time() / 1e-6);
  std::string msg = buf + what +
                    ". The time step is probably too large for the stretch/shear stiffness "
                    "(time.dt_ns = " +
                    format_g(c.time_dt_ns) +
                    "): try a smaller time.dt_ns, or check the moduli and forces.";
  if (result.checkpoint_step >= 0 && writes())
    msg += " The last good checkpoint (step " + std::to_string(result.checkpoint_step) +
           ") is kept in " + dir.checkpoint().string() + ".";
  try {
    finish(last_row, to_string(StopReason::blow_up), msg);
  } catch (const RunError&) {
    // the blow-up is the error to report
  }
  throw RunError(msg);
}

sim::Observables Run::State::observe_checked() {
  sim::Observables o = sim->observe();
  // E_total includes E_K = ½ρΣ|u|²h³, so a NaN/Inf anywhere in the fluid shows here (the rod
  // itself is checked after every step by rod_problem)
  if (!std::isfinite(o.E_total_kT))
    blow_up("the fluid velocity or an energy is not finite (E_total = " + format_g(o.E_total_kT) +
            " kT, E_K = " + format_g(o.E_kinetic_kT) + " kT)");
  return o;
}

// The kinetic-energy rule fired: test the state before calling it an equilibrium
// (sim/stability.hpp). Unstable: the run goes on from the probe's end, with a row there.
StopReason Run::State::test_stability(StopReason candidate) {
  sim::Simulation& s = *sim;
  const sim::StabilityProbe& probe = s.params().stability;
  if (!probe.enabled || distributed) return candidate;
  nlohmann::json tests = nlohmann::json::parse(meta.stability_tests_json);
  if (probe.method == sim::StabilityProbe::Method::hessian) {
    // The Hessian test takes no simulated time, and after an unstable verdict a slow unstable
    // mode (the ΔLk = 2 circle: tens of µs) keeps the rule firing at every output step while the
    // state has barely moved. So after k unstable verdicts in a row the next test waits until
    // 2^(k−1) time.stability_probe_us have passed since the last (read from the tests listed,
    // which the checkpoint keeps: a resumed run tests at the same steps).
    int k = 0;
    double last_us = 0;
    for (auto it = tests.rbegin(); it != tests.rend() && !(*it).value("stable", true); ++it)
      if (k++ == 0) last_us = (*it).value("time_us", 0.0);
    if (k > 0 && s.time() / 1e-6 < last_us + std::ldexp(probe.time / 1e-6, k - 1))
      return s.at_end() ? StopReason::end_time : StopReason::none;
  }
  const sim::ProbeOutcome o = sim::probe_stability(s, probe, tests.size());
  tests.push_back({{"step", o.step},
                   {"time_us", o.time_us},
                   {"probe_steps", o.steps},
                   {"continuation_steps", o.continuation_steps},
                   {"probe_time_us", o.duration_us},
                   {"kick_A", probe.kick},
                   {"amplitude_rad", probe.amplitude},
                   {"seed", probe.seed + tests.size()},
                   {"tolerance_kT", probe.tolerance / s.params().kT},
                   {"E_total_before_kT", o.E_before_kT},
                   {"E_total_continuation_kT", o.E_continuation_kT},
                   {"E_total_after_kT", o.E_after_kT},
                   {"E_difference_min_kT", o.min_difference_kT},
                   {"E_difference_min_after_us", o.min_difference_after_us},
                   {"writhe_before", o.writhe_before},
                   {"writhe_continuation", o.writhe_continuation},
                   {"writhe_after", o.writhe_after},
                   {"stable", o.stable},
                   {"method", o.hessian ? "hessian" : "dynamic"}});
  if (o.hessian) {
    nlohmann::json& t = tests.back();
    t["lowest_eigenvalues_kT_per_A2"] = o.lowest_eigenvalues;
    t["negative_modes"] = o.negative_modes;
    t["zero_modes"] = o.zero_modes;
    t["slithering_modes"] = o.slithering_modes;
    t["gradient_kT_per_A"] = o.gradient_kT_per_A;
    t["hessian_asymmetry"] = o.asymmetry;
  }
  meta.stability_tests_json = tests.dump();
  say("ibrod: stability test at step " + std::to_string(o.step) + ": " + sim::describe(o) +
      (o.stable ? "; an equilibrium" : "; not an equilibrium, the run goes on from there"));
  if (o.stable) return candidate;
  if (const std::string bad = s.state_check(); !bad.empty()) blow_up(bad);
  last_row = observe_checked();
  record_row();
  check_link(last_row);
  return s.at_end() ? StopReason::end_time : StopReason::none;
}

void Run::State::check_link(const sim::Observables& o) {
  const double drift = sim::link_drift(o, result.initial);
  if (std::isnan(drift)) return;  // no linking number to conserve (open rods)
  meta.max_link_drift = std::max(meta.max_link_drift, drift);
  if (drift > kLinkDriftWarning && !meta.self_passage_warning) {
    meta.self_passage_warning = true;
    meta.self_passage_step = o.step;
    char buf[420];
    std::snprintf(buf, sizeof buf,
                  "ibrod: warning: at step %lld the linking number Lk = %.4f drifted by %.3g from "
                  "its initial %.4f (more than %.1f): %s (steric.stiffness or steric.diameter_A "
                  "too small, or Δt too large); recorded in summary.json",
                  static_cast<long long>(o.step), o.link, o.link - result.initial.link,
                  result.initial.link, kLinkDriftWarning,
                  rod::names_rods(sim->rod_ranges())
                      ? "a rod has probably passed through itself or another rod "
                        "(rods.csv: each rod's link and each pair's)"
                      : "the rod has probably passed through itself");
    say(buf);
  }
}

// The time loop: step, check, and write what the Simulation's schedule asks for.
RunResult Run::State::loop(const std::function<int()>& pending, std::int64_t max_steps) {
  sim::Simulation& s = *sim;
  // the step's OpenMP loops on the run's thread count in the thread that runs them: OpenMP keeps
  // the count per thread, and the Python module may advance a run from a worker thread (where
  // the default count would sum the per-thread pair-force buffers in another order)
  omp_set_num_threads(s.system().fluid_threads());
  loop_start = Clock::now();
  start_step = s.step_count();
  result.signal = 0;
  // (Simulation::state_check: each rod's spacing, with thermal noise the tolerance widened to
  // what a segment's thermal stretch alone may reach; docs/thermal.md)
  try {
    ensure_space();
    if (!begun && result.resumed_from < 0) {
      if (const std::string bad = s.state_check(); !bad.empty())
        blow_up("the initial state is not sane: " + bad);
      last_row = observe_checked();
      result.initial = meta.initial = last_row;
      record_row();
      write_frame();
      write_checkpoint(StopReason::none);
    } else if (!begun) {
      last_row = s.observe();
    }
    begun = true;

    // a line at once, with the state's real values (a large grid's first output step may be
    // minutes away)
    if (!s.at_end()) progress.update(progress_line(last_row), 0.0, false, /*force=*/true);
    bool shown_output_step = false;

    StopReason reason = StopReason::none;
    if (s.at_end()) {
      // resumed at its end time (a checkpoint at t_end, or t_end moved to it): stop here
      reason = StopReason::end_time;
      write_checkpoint(reason);
      progress.update(progress_line(last_row), seconds_since(loop_start), /*last=*/true);
    }
    std::int64_t done = 0;  // steps of this segment
    while (reason == StopReason::none) {
      // distributed: the ranks agree on a signal (each may see it after another step)
      if (const int sig = distributed ? int(mpi::max(pending())) : pending()) {
        // the end of the current step: save it, then stop
        if (result.checkpoint_step != s.step_count()) write_checkpoint(StopReason::none);
        progress.finish_line();
        result.signal = sig;
        result.reason = StopReason::interrupted;
        finish(last_row, to_string(StopReason::interrupted), "");
        char buf[256];
        std::snprintf(buf, sizeof buf, "ibrod: interrupted by %s at step %lld (t = %.4f us)",
                      signal_name(sig), static_cast<long long>(s.step_count()), s.time() / 1e-6);
        say(buf);
        return result;
      }
      s.step();
      ++done;
      if (const std::string bad = s.state_check(); !bad.empty()) blow_up(bad);
      const bool segment_end = max_steps > 0 && done >= max_steps;
      const bool output_step = s.output_due() || segment_end;
      if (output_step) {
        last_row = observe_checked();
        record_row();
        check_link(last_row);
        reason = s.stop_reason(last_row);
        if (reason == StopReason::equilibrium) reason = test_stability(reason);
        if (reason == StopReason::none && segment_end) reason = StopReason::end_time;
      }
      const bool stop = reason != StopReason::none;
      const bool frame_step = s.frame_due(stop);
      const bool checkpoint_step = s.checkpoint_due(stop);
      if (frame_step) write_frame();
      if (checkpoint_step) write_checkpoint(reason);
      // before the next step's writes: room for a new checkpoint beside the old one, frames
      if (!stop && (output_step || frame_step || checkpoint_step)) ensure_space();
      const double now = seconds_since(loop_start);
      if (stop) {
        progress.update(progress_line(last_row), now, /*last=*/true);
        break;
      }
      // a line at the first output step (ms/step and ETA now measured) and after one interval,
      // then by the clock (with the latest row: ms/step and ETA are current, the observables are
      // those of the last output step)
      if (output_step && !shown_output_step) {
        progress.update(progress_line(last_row), now, false, /*force=*/true);  // with ms/step
        shown_output_step = true;
      } else if (progress.due(now)) {
        progress.update(progress_line(last_row), now);
      }
    }
    result.reason = reason;
    finish(last_row, to_string(reason), "");
  } catch (const RunError& e) {
    // leave a summary that says why the run stopped, if the disk still takes one
    const std::string what = e.what();
    if (what.rfind("run: blow-up", 0) == 0) {
      progress.finish_line();
      throw;
    }
    // a write that failed because the run directory was deleted or moved under the run (finish
    // notices a directory that is gone; a file of the run's that vanished mid-write, ENOENT, means
    // the deletion was under way): that is the cause to report, with no --resume advice
    std::string gone;
    if (writes() && what.rfind("output: ", 0) == 0 &&
        what.find(dir.root().string()) != std::string::npos &&
        what.find(std::strerror(ENOENT)) != std::string::npos)
      gone = RunFiles::directory_gone(dir.root(), sim->step_count());
    try {
      finish(last_row, to_string(StopReason::error), what);
    } catch (const RunError& f) {
      if (std::string(f.what()).find(" was deleted or moved while the run") != std::string::npos)
        gone = f.what();
    }
    progress.finish_line();
    if (!gone.empty()) throw RunError(gone);
    // the advice that works: --resume needs a checkpoint
    if (!writes()) throw;
    if (what.find("--resume") != std::string::npos || what.find("--overwrite") != std::string::npos)
      throw;
    throw RunError(what + (result.checkpoint_step >= 0
                               ? "; once the cause is fixed, continue with: ibrod run --resume " +
                                     dir.root().string()
                               : "; the run stopped before its first checkpoint: once the cause "
                                 "is fixed, start it again with --overwrite (ibrod run CONFIG -o " +
                                     dir.root().string() + " --overwrite)"));
  }

  char buf[512];
  if (sim->link_defined())
    std::snprintf(buf, sizeof buf,
                  "ibrod: stopped (%s) after %lld steps, t = %.4f us, Wr = %.4f, Tw = %.4f, "
                  "Lk = %.4f; %.1f s wall, %.3f ms/step",
                  to_string(result.reason).c_str(), static_cast<long long>(result.steps),
                  result.time_us, last_row.writhe, last_row.twist, last_row.link, result.wall_s,
                  result.ms_per_step);
  else  // an open rod: no writhe or link (docs/model.md "Open rods")
    std::snprintf(buf, sizeof buf,
                  "ibrod: stopped (%s) after %lld steps, t = %.4f us, open rod: Tw = %.4f, "
                  "E_elastic = %.4f kT; %.1f s wall, %.3f ms/step",
                  to_string(result.reason).c_str(), static_cast<long long>(result.steps),
                  result.time_us, last_row.twist,
                  last_row.E_bend_kT + last_row.E_twist_kT + last_row.E_stretch_kT, result.wall_s,
                  result.ms_per_step);
  say(buf);
  return result;
}

InitialShapes read_initial_shapes(const config::Config& c) {
  InitialShapes out;
  const auto read = [&](const config::Config& cr, const std::string& key, int rod,
                        const rod::RodRange& layout) {
    rod::RodState shape = io::read_rod_shape(cr.rod_initial_shape, key, rod);
    if (const std::string bad = sim::state_problem(shape, layout); !bad.empty())
      throw ConfigError(key + " = '" + cr.rod_initial_shape + "': " + bad +
                        " (rod.base_pairs = " + std::to_string(cr.rod_base_pairs) +
                        ", rod.rise_A = " + format_g(cr.rod_rise_A) + " Å)");
    return shape;
  };
  // each rod's own rod.initial_shape ([[rods]] table r: rod r of a file of several rods)
  const std::vector<rod::RodRange> layout = config::rod_layout(c);
  for (const config::RodConfig& rc : config::rod_configs(c)) {
    out.emplace_back();
    if (!rc.keys.rod_initial_shape.empty())
      out.back() = read(rc.keys, rc.key("initial_shape"), rc.table, layout[out.size() - 1]);
  }
  // the rods together: no two on top of each other, in the box or across its faces
  const sim::SimParams p = config::to_params(c);
  rod::RodState whole = sim::initial_state(p);
  const std::vector<rod::RodRange> ranges = rod::ranges_of(p.stepper.rods);
  for (std::size_t r = 0; r < out.size(); ++r) {
    if (!out[r]) continue;
    for (int k = 0; k < ranges[r].n; ++k) {
      whole.X[ranges[r].offset + k] = out[r]->X[k];
      whole.D[ranges[r].offset + k] = out[r]->D[k];
    }
  }
  if (const std::string bad = sim::rods_state_problem(p.stepper.rods, whole, p.stepper.grid.L);
      !bad.empty())
    throw ConfigError("rod.initial_shape: the initial state: " + bad);
  return out;
}

Run::Run(const config::Config& c, const RunOptions& opt) {
  config::validate(c);
  s_ = std::make_unique<State>(c, opt);
  // the per-link files (rod.moduli_file, rod.intrinsic_file) read and checked before anything is
  // written, as every key is
  (void)config::to_params(c);
  // a fresh run gets its id here; a resumed one keeps its own (Run::State::open_checkpoint)
  if (!opt.resume) s_->stamp.run_id = new_run_id();
  s_->stamp.inputs = input_checksums(c);
  s_->restamp();
  // rod.initial_shape: read and checked before anything is written (a resumed run has its state)
  if (!opt.resume) {
    s_->rod_shapes = read_initial_shapes(c);
  }
}

Run::~Run() = default;

RunResult Run::execute() {
  State& st = *s_;
  st.check_launch();
  if (st.opt.resume) {
    try {
      st.open_checkpoint();
    } catch (const AlreadyFinished&) {
      return st.result;
    }
  }
  st.prepare_directory();
  // from here a SIGINT/SIGTERM (during FFTW's planning, too) stops the run after a checkpoint
  const SignalGuard signals(st.opt.handle_signals, SignalGuard::Mode::run);
  st.build_simulation();
  st.restore_state();
  st.open_files();
  if (st.complete_only) return st.complete();
  st.announce();
  return st.loop([&] { return signals.pending(); }, -1);
}

void Run::prepare() {
  State& st = *s_;
  if (st.opt.resume || st.distributed)
    throw ConfigError("run: the step-by-step interface runs a fresh run on one process only");
  st.check_launch();
  st.prepare_directory();
  st.build_simulation();
  st.restore_state();
  st.open_files();
  st.announce();
}

RunResult Run::advance(std::int64_t max_steps, const std::function<int()>& pending) {
  State& st = *s_;
  if (!st.sim) throw std::logic_error("Run::advance: call prepare() first");
  if (max_steps == 0 || max_steps < -1)
    throw std::invalid_argument("Run::advance: max_steps must be positive (or -1: no limit)");
  return st.loop(pending, max_steps);
}

void Run::set_end_time(double t_end_us) {
  State& st = *s_;
  config::Config next = st.user;
  next.time_t_end_us = t_end_us;
  config::validate(next);
  st.user.time_t_end_us = st.c.time_t_end_us = t_end_us;
  st.restamp();
  st.meta.config_toml = st.config_text;
  if (st.sim) st.sim->set_t_end(t_end_us * 1e-6);
  st.on_disk([&] { io::write_file_atomic(st.dir.config(), st.config_text); });
}

sim::Simulation& Run::simulation() {
  if (!s_->sim) throw std::logic_error("Run::simulation: call prepare() first");
  return *s_->sim;
}

const config::Config& Run::config() const { return s_->c; }

const std::vector<sim::Observables>& Run::rows() const { return s_->rows; }

RunResult run(const config::Config& c, const RunOptions& opt) { return Run(c, opt).execute(); }

}  // namespace ibrod::driver
