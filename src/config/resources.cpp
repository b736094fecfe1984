#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include "config/config.hpp"
#include "config/detail.hpp"

// What the machine lets this process allocate, compared with what a run needs, before anything
// is allocated (issue 13 item 7: a grid too large for the memory ended in a bare std::bad_alloc).
namespace ibrod::config {

namespace {

constexpr double MiB = 1 << 20;

// Pages of this process from /proc/self/statm: field 0 the whole address space, field 5 data +
// stack (what RLIMIT_AS and RLIMIT_DATA count); 0 where unknown.
double statm_bytes(int field) {
  std::ifstream in("/proc/self/statm");
  double v = 0;
  for (int i = 0; i <= field && (in >> v); ++i) {
  }
  return in ? v * double(::sysconf(_SC_PAGESIZE)) : 0;
}

// The cgroup v2 memory.max of this process (containers, systemd slices), or 0 if none.
double cgroup_max_bytes() {
  std::ifstream cg("/proc/self/cgroup");
  std::string line;
  while (std::getline(cg, line)) {
    if (line.rfind("0::", 0) != 0) continue;
    std::ifstream mx("/sys/fs/cgroup" + line.substr(3) + "/memory.max");
    double v = 0;
    if (mx >> v) return v;  // "max" reads as no number
  }
  return 0;
}

void lower(double& best, std::string* why, double v, const char* name) {
  if (v > 0 && v < best) {
    best = v;
    if (why) *why = name;
  }
}

}  // namespace

double memory_available_bytes(std::string* why) {
  double best = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE));
  if (why) *why = "physical memory";
  if (!(best > 0)) best = 1e300;
  lower(best, why, cgroup_max_bytes(), "the cgroup's memory.max");
  rlimit r{};
  if (::getrlimit(RLIMIT_AS, &r) == 0 && r.rlim_cur != RLIM_INFINITY)
    lower(best, why, std::max(1.0, double(r.rlim_cur) - statm_bytes(0)),
          "RLIMIT_AS (ulimit -v) less the address space in use");
  if (::getrlimit(RLIMIT_DATA, &r) == 0 && r.rlim_cur != RLIM_INFINITY)
    lower(best, why, std::max(1.0, double(r.rlim_cur) - statm_bytes(5)),
          "RLIMIT_DATA (ulimit -d) less the data in use");
  return best;
}

void check_memory(const Config& c, int ranks) {
  std::string why;
  const double need = memory_estimate_bytes(c, ranks);
  const double have = memory_available_bytes(&why);
  if (need <= have) return;
  // blame the rod only when it, not the grid, is what does not fit
  const bool rod = 400.0 * c.rod_base_pairs > 0.5 * need;
  detail::bad(rod ? "rod.base_pairs" : "grid.n", std::to_string(rod ? c.rod_base_pairs : c.grid_n),
              "a run that fits in memory: it needs about " + detail::fmt(std::ceil(need / MiB)) +
                  " MiB (ibrod check: memory estimate) but this process may allocate " +
                  detail::fmt(std::floor(have / MiB)) + " MiB (" + why + ")");
}

}  // namespace ibrod::config
