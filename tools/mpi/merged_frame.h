// SPDX-License-Identifier: MIT
// Every rank's particles of a distributed world as one frame on rank 0, ordered by id: what an
// undivided world's frame holds, so the merged files read as sph-run's.
#ifndef SPH_TOOLS_MERGED_FRAME_H
#define SPH_TOOLS_MERGED_FRAME_H

#include <mpi.h>

#include "particle_frame.h"
#include "sph_mpi.h"

namespace sph_tools {

// COLLECTIVE over `comm` (the world's communicator). `own` holds this rank's particles
// (read_particles of this frame). On rank 0, *out gets the world's: positions, velocities and
// ids through sph_mpi_world_gather (by id), density, pressure and the user attribute matched
// to them by id from every rank's `own` (sph_mpi_world_gather carries only the first three).
// Other ranks leave *out alone. Throws LibraryError (the gather's code), or std::runtime_error
// when an id of the gather is on no rank (a library fault).
void gather_frame(const sph_world* world, MPI_Comm comm, const ParticleFrame& own, ParticleFrame* out);

}  // namespace sph_tools

#endif
