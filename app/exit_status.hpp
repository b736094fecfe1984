#pragma once
// The one mapping from an exception to the program's message and exit status, shared by every
// subcommand: 2 invalid input (ConfigError), 3 the run failed (RunError), 1 anything else.
#include <cstdio>
#include <exception>

#include "core/error.hpp"

namespace ibrod::app {

/// Prints "ibrod: error: …" (unless print is false) and returns the exit status for e.
inline int report_error(const std::exception& e, bool print = true) {
  if (print) std::fprintf(stderr, "ibrod: error: %s\n", e.what());
  if (dynamic_cast<const ConfigError*>(&e)) return 2;
  if (dynamic_cast<const RunError*>(&e)) return 3;
  return 1;
}

}  // namespace ibrod::app
