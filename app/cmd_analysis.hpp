#pragma once
// The post-processing subcommands of the ibrod program:
//   ibrod analyze DIR [--delta D] [--fit-tolerance T] [--quiet]
//   ibrod render  DIR [--time T]... [--views top,side,oblique] [--size WxH]
// add_analysis_commands registers them on the program's CLI::App. Each one runs from its CLI11
// callback, inside app.parse(), and ends parsing by throwing CLI::RuntimeError(status) with the
// exit status (0 done, 2 bad input, 3 failed write), after printing any error as
// "ibrod: error: …" on stderr; CLI::App::exit prints nothing for RuntimeError and returns the
// status. So main needs only: add_analysis_commands(app) before app.parse, and to return
// app.exit(e) from its CLI::ParseError handler.
#include <CLI/CLI.hpp>

void add_analysis_commands(CLI::App& app);
