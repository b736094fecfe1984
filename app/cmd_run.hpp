#pragma once
// `ibrod run`, `ibrod check` and `ibrod bench` (README.md): one trajectory (or its configuration,
// or its benchmark) from a config file plus `--set` overrides. Like the other subcommands, each
// runs from its CLI11 callback and ends parsing by throwing CLI::RuntimeError(status): 0 done,
// 2 invalid input, 3 the run failed, 128 + N stopped by signal N after a checkpoint.
// `mpirun -np K ibrod run` splits one fluid grid over K ranks (driver/run.hpp).
// main needs only: add_run_commands(app) before app.parse.
#include <CLI/CLI.hpp>

void add_run_commands(CLI::App& app);
