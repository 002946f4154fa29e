// SPDX-License-Identifier: MIT
// DistributedMaker: the world of a SceneRuntime made distributed (sph_mpi.h) over an MPI
// communicator, every rank building the same scene; rank 0 adds every fluid body's particles,
// so ids are numbered as an undivided world of the same scene numbers them.
#ifndef SPH_TOOLS_DISTRIBUTED_MAKER_H
#define SPH_TOOLS_DISTRIBUTED_MAKER_H

#include <cstdint>

#include "scene_runtime.h"
#include "sph_mpi.h"

namespace sph_tools {

class DistributedMaker : public SceneRuntime::WorldMaker {
 public:
  // comm: the communicator's Fortran handle (MPI_Comm_c2f); rank: this rank in it.
  DistributedMaker(int32_t comm, int rank) : comm_(comm), rank_(rank) {}

  // COLLECTIVE (sph_mpi_world_create).
  sph_result create_world(sph_context* context, const sph_world_def* def, sph_world** out) override {
    return sph_mpi_world_create(context, def, comm_, nullptr, out);
  }
  // COLLECTIVE: every rank holds the same arrays (the same scene); rank 0's are added, each
  // particle moves to the rank of its slab in the next step.
  sph_result add_particles(sph_world* world, const float* positions, const float* velocities,
                           uint32_t count) override {
    return sph_mpi_world_add_particles(world, positions, velocities, rank_ == 0 ? count : 0u, nullptr);
  }

 private:
  int32_t comm_;
  int rank_;
};

}  // namespace sph_tools

#endif
