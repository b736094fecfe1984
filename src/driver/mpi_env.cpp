#include "driver/mpi_env.hpp"

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
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") ||
         std::getenv("PMIX_RANK");
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

}  // namespace ibrod::driver::mpi
