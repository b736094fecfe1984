#pragma once
// FFTW's process-wide state, shared by FluidSolver and DistributedFluid: its threads, its wisdom
// and the on-disk wisdom cache.
//
// FFTW wisdom: the plans that FFTW_MEASURE chose, saved as text. FFTW_MEASURE times candidate
// algorithms, so two processes may pick different plans for the same grid, and different plans
// round differently. A process that imports the wisdom of another before it constructs its
// FluidSolver makes the same plans, hence bit-for-bit the same velocities (the run driver keeps
// the wisdom of each run in its output directory for `ibrod run --resume`).
#include <functional>
#include <string>

namespace ibrod::fluid {

/// Adds the wisdom in `path` to this process's planner (before any FluidSolver is made).
/// Returns false if the file cannot be read or is not FFTW wisdom.
bool import_wisdom(const std::string& path);

/// Writes all wisdom this process has accumulated to `path`. Returns false on failure.
bool export_wisdom(const std::string& path);

/// On-disk FFTW wisdom cache used by FluidSolver when plan_measure is set: $IBROD_FFTW_WISDOM_CACHE
/// if set (empty: no cache), else $XDG_CACHE_HOME/ibrod/fftw-wisdom, else
/// $HOME/.cache/ibrod/fftw-wisdom ("" if none of them is set).
std::string wisdom_cache_path();
/// The process's FFTW wisdom as text (what export_wisdom writes); "" on failure.
std::string wisdom_text();

/// Writes this process's wisdom to the cache file `path` (its folder made if missing), by a
/// temporary file and a rename, so that concurrent processes never see a half-written file. Best
/// effort: a cache that cannot be written only costs planning time later.
void save_wisdom_cache(const std::string& path);

/// Registers FFTW's threaded solvers, once per process, before any threaded plan is made or any
/// wisdom that names them is read. Throws std::runtime_error if FFTW cannot.
void init_fftw_threads();

/// Makes a set of plans with `make(flags)`, which returns false, having destroyed whatever it
/// made, if a plan fails. measure = false: FFTW_ESTIMATE. Otherwise FFTW_MEASURE, where wisdom
/// already in the process (a resumed run imports its own first) wins, then the on-disk cache
/// (wisdom_cache_path()), and only if that lacks these plans too they are measured and the cache
/// rewritten. Returns make's result.
bool plan_with_wisdom(bool measure, unsigned flags, const std::function<bool(unsigned)>& make);

}  // namespace ibrod::fluid
