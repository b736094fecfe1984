// `ibrod sweep` (cmd_sweep.hpp); the work is in driver/sweep_file.hpp and driver/sweep_runner.hpp.
#include "cmd_sweep.hpp"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "driver/mpi_env.hpp"
#include "driver/sweep_runner.hpp"
#include "exit_status.hpp"

namespace {

struct SweepArgs {
  std::string file, output;
  int jobs = 1;
  bool list = false;
  long point = -1;  ///< --point K: this point alone (a scheduler's job array); −1: all
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
    opt.output_root = !a.output.empty()         ? fs::path(a.output)
                      : !sw.output_root.empty() ? fs::path(sw.output_root)
                                                : fs::path(fs::path(a.file).stem());
    if (a.list) {
      if (root)
        for (const auto& pt : sw.points)
          std::printf(
              "%4zu  %-40s %s\n", pt.index, pt.name.c_str(),
              ibrod::driver::to_string(ibrod::driver::point_state(opt.output_root / pt.name)));
      return 0;
    }
    if (a.point >= 0) {
      if (std::size_t(a.point) >= sw.points.size())
        throw ibrod::ConfigError("sweep: --point " + std::to_string(a.point) +
                                 " is not a point of " + a.file + ": its points are 0 to " +
                                 std::to_string(sw.points.size() - 1) + " (--list shows them)");
      opt.only_point = a.point;
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
    const long long elsewhere = ibrod::driver::mpi::sum(r.running);
    if (world.size > 1 && root)
      std::printf(
          "sweep: all ranks: %lld points, %lld finished now, %lld already finished, %lld "
          "failed\n",
          points, completed, skipped, failed);
    if (elsewhere > 0 && root)
      std::fprintf(stderr,
                   "ibrod: sweep: %lld points are still being written by another process; "
                   "run the sweep again when they are done\n",
                   elsewhere);
    status = sig ? 128 + int(sig) : (failed > 0 || elsewhere > 0) ? 4 : 0;
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
  sweep->add_flag("--list", a->list, "print every point's index, name and state, run nothing");
  sweep
      ->add_option("--point", a->point,
                   "run point K alone (0-based, as --list numbers them), with the same naming, "
                   "skipping and resuming rules: one task of a scheduler's job array "
                   "(e.g. --point $SLURM_ARRAY_TASK_ID)")
      ->check(CLI::NonNegativeNumber);
  sweep->callback([a] { throw CLI::RuntimeError(sweep_main(*a)); });
}
