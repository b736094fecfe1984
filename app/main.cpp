// ibrod command-line program.
//   ibrod run   [CONFIG] [--set k=v]... [-o DIR] [--overwrite] [--fftw-wisdom FILE]
//   ibrod run   --resume DIR [--force] [--set k=v]...
//   ibrod check [CONFIG] [--set k=v]...
//   ibrod bench [CONFIG] [--set k=v]... [--steps K] [--threads T]
//   ibrod analyze DIR | render DIR [--time T] [--views ...] | sweep SWEEP.toml [-j K]
// Exit status: 0 success, 2 invalid input (config, arguments, output directory, unusable
// checkpoint), 3 the run failed (blow-up, I/O such as a full disk), 128 + N stopped by signal N
// (SIGINT 130, SIGTERM 143) after writing a checkpoint, 1 anything else.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/error.hpp"
#include "cmd_analysis.hpp"
#include "cmd_sweep.hpp"
#include "exit_status.hpp"
#include "driver/bench.hpp"
#include "config/config.hpp"
#include "driver/mpi_env.hpp"
#include "driver/run.hpp"

namespace {

ibrod::config::Config resolve(const std::string& path, const std::vector<std::string>& sets) {
  ibrod::config::Config c = ibrod::config::load_config(path);
  for (const auto& s : sets) ibrod::config::apply_override(c, s);
  ibrod::config::validate(c);
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ibrod: elastic rods in viscous fluid by the generalized immersed boundary method"};
  app.require_subcommand(1);

  std::string config_path, out_dir = "ibrod-out";
  std::vector<std::string> sets;
  bool overwrite = false;

  std::string resume_dir, wisdom;
  bool force = false;
  auto* run = app.add_subcommand("run", "run one trajectory");
  auto* run_config =
      run->add_option("config", config_path, "TOML config (default: the built-in reference run)");
  run->add_option("--set", sets, "override one key: section.key=value (repeatable)");
  auto* run_out = run->add_option("-o,--output", out_dir, "output directory")->capture_default_str();
  auto* run_overwrite =
      run->add_flag("--overwrite", overwrite, "replace the files of an existing output directory");
  auto* run_resume = run->add_option(
      "--resume", resume_dir,
      "continue the stopped run in DIR from DIR/checkpoint.bin (reads DIR/config.toml)");
  run_resume->excludes(run_config)->excludes(run_out)->excludes(run_overwrite);
  run->add_flag("--force", force,
                "with --resume: continue even if the configuration (with --set) differs from "
                "the checkpoint's")
      ->needs(run_resume);
  run->add_option("--fftw-wisdom", wisdom,
                  "import FFTW plans from FILE (e.g. another run's fftw.wisdom): runs that share "
                  "plans agree bit for bit");

  auto* check = app.add_subcommand("check", "print the resolved parameters and derived quantities");
  check->add_option("config", config_path, "TOML config (default: the built-in reference run)");
  check->add_option("--set", sets, "override one key: section.key=value (repeatable)");

  int bench_steps = 200, bench_threads = 0;
  auto* bench = app.add_subcommand("bench", "time one step by phase against its FFTs alone");
  bench->add_option("config", config_path, "TOML config (default: the built-in reference run)");
  bench->add_option("--set", sets, "override one key: section.key=value (repeatable)");
  bench->add_option("--steps", bench_steps, "timed steps")->check(CLI::PositiveNumber)->capture_default_str();
  bench->add_option("--threads", bench_threads, "threads (0: run.threads of the config)")
      ->check(CLI::NonNegativeNumber);

  add_analysis_commands(app);  // analyze, render (app/cmd_analysis.cpp)
  add_sweep_command(app);      // sweep (app/cmd_sweep.cpp)

  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    // analyze, render and sweep run inside parse() and end with their own status
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  // `mpirun -np K ibrod run`: MPI is initialised (only under a launcher) before anything can
  // fail, so that every rank reaches the same error and exit status; K > 1 splits the fluid grid
  // over the ranks (io/run.hpp). Without a launcher this is a one-process program, MPI untouched.
  ibrod::driver::mpi::World world;
  if (*run) world = ibrod::driver::mpi::init(&argc, &argv);
  struct Finalize {
    const ibrod::driver::mpi::World& w;
    ~Finalize() {
      std::fflush(stdout);
      ibrod::driver::mpi::finalize(w);
    }
  } finalize{world};

  const bool resuming = *run && !resume_dir.empty();
  if (resuming) {
    config_path = (std::filesystem::path(resume_dir) / "config.toml").string();
    out_dir = resume_dir;
  }

  try {
    if (resuming && !std::filesystem::exists(config_path))
      throw ibrod::ConfigError("resume: '" + resume_dir +
                               "' holds no config.toml: it is not the output directory of an "
                               "ibrod run");
    const ibrod::config::Config c = resolve(config_path, sets);
    if (*check) {
      std::printf("# resolved configuration\n%s\n# derived quantities\n%s",
                  ibrod::config::describe(c).c_str(), ibrod::config::derived_report(c).c_str());
      return 0;
    }
    if (*bench) {
      ibrod::config::Config b = c;
      if (bench_threads > 0) b.run_threads = bench_threads;
      ibrod::driver::print_bench(b, ibrod::driver::bench(b, bench_steps), stdout);
      return 0;
    }
    ibrod::driver::RunOptions opt;
    opt.output_dir = out_dir;
    opt.overwrite = overwrite;
    opt.resume = resuming;
    opt.force = force;
    opt.fftw_wisdom = wisdom;
    opt.rank = world.rank;
    opt.ranks = world.size;
    const ibrod::driver::RunResult r = ibrod::driver::run(c, opt);
    if (r.signal != 0 && world.rank == 0) {
      std::fprintf(stderr,
                   "ibrod: stopped by signal %d at step %lld; checkpoint written. Continue with: "
                   "ibrod run --resume %s\n",
                   r.signal, static_cast<long long>(r.steps), out_dir.c_str());
    }
    if (r.signal != 0) return 128 + r.signal;
    return 0;
  } catch (const std::exception& e) {
    return ibrod::app::report_error(e);
  }
}
