#include "fluid/fftw_wisdom.hpp"

#include <fftw3.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <system_error>

namespace ibrod::fluid {
namespace {

// Threaded solvers must be registered before wisdom that names them is read: FFTW asks for
// fftw_init_threads before any other call. Once per process (FFTW ≥ 3.3 keeps its own guard too).
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

std::string wisdom_text() {
  if (!init_threads()) return {};
  char* text = fftw_export_wisdom_to_string();
  if (!text) return {};
  std::string out(text);
  std::free(text);
  return out;
}

std::string wisdom_cache_path() {
  if (const char* p = std::getenv("IBROD_FFTW_WISDOM_CACHE")) return p;  // "" disables
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
    return std::string(x) + "/ibrod/fftw-wisdom";
  if (const char* h = std::getenv("HOME"); h && *h)
    return std::string(h) + "/.cache/ibrod/fftw-wisdom";
  return {};
}

void save_wisdom_cache(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  // write then rename: concurrent processes never see a half-written file
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  if (export_wisdom(tmp)) fs::rename(tmp, path, ec);
  if (ec || fs::exists(tmp, ec)) fs::remove(tmp, ec);
}

void init_fftw_threads() {
  if (!init_threads()) throw std::runtime_error("FFTW: fftw_init_threads failed");
}

bool plan_with_wisdom(bool measure, unsigned flags, const std::function<bool(unsigned)>& make) {
  if (!measure) return make(flags | FFTW_ESTIMATE);
  flags |= FFTW_MEASURE;
  if (make(flags | FFTW_WISDOM_ONLY)) return true;
  const std::string cache = wisdom_cache_path();
  if (!cache.empty()) import_wisdom(cache);
  if (make(flags | FFTW_WISDOM_ONLY)) return true;
  if (!make(flags)) return false;
  if (!cache.empty()) save_wisdom_cache(cache);
  return true;
}

}  // namespace ibrod::fluid
