// `ibrod sweep` (cmd_sweep.hpp); the work is in driver/sweep_file.hpp and driver/sweep_runner.hpp.
#include "cmd_sweep.hpp"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "exit_status.hpp"
#include "driver/mpi_env.hpp"
#include "driver/sweep_runner.hpp"

namespace {

struct SweepArgs {
  std::string file, output;
  int jobs = 1;
  bool list = false;
};

int sweep_main(const SweepArgs& a) {
  namespace fs = std::filesystem;
  // MPI only under a launcher; the ranks share the points, each spawns plain `ibrod run`s
  const ibrod::driver::mpi::World world = ibrod::driver::mpi::init(nullptr, nullptr);
  struct Finalize {
    const ibrod::driver::mpi::World& w;
    ~Finalize() { ibrod::driver::mpi::finalize(w); }
  } finalize{world};
  const bool root = world.rank == 0;
  int status = 0;
  try {
    const ibrod::driver::Sweep sw = ibrod::driver::load_sweep(a.file);
    ibrod::driver::SweepOptions opt;
    opt.output_root = !a.output.empty()          ? fs::path(a.output)
                      : !sw.output_root.empty() ? fs::path(sw.output_root)
                                                : fs::path(fs::path(a.file).stem());
    if (a.list) {
      if (root)
        for (const auto& pt : sw.points)
          std::printf("%-40s %s\n", pt.name.c_str(),
                      ibrod::driver::to_string(ibrod::driver::point_state(opt.output_root / pt.name)));
      return 0;
    }
    opt.jobs = a.jobs;
    opt.rank = world.rank;
    opt.ranks = world.size;
    const ibrod::driver::SweepReport r = ibrod::driver::run_sweep(sw, opt);
    for (const auto& name : r.failed_names)
      std::fprintf(stderr, "ibrod: sweep: point %s failed\n", name.c_str());
    // collectives in the same order on every rank
    const long long failed = ibrod::driver::mpi::sum(r.failed);
    const long long sig = ibrod::driver::mpi::max(r.signal);
    const long long points = ibrod::driver::mpi::sum(r.points);
    const long long completed = ibrod::driver::mpi::sum(r.completed);
    const long long skipped = ibrod::driver::mpi::sum(r.skipped);
    if (world.size > 1 && root)
      std::printf("sweep: all ranks: %lld points, %lld finished now, %lld already finished, %lld "
                  "failed\n",
                  points, completed, skipped, failed);
    status = sig ? 128 + int(sig) : failed > 0 ? 4 : 0;
  } catch (const std::exception& e) {
    // a bad sweep file is the same on every rank: only rank 0 says so
    status = ibrod::app::report_error(e, root || !dynamic_cast<const ibrod::ConfigError*>(&e));
  }
  std::fflush(stdout);
  return status;
}

}  // namespace

void add_sweep_command(CLI::App& app) {
  auto a = std::make_shared<SweepArgs>();
  auto* sweep = app.add_subcommand(
      "sweep", "run every point of a parameter sweep (SWEEP.toml: a config plus [sweep] lists)");
  sweep->add_option("sweep_file", a->file, "sweep file (docs/sweeps.md)")->required();
  sweep->add_option("-j,--jobs", a->jobs, "ibrod run processes at a time (per MPI rank)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sweep->add_option("-o,--output", a->output,
                    "root of the point directories (default: `output_dir` of the sweep file, else "
                    "the sweep file's name without .toml)");
  sweep->add_flag("--list", a->list, "print every point's name and state, run nothing");
  sweep->callback([a] { throw CLI::RuntimeError(sweep_main(*a)); });
}
