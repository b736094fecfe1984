#include "driver/run_files.hpp"

#include <nlohmann/json.hpp>

#include "io/observables_json.hpp"

namespace ibrod::driver {

namespace fs = std::filesystem;
using io::CheckpointMeta;
using io::observables_json;

void prepare_output_dir(const io::RunDir& run_dir, bool overwrite) {
  const fs::path& dir = run_dir.root();
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
      for (const fs::path& f : run_dir.run_files()) fs::remove_all(f, ec);
    }
  }
  fs::create_directories(dir, ec);
  if (ec) throw RunError("output: cannot create '" + dir.string() + "': " + ec.message());
}

// ---------------------------------------------------------------------------------------------
// Output files that grow during the run: timeseries.csv, trajectory.h5, rod.pvd (+ fluid.pvd).

std::string summary_json(const config::Config& c, const RunResult& r, const CheckpointMeta& meta,
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

}  // namespace ibrod::driver
