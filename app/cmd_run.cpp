// `ibrod run`, `ibrod check`, `ibrod bench` (cmd_run.hpp); the work is in driver/run.hpp,
// config/config.hpp and driver/bench.hpp.
#include "cmd_run.hpp"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "core/error.hpp"
#include "driver/bench.hpp"
#include "driver/bench_schemes.hpp"
#include "driver/mpi_env.hpp"
#include "driver/run.hpp"
#include "exit_status.hpp"
#include "io/run_dir.hpp"

namespace {

namespace cfg = ibrod::config;
namespace driver = ibrod::driver;

struct ConfigArgs {
  std::string config_path;
  bool config_given = false;  ///< CONFIG was on the command line (perhaps as "")
  std::vector<std::string> sets;
};

struct RunArgs : ConfigArgs {
  std::string out_dir = "ibrod-out", resume_dir, wisdom;
  bool overwrite = false, force = false;
};

struct BenchArgs : ConfigArgs {
  int steps = 200, threads = 0;
  bool schemes = false;  // issue 14: explicit against implicit, µs per wall hour
  double implicit_dt_ns = 2, implicit_ns = 200;
};

cfg::Config resolve(const ConfigArgs& a) {
  // `ibrod run ""` is not `ibrod run`: an empty path is refused, not read as "defaults"
  if (a.config_given && a.config_path.empty())
    throw ibrod::ConfigError(
        "config: cannot read file '': the path is empty (omit CONFIG for "
        "the built-in reference run)");
  cfg::Config c = cfg::load_config(a.config_path);
  for (const auto& s : a.sets) cfg::apply_override(c, s);
  cfg::validate(c);
  return c;
}

void add_config_args(CLI::App* cmd, ConfigArgs& a) {
  cmd->add_option("config", a.config_path, "TOML config (default: the built-in reference run)")
      ->each([&a](const std::string&) { a.config_given = true; });
  cmd->add_option("--set", a.sets, "override one key: section.key=value (repeatable)");
}

int run_main(RunArgs a) {
  // `mpirun -np K ibrod run`: MPI is initialised (only under a launcher) before anything can
  // fail, so that every rank reaches the same error and exit status; K > 1 splits the fluid grid
  // over the ranks (driver/run.hpp). Without a launcher this is a one-process program.
  const driver::mpi::World world = driver::mpi::init(nullptr, nullptr);
  struct Finalize {
    const driver::mpi::World& w;
    ~Finalize() {
      std::fflush(stdout);
      driver::mpi::finalize(w);
    }
  } finalize{world};
  const bool resuming = !a.resume_dir.empty();
  if (resuming) {
    a.config_path = ibrod::io::RunDir(a.resume_dir).config().string();
    a.out_dir = a.resume_dir;
  }
  try {
    if (resuming && !std::filesystem::exists(a.config_path))
      throw ibrod::ConfigError("resume: '" + a.resume_dir +
                               "' holds no config.toml: it is not the output directory of an "
                               "ibrod run");
    const cfg::Config c = resolve(a);
    driver::RunOptions opt;
    opt.output_dir = a.out_dir;
    opt.overwrite = a.overwrite;
    opt.resume = resuming;
    opt.force = a.force;
    opt.fftw_wisdom = a.wisdom;
    opt.rank = world.rank;
    opt.ranks = world.size;
    // the memory a run needs against what this process may allocate, before any of it is
    cfg::check_memory(c, world.size);
    const driver::RunResult r = driver::run(c, opt);
    if (r.signal != 0 && world.rank == 0) {
      std::fprintf(stderr,
                   "ibrod: stopped by signal %d at step %lld; checkpoint written. Continue with: "
                   "ibrod run --resume %s\n",
                   r.signal, static_cast<long long>(r.steps), a.out_dir.c_str());
    }
    return r.signal != 0 ? 128 + r.signal : 0;
  } catch (const std::exception& e) {
    return ibrod::app::report_error(e);
  }
}

int check_main(const ConfigArgs& a) {
  try {
    const cfg::Config c = resolve(a);
    // rod.initial_shape and the rods' start together, checked as `ibrod run` checks them
    driver::read_initial_shapes(c);
    std::printf("# resolved configuration\n%s\n# derived quantities\n%s", cfg::describe(c).c_str(),
                cfg::derived_report(c).c_str());
    for (const std::string& w : cfg::check_warnings(c)) std::printf("# warning: %s\n", w.c_str());
    // a config may be meant for a larger machine: `check` warns where `run` would refuse
    try {
      cfg::check_memory(c);
    } catch (const ibrod::ConfigError& e) {
      std::printf("# warning: `ibrod run` here would refuse: %s\n", e.what());
    }
    return 0;
  } catch (const std::exception& e) {
    return ibrod::app::report_error(e);
  }
}

int bench_main(const BenchArgs& a) {
  try {
    cfg::Config c = resolve(a);
    if (a.threads > 0) c.run_threads = a.threads;
    cfg::check_memory(c);
    if (a.schemes) {
      driver::print_bench_schemes(
          driver::bench_schemes(c, a.steps, a.implicit_dt_ns, a.implicit_ns), stdout);
      return 0;
    }
    driver::print_bench(c, driver::bench(c, a.steps), stdout);
    return 0;
  } catch (const std::exception& e) {
    return ibrod::app::report_error(e);
  }
}

}  // namespace

void add_run_commands(CLI::App& app) {
  auto ra = std::make_shared<RunArgs>();
  auto* run = app.add_subcommand("run", "run one trajectory");
  add_config_args(run, *ra);
  auto* run_config = run->get_option("config");
  auto* run_out =
      run->add_option("-o,--output", ra->out_dir, "output directory")->capture_default_str();
  auto* run_overwrite = run->add_flag("--overwrite", ra->overwrite,
                                      "replace the files of an existing output directory");
  auto* run_resume = run->add_option(
      "--resume", ra->resume_dir,
      "continue the stopped run in DIR from DIR/checkpoint.bin (reads DIR/config.toml)");
  run_resume->excludes(run_config)->excludes(run_out)->excludes(run_overwrite);
  run->add_flag("--force", ra->force,
                "with --resume: continue even if the configuration (with --set) differs from "
                "the checkpoint's")
      ->needs(run_resume);
  run->add_option("--fftw-wisdom", ra->wisdom,
                  "import FFTW plans from FILE (e.g. another run's fftw.wisdom): runs that share "
                  "plans agree bit for bit");
  run->callback([ra] { throw CLI::RuntimeError(run_main(*ra)); });

  auto ca = std::make_shared<ConfigArgs>();
  auto* check = app.add_subcommand("check", "print the resolved parameters and derived quantities");
  add_config_args(check, *ca);
  check->callback([ca] { throw CLI::RuntimeError(check_main(*ca)); });

  auto ba = std::make_shared<BenchArgs>();
  auto* bench = app.add_subcommand("bench", "time one step by phase against its FFTs alone");
  add_config_args(bench, *ba);
  bench->add_option("--steps", ba->steps, "timed steps")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  bench->add_option("--threads", ba->threads, "threads (0: run.threads of the config)")
      ->check(CLI::NonNegativeNumber);
  bench->add_flag("--schemes", ba->schemes,
                  "instead: simulated µs per wall hour of the explicit scheme (--steps steps of "
                  "time.dt_ns) and the implicit one (--implicit-ns at Δt ≤ --implicit-dt-ns); "
                  "last line us_per_hour_explicit=… us_per_hour_implicit=…");
  bench->add_option("--implicit-dt-ns", ba->implicit_dt_ns, "with --schemes: the implicit Δt max")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  bench->add_option("--implicit-ns", ba->implicit_ns, "with --schemes: implicit simulated ns")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  bench->callback([ba] { throw CLI::RuntimeError(bench_main(*ba)); });
}
