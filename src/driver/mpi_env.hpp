#pragma once
// Optional MPI (CMake finds it: IBROD_MPI is defined and ibrod_io links MPI::MPI_CXX). ibrod
// initialises MPI only when started by a launcher (`mpirun -np K ibrod …`), so that a plain
// `ibrod run`, and every run a sweep spawns, stays a one-process program without MPI.
// Without IBROD_MPI every function here is the one-rank answer.
#include <functional>
#include <string>

namespace ibrod::driver::mpi {

/// true if built with MPI (IBROD_MPI).
bool available();
/// true if the environment says a launcher started this process (OMPI_COMM_WORLD_SIZE,
/// PMI_SIZE or PMIX_RANK set).
bool launched();

struct World {
  int rank = 0;
  int size = 1;
  bool initialized = false;  ///< this call ran MPI_Init (finalize() must follow)
};

/// MPI_Init when available() and launched() (and not yet initialised); rank and size of
/// MPI_COMM_WORLD. Otherwise rank 0 of 1.
World init(int* argc, char*** argv);
/// Sum of v over the ranks (v itself without MPI).
long long sum(long long v);
/// Maximum of v over the ranks.
long long max(long long v);
/// rank 0's v on every rank (v itself without MPI).
long long broadcast(long long v);
/// rank 0's s on every rank (s itself without MPI).
std::string broadcast(const std::string& s);
/// Runs f on rank 0 only; then every rank throws what rank 0 threw (ConfigError, RunError or
/// std::runtime_error, with its message), so that all ranks stop at the same point with the same
/// exit status (rank 0 alone writes files: a full disk must not leave the others waiting in the
/// next collective). One broadcast per call; with one rank it is f().
void on_root(int rank, int ranks, const std::function<void()>& f);
/// MPI_Finalize if init() initialised MPI.
void finalize(const World& w);

}  // namespace ibrod::driver::mpi
