// ibrod command-line program.
//   ibrod run   [CONFIG] [--set k=v]... [-o DIR] [--overwrite] [--fftw-wisdom FILE]
//   ibrod run   --resume DIR [--force] [--set k=v]...
//   ibrod check [CONFIG] [--set k=v]...
//   ibrod bench [CONFIG] [--set k=v]... [--steps K] [--threads T]
//   ibrod analyze DIR | render DIR [--time T] [--views ...] | sweep SWEEP.toml [-j K]
//   ibrod compare RUN_A RUN_B [--max-dwr X] [--max-de KT] [--max-final-de KT] [--json FILE]
// Each subcommand lives in its own cmd_*.cpp and runs from its CLI11 callback, ending the parse
// with CLI::RuntimeError(status). Exit status: 0 success, 2 invalid input (config, arguments,
// output directory, unusable checkpoint, more memory than allowed), 3 the run failed (blow-up,
// I/O such as a full disk, out of memory),
// 4 some points of a sweep failed, 128 + N stopped by signal N (SIGINT 130, SIGTERM 143) after
// writing a checkpoint, 1 a limit of `compare` exceeded, or anything else.
#include <CLI/CLI.hpp>

#include <string>

#include "cmd_analysis.hpp"
#include "cmd_compare.hpp"
#include "cmd_run.hpp"
#include "cmd_sweep.hpp"

int main(int argc, char** argv) {
  CLI::App app{"ibrod: elastic rods in viscous fluid by the generalized immersed boundary method"};
#ifdef IBROD_MPI
  const char* mpi = "yes";
#else
  const char* mpi = "no";
#endif
  app.set_version_flag("--version", std::string("ibrod ") + IBROD_VERSION + " (git " +
                                        IBROD_GIT_HASH + ", " + IBROD_BUILD_TYPE + " build, MPI " +
                                        mpi + ")");
  app.require_subcommand(1);
  add_run_commands(app);       // run, check, bench (app/cmd_run.cpp)
  add_analysis_commands(app);  // analyze, render (app/cmd_analysis.cpp)
  add_compare_command(app);    // compare (app/cmd_compare.cpp)
  add_sweep_command(app);      // sweep (app/cmd_sweep.cpp)
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // every subcommand ends here with its status
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return 0;
}
