// SPDX-License-Identifier: MIT
// A distributed world's figures of a frame for sph-run's summary and --stats-json: each rank's
// sph_world_get_stats reads its own particles only (sph_mpi.h), so the ranks reduce theirs into
// the world's. The same reduction carries the interrupt flag, so that every rank learns of a
// Ctrl-C on any rank in the same frame.
#ifndef SPH_TOOLS_WORLD_STATS_H
#define SPH_TOOLS_WORLD_STATS_H

#include <mpi.h>

#include "sph_c.h"

namespace sph_tools {

// COLLECTIVE over `comm`. `own`: this rank's sph_stats of the last step. Returns the world's:
// particle_count and memory_bytes summed over the ranks; density_mean and neighbors_mean
// weighted by each rank's particles; the maxima (max_speed, density_max, neighbors_max, dt_max,
// substeps) and minima (density_min, dt_min) over the ranks that hold particles; stage_ms and
// step_ms the slowest rank's (the ranks wait for each other every substep). The other fields
// are this rank's. *agreed gets the largest of the ranks' `signal` (0: none asked to stop).
sph_stats world_stats(const sph_stats& own, int signal, MPI_Comm comm, int* agreed);

// COLLECTIVE over `comm`: the largest of the ranks' `signal` (0: no rank was asked to stop).
int agreed_signal(int signal, MPI_Comm comm);

}  // namespace sph_tools

#endif
