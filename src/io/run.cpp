#include "io/run.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <toml++/toml.h>

#include "core/error.hpp"

namespace ibrod::io {

namespace fs = std::filesystem;

std::string timeseries_header() {
  return "step,time_us,E_bend_kT,E_twist_kT,E_stretch_kT,E_electro_kT,dE_electro_kT,E_steric_kT,"
         "E_kinetic_kT,E_total_kT,writhe,twist,link,closest_approach_A,bp_spacing_A";
}

std::string timeseries_row(const sim::Observables& o) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%lld,%.10g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,"
                "%.10g,%.10g",
                static_cast<long long>(o.step), o.time_us, o.E_bend_kT, o.E_twist_kT,
                o.E_stretch_kT, o.E_electro_kT, o.dE_electro_kT, o.E_steric_kT, o.E_kinetic_kT,
                o.E_total_kT, o.writhe, o.twist, o.link, o.closest_approach_A, o.bp_spacing_A);
  return buf;
}

namespace {

void write_file(const fs::path& p, const std::string& text) {
  // write to a temporary name, then rename: a reader never sees a half-written file
  const fs::path tmp = p.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
    out.flush();
    if (!out) throw RunError("cannot write " + tmp.string() + " (disk full or no permission?)");
  }
  std::error_code ec;
  fs::rename(tmp, p, ec);
  if (ec) throw RunError("cannot rename " + tmp.string() + " to " + p.string() + ": " + ec.message());
}

std::string final_state_csv(const rod::RodState& s) {
  std::string out = "x_A,y_A,z_A,d1x,d1y,d1z,d2x,d2y,d2z,d3x,d3y,d3z\n";
  char buf[512];
  for (int k = 0; k < s.size(); ++k) {
    const Vec3& x = s.X[k];
    const Mat3& D = s.D[k];
    std::snprintf(buf, sizeof buf, "%.12g,%.12g,%.12g,%.15g,%.15g,%.15g,%.15g,%.15g,%.15g,%.15g,%.15g,%.15g\n",
                  x[0], x[1], x[2], D(0, 0), D(1, 0), D(2, 0), D(0, 1), D(1, 1), D(2, 1), D(0, 2),
                  D(1, 2), D(2, 2));
    out += buf;
  }
  return out;
}

toml::table observables_table(const sim::Observables& o) {
  return toml::table{{"step", o.step},
                     {"time_us", o.time_us},
                     {"E_bend_kT", o.E_bend_kT},
                     {"E_twist_kT", o.E_twist_kT},
                     {"E_stretch_kT", o.E_stretch_kT},
                     {"E_electro_kT", o.E_electro_kT},
                     {"dE_electro_kT", o.dE_electro_kT},
                     {"E_steric_kT", o.E_steric_kT},
                     {"E_kinetic_kT", o.E_kinetic_kT},
                     {"E_total_kT", o.E_total_kT},
                     {"writhe", o.writhe},
                     {"twist", o.twist},
                     {"link", o.link},
                     {"closest_approach_A", o.closest_approach_A},
                     {"bp_spacing_A", o.bp_spacing_A}};
}

std::string summary_json(const Config& c, const RunResult& r) {
  toml::table t{{"steps", r.steps},
                {"time_us", r.time_us},
                {"stop_reason", sim::to_string(r.reason)},
                {"excess_link", c.rod_excess_link},
                {"link_drift", r.final.link - r.initial.link},
                {"wall_time_s", r.wall_s},
                {"ms_per_step", r.ms_per_step},
                {"initial", observables_table(r.initial)},
                {"final", observables_table(r.final)}};
  std::ostringstream os;
  os << toml::json_formatter{t} << "\n";
  return os.str();
}

std::string hms(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return buf;
}

void prepare_output_dir(const fs::path& dir, bool overwrite) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec))
      throw ConfigError("output: '" + dir.string() + "' exists and is not a directory");
    if (!fs::is_empty(dir, ec) && !overwrite)
      throw ConfigError("output: directory '" + dir.string() +
                        "' already holds files; choose another -o DIR or pass --overwrite");
  }
  fs::create_directories(dir, ec);
  if (ec) throw RunError("output: cannot create '" + dir.string() + "': " + ec.message());
}

}  // namespace

RunResult run(const Config& c, const RunOptions& opt) {
  validate(c);
  const fs::path dir(opt.output_dir);
  prepare_output_dir(dir, opt.overwrite);
  write_file(dir / "config.toml", to_toml(c));

  const auto t0 = std::chrono::steady_clock::now();
  sim::Simulation sim(to_params(c));
  const auto& p = sim.params();
  const double dt = p.stepper.fluid.dt;
  const auto total_steps = std::int64_t(std::ceil(p.t_end / dt - 0.5));

  const fs::path ts_path = dir / "timeseries.csv";
  std::FILE* ts = std::fopen(ts_path.c_str(), "w");
  if (!ts) throw RunError("output: cannot open " + ts_path.string());
  auto emit = [&](const sim::Observables& o) {
    // flushed row by row: a killed run loses nothing already computed
    if (std::fprintf(ts, "%s\n", timeseries_row(o).c_str()) < 0 || std::fflush(ts) != 0)
      throw RunError("output: cannot write " + ts_path.string() + " (disk full?)");
  };
  std::fprintf(ts, "%s\n", timeseries_header().c_str());

  RunResult r;
  r.initial = sim.observe();
  emit(r.initial);
  sim::Observables o = r.initial;

  const auto loop_start = std::chrono::steady_clock::now();
  if (opt.log)
    std::fprintf(opt.log, "ibrod: %lld steps of %.4g ns on %d³, %d rod points, ΔLk = %d -> %s\n",
                 static_cast<long long>(total_steps), dt / 1e-9, p.stepper.grid.n,
                 p.stepper.rod.n, p.circle.excess_link, dir.c_str());
  for (;;) {
    sim.step();
    const bool at_end = sim.step_count() >= total_steps;
    if (sim.step_count() % p.output_every != 0 && !at_end) continue;
    o = sim.observe();
    if (!sim.finite() || !std::isfinite(o.E_total_kT)) {
      std::fclose(ts);
      throw RunError("run: the state became non-finite (NaN/Inf) by step " +
                     std::to_string(sim.step_count()) + " (t = " + std::to_string(o.time_us) +
                     " µs); the time step is probably too large for the stretch/shear "
                     "stiffness (time.dt_ns = " + std::to_string(c.time_dt_ns) + ")");
    }
    emit(o);
    r.reason = sim.stop_reason(o);
    if (at_end && r.reason == sim::StopReason::none) r.reason = sim::StopReason::end_time;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
    const double ms = 1e3 * elapsed / double(sim.step_count());
    if (opt.log) {
      std::fprintf(opt.log,
                   "step %lld/%lld  t = %.4f us  Wr = %+.4f  Lk = %+.4f  E_K = %.3e kT  "
                   "%.3f ms/step  ETA %s\n",
                   static_cast<long long>(sim.step_count()), static_cast<long long>(total_steps),
                   o.time_us, o.writhe, o.link, o.E_kinetic_kT, ms,
                   hms(1e-3 * ms * double(total_steps - sim.step_count())).c_str());
      std::fflush(opt.log);
    }
    if (r.reason != sim::StopReason::none) break;
  }
  std::fclose(ts);

  const auto t1 = std::chrono::steady_clock::now();
  r.steps = sim.step_count();
  r.time_us = sim.time() / 1e-6;
  r.final = o;
  r.wall_s = std::chrono::duration<double>(t1 - t0).count();
  r.ms_per_step =
      1e3 * std::chrono::duration<double>(t1 - loop_start).count() / double(std::max<std::int64_t>(r.steps, 1));
  write_file(dir / "final_state.csv", final_state_csv(sim.rod()));
  write_file(dir / "summary.json", summary_json(c, r));
  if (opt.log)
    std::fprintf(opt.log, "ibrod: stopped (%s) after %lld steps, t = %.4f us, Wr = %.4f, Tw = %.4f, "
                 "Lk = %.4f; %.1f s wall, %.3f ms/step\n",
                 sim::to_string(r.reason).c_str(), static_cast<long long>(r.steps), r.time_us,
                 o.writhe, o.twist, o.link, r.wall_s, r.ms_per_step);
  return r;
}

}  // namespace ibrod::io
