#include "driver/run_files.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "io/observables_json.hpp"

namespace ibrod::driver {

namespace fs = std::filesystem;
using io::CheckpointMeta;

namespace {
// The simulated time is a sum of steps: 0.5 µs comes out as 0.5000000000000001. summary.json
// gives it to 12 significant digits (far below any Δt), so that it reads as the time it is.
double time_without_noise(double t_us) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.12g", t_us);
  return std::strtod(buf, nullptr);
}
}  // namespace
using io::observables_json;

void prepare_output_dir(const io::RunDir& run_dir, bool overwrite, std::optional<DirLock>& lock) {
  const fs::path& dir = run_dir.root();
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw ConfigError("output: '" + dir.string() + "' exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) throw RunError("output: cannot create '" + dir.string() + "': " + ec.message());
  lock.emplace(dir);  // before anything is looked at or removed: one writer at a time
  bool holds_files = false;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path() != run_dir.lock()) holds_files = true;
  if (holds_files && !overwrite)
    throw ConfigError("output: directory '" + dir.string() +
                      "' already holds files; choose another -o DIR, pass --overwrite, or "
                      "continue a stopped run with --resume " +
                      dir.string());
  if (overwrite) {
    // stale frames or a stale checkpoint of an earlier run must not mix with this one; only what
    // a run writes is removed (a file of the user's, in DIR or in vtk/, is kept)
    for (const fs::path& f : run_dir.run_files()) fs::remove_all(f, ec);
    const fs::path vtk = dir / io::RunDir::kVtkDir;
    if (fs::is_directory(fs::symlink_status(vtk, ec))) {
      std::vector<fs::path> frames;
      for (const auto& e : fs::directory_iterator(vtk, ec))
        if (io::RunDir::is_frame_file(e.path().filename().string())) frames.push_back(e.path());
      for (const fs::path& f : frames) fs::remove(f, ec);
      fs::remove(vtk, ec);  // only if now empty
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Output files that grow during the run: timeseries.csv, trajectory.h5md, rod.pvd (+ fluid.pvd).

std::string summary_json(const config::Config& c, bool link_defined, const RunResult& r,
                         const CheckpointMeta& meta, std::int64_t frames,
                         const std::string& stop_reason, const std::string& error) {
  nlohmann::ordered_json j;
  j["steps"] = r.steps;
  j["time_us"] = time_without_noise(r.time_us);
  j["stop_reason"] = stop_reason;
  j["excess_link"] = c.rod_excess_link;
  j["closed"] = link_defined;
  // docs/thermal.md: whether the run had thermal noise, at which temperature, with which seed
  j["thermal"] = c.solvent_thermal;
  j["temperature_K"] = c.solvent_temperature_K;
  j["seed"] = c.run_seed;
  // an open rod has no link: null, "not defined" (docs/outputs.md)
  j["link_drift"] = link_defined ? nlohmann::ordered_json(r.final.link - r.initial.link)
                                 : nlohmann::ordered_json(nullptr);
  j["max_link_drift"] =
      link_defined ? nlohmann::ordered_json(meta.max_link_drift) : nlohmann::ordered_json(nullptr);
  j["self_passage_warning"] = meta.self_passage_warning;
  j["self_passage_step"] = meta.self_passage_step >= 0
                               ? nlohmann::ordered_json(meta.self_passage_step)
                               : nlohmann::ordered_json(nullptr);
  j["wall_time_s"] = r.wall_s;
  j["ms_per_step"] = r.ms_per_step;
  // the implicit scheme's factorisations of its local system in this process (docs/large_dt.md)
  if (r.implicit_factorizations >= 0) {
    j["implicit_factorizations"] = r.implicit_factorizations;
    j["implicit_early_refreshes"] = r.implicit_early_refreshes;
    j["implicit_stokes_solves"] = r.implicit_stokes_solves;
  }
  j["total_wall_time_s"] = meta.wall_s;
  j["threads"] = meta.threads;
  j["resumed_from_step"] = r.resumed_from >= 0 ? nlohmann::ordered_json(r.resumed_from)
                                               : nlohmann::ordered_json(nullptr);
  j["resumes"] = meta.resumes;
  j["checkpoint_step"] = r.checkpoint_step >= 0 ? nlohmann::ordered_json(r.checkpoint_step)
                                                : nlohmann::ordered_json(nullptr);
  j["frames"] = frames;
  j["stability_tests"] = nlohmann::ordered_json::parse(meta.stability_tests_json);
  // an equilibrium is verified when the last stability test at the stop found it stable
  if (stop_reason == "equilibrium") {
    const auto tests = nlohmann::json::parse(meta.stability_tests_json);
    j["equilibrium_verified"] = !tests.empty() && tests.back().value("stable", false) &&
                                tests.back().value("step", std::int64_t(-1)) == r.steps;
  } else {
    j["equilibrium_verified"] = false;
  }
  j["error"] = error.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(error);
  j["initial"] = observables_json(r.initial);
  j["final"] = observables_json(r.final);
  j["initial"]["time_us"] = time_without_noise(r.initial.time_us);
  j["final"]["time_us"] = time_without_noise(r.final.time_us);
  return j.dump(2) + "\n";
}

}  // namespace ibrod::driver
