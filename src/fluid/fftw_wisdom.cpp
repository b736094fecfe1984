#include "fluid/fftw_wisdom.hpp"

#include <fftw3.h>

#include <mutex>

namespace ibrod::fluid {
namespace {

// Threaded solvers must be registered before wisdom that names them is read: FFTW asks for
// fftw_init_threads before any other call. It is idempotent (FFTW ≥ 3.3 keeps a guard), so the
// FluidSolver constructor calling it again is harmless.
bool init_threads() {
  static std::once_flag once;
  static bool ok = false;
  std::call_once(once, [] { ok = fftw_init_threads() != 0; });
  return ok;
}

}  // namespace

bool import_wisdom(const std::string& path) {
  return init_threads() && fftw_import_wisdom_from_filename(path.c_str()) != 0;
}

bool export_wisdom(const std::string& path) {
  return init_threads() && fftw_export_wisdom_to_filename(path.c_str()) != 0;
}

}  // namespace ibrod::fluid
