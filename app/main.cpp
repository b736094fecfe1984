// ibrod command-line program.
//   ibrod run   [CONFIG] [--set k=v]... [-o DIR] [--overwrite]
//   ibrod check [CONFIG] [--set k=v]...
//   ibrod bench [CONFIG] [--set k=v]... [--steps K] [--threads T]
// Exit status: 0 success, 2 invalid input (config, arguments, output directory), 3 the run failed
// (non-finite state, I/O), 1 anything else.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/error.hpp"
#include "io/bench.hpp"
#include "io/config.hpp"
#include "io/run.hpp"

namespace {

ibrod::io::Config resolve(const std::string& path, const std::vector<std::string>& sets) {
  ibrod::io::Config c = ibrod::io::load_config(path);
  for (const auto& s : sets) ibrod::io::apply_override(c, s);
  ibrod::io::validate(c);
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ibrod: elastic rods in viscous fluid by the generalized immersed boundary method"};
  app.require_subcommand(1);

  std::string config_path, out_dir = "ibrod-out";
  std::vector<std::string> sets;
  bool overwrite = false;

  auto* run = app.add_subcommand("run", "run one trajectory");
  run->add_option("config", config_path, "TOML config (default: the built-in reference run)");
  run->add_option("--set", sets, "override one key: section.key=value (repeatable)");
  run->add_option("-o,--output", out_dir, "output directory")->capture_default_str();
  run->add_flag("--overwrite", overwrite, "replace the files of an existing output directory");

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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }

  try {
    const ibrod::io::Config c = resolve(config_path, sets);
    if (*check) {
      std::printf("# resolved configuration\n%s\n# derived quantities\n%s",
                  ibrod::io::describe(c).c_str(), ibrod::io::derived_report(c).c_str());
      return 0;
    }
    if (*bench) {
      ibrod::io::Config b = c;
      if (bench_threads > 0) b.run_threads = bench_threads;
      ibrod::io::print_bench(b, ibrod::io::bench(b, bench_steps), stdout);
      return 0;
    }
    ibrod::io::RunOptions opt;
    opt.output_dir = out_dir;
    opt.overwrite = overwrite;
    ibrod::io::run(c, opt);
    return 0;
  } catch (const ibrod::ConfigError& e) {
    std::fprintf(stderr, "ibrod: error: %s\n", e.what());
    return 2;
  } catch (const ibrod::RunError& e) {
    std::fprintf(stderr, "ibrod: error: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ibrod: error: %s\n", e.what());
    return 1;
  }
}
