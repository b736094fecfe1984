#include "driver/mpi_env.hpp"

#include <functional>
#include <stdexcept>

#include "core/error.hpp"

#include <cstdlib>

#ifdef IBROD_MPI
#include <mpi.h>
#endif

namespace ibrod::driver::mpi {

bool available() {
#ifdef IBROD_MPI
  return true;
#else
  return false;
#endif
}

bool launched() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
}

World init([[maybe_unused]] int* argc, [[maybe_unused]] char*** argv) {
  World w;
#ifdef IBROD_MPI
  if (!launched()) return w;
  int already = 0;
  MPI_Initialized(&already);
  if (!already) {
    MPI_Init(argc, argv);
    w.initialized = true;
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &w.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &w.size);
#endif
  return w;
}

long long sum(long long v) {
#ifdef IBROD_MPI
  int on = 0;
  MPI_Initialized(&on);
  if (on) {
    long long out = 0;
    MPI_Allreduce(&v, &out, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    return out;
  }
#endif
  return v;
}

long long max(long long v) {
#ifdef IBROD_MPI
  int on = 0;
  MPI_Initialized(&on);
  if (on) {
    long long out = 0;
    MPI_Allreduce(&v, &out, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    return out;
  }
#endif
  return v;
}

long long broadcast(long long v) {
#ifdef IBROD_MPI
  int on = 0;
  MPI_Initialized(&on);
  if (on) MPI_Bcast(&v, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
#endif
  return v;
}

std::string broadcast(const std::string& s) {
#ifdef IBROD_MPI
  int on = 0;
  MPI_Initialized(&on);
  if (on) {
    long long len = broadcast(static_cast<long long>(s.size()));
    std::string out = s;
    out.resize(std::size_t(len));
    MPI_Bcast(out.data(), int(len), MPI_CHAR, 0, MPI_COMM_WORLD);
    return out;
  }
#endif
  return s;
}

void finalize([[maybe_unused]] const World& w) {
#ifdef IBROD_MPI
  if (w.initialized) MPI_Finalize();
#endif
}

// Under MPI (ranks > 1) rank 0 alone writes files. What it writes may fail (disk full, an
// output directory in the way) while the other ranks carry on into the next collective and wait
// forever: on_root runs f on rank 0 only and then every rank throws what rank 0 threw (the same
// type, ConfigError, RunError or std::runtime_error, and message), so that all ranks stop at the
// same point with the same exit status. One broadcast per call; without MPI it is f().

void on_root(int rank, int ranks, const std::function<void()>& f) {
  if (ranks <= 1) {
    f();
    return;
  }
  long long kind = 0;
  std::string what;
  if (rank == 0) {
    try {
      f();
    } catch (const ConfigError& e) {
      kind = 2;
      what = e.what();
    } catch (const RunError& e) {
      kind = 3;
      what = e.what();
    } catch (const std::exception& e) {
      kind = 1;
      what = e.what();
    }
  }
  kind = broadcast(kind);
  if (kind == 0) return;
  what = broadcast(what);
  if (kind == 2) throw ConfigError(what);
  if (kind == 3) throw RunError(what);
  throw std::runtime_error(what);
}

}  // namespace ibrod::driver::mpi
