#pragma once
// sim/Domain.h over MPI (OpenMPI from Debian): `mpirun -np N rend run SCENE`. Built when CMake
// finds MPI (REND_HAVE_MPI); without it, or when the process was not started by mpirun, rend
// runs on one process as always.

#include <memory>
#include <string>

#include "sim/Domain.h"

namespace rend {

/// Starts MPI when this process is one of several that mpirun started, and returns the number
/// of processes (1 otherwise, or without MPI). Call once, first thing in main().
int startProcesses(int& argc, char**& argv);
/// Ends MPI if startProcesses() started it.
void endProcesses();
/// This process's rank, 0 when there is only one.
int processRank();
/// The processes of this run: 1 unless mpirun started several.
int processCount();
/// The MPI library and this run's processes, or why there is none ("not built").
std::string mpiVersion();
/// Ends every process with `code`: one that fails alone must not leave the others waiting.
[[noreturn]] void abortProcesses(int code);
/// The slabs of `bonds` over all processes, with this one's slab. Throws std::invalid_argument
/// when the sheet is too small for them (sim/Domain.h).
std::unique_ptr<sim::Domain> makeMpiDomain(const sim::BondFamilies& bonds);

}  // namespace rend
