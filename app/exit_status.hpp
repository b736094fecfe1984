#pragma once
// The one mapping from an exception to the program's message and exit status, shared by every
// subcommand: 2 invalid input (ConfigError), 3 the run failed (RunError, or out of memory), 1
// anything else.
#include <cstdio>
#include <exception>
#include <new>

#include "core/error.hpp"

namespace ibrod::app {

/// Prints "ibrod: error: …" (unless print is false) and returns the exit status for e.
inline int report_error(const std::exception& e, bool print = true) {
  // never a bare "std::bad_alloc": say what ran out and what to do
  if (dynamic_cast<const std::bad_alloc*>(&e)) {
    if (print)
      std::fprintf(stderr,
                   "ibrod: error: out of memory (std::bad_alloc): the run needs more memory than "
                   "this process may allocate; `ibrod check` prints the memory estimate (lower "
                   "grid.n or rod.base_pairs, or raise the limit)\n");
    return 3;
  }
  if (print) std::fprintf(stderr, "ibrod: error: %s\n", e.what());
  if (dynamic_cast<const ConfigError*>(&e)) return 2;
  if (dynamic_cast<const RunError*>(&e)) return 3;
  return 1;
}

}  // namespace ibrod::app
