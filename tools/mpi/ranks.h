// SPDX-License-Identifier: MIT
// The communicator sph-run-mpi runs on, and the end of a run that one rank alone cannot go on
// with.
#ifndef SPH_TOOLS_RANKS_H
#define SPH_TOOLS_RANKS_H

#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "exit_codes.h"

namespace sph_tools {

struct Ranks {
  MPI_Comm comm = MPI_COMM_WORLD;
  int rank = 0, count = 1;
};

// A failure of this rank alone (its files): the others would wait for it in the next
// collective call, so the run ends here for all.
[[noreturn]] inline void abort_run(const Ranks& r, const std::string& message) {
  std::fprintf(stderr, "sph-run-mpi: rank %d: %s\n", r.rank, message.c_str());
  std::fflush(stderr);
  MPI_Abort(r.comm, kExitRuntime);
  std::_Exit(kExitRuntime);
}

}  // namespace sph_tools

#endif
