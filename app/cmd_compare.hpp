#pragma once
// `ibrod compare RUN_A RUN_B [--max-dwr X] [--max-de KT] [--max-final-de KT] [--guard-us US]
//                            [--contact-distance A] [--json FILE] [-q]`
// (docs/analysis.md "Comparing two runs"; the work is in analysis/compare.hpp). Registered on the
// program's CLI::App by add_compare_command; like the other subcommands it runs from its CLI11
// callback and ends parsing with CLI::RuntimeError(status): 0 done (and within every limit
// given), 1 a limit exceeded or a shape mismatch outside the guard (only with a limit), 2 bad
// input (a missing directory or file, no common time), 3 the --json file could not be written.
#include <CLI/CLI.hpp>

void add_compare_command(CLI::App& app);
