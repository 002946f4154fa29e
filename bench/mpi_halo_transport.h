/* SPDX-License-Identifier: MIT */
/* bench/mpi_halo's window on a distributed world's transport (issue 19): the wall time a rank
 * spends inside its MPI calls, per call and per stage of the last step. Not the library's API:
 * mpi_halo links the library's objects (sph_internal and sph_mpi_objects) instead of libsph_mpi,
 * so these read the internals (mpi_halo_transport.cpp) and libsph_mpi exports nothing more. */
#ifndef MPI_HALO_TRANSPORT_H
#define MPI_HALO_TRANSPORT_H

#include <stdint.h>

#include "sph_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/* src/core/rank_transport.h's TransportCall, in its order. */
#define MPI_HALO_CALL_COUNT 8
/* src/core/distributed.h's HaloPhase, in its order. */
#define MPI_HALO_PHASE_COUNT 8

typedef struct mpi_halo_transport {
  /* Since the world was made, in the transport's calls by kind (mpi_halo_call_name). */
  uint64_t calls[MPI_HALO_CALL_COUNT];
  double ms[MPI_HALO_CALL_COUNT];
  double total_ms;
  /* Of the last step's stage_ms (sph_stats), the time inside the transport's calls and, of that,
   * the waits at the barriers mpi_halo_wait_at_barriers puts before them. */
  float stage_ms[SPH_STAGE_COUNT];
  float stage_wait_ms[SPH_STAGE_COUNT];
  /* A CPU rank's hash+sort stage in its parts since the world was made (mpi_halo_phase_name;
   * zero on a CUDA rank). */
  double phase_ms[MPI_HALO_PHASE_COUNT];
} mpi_halo_transport;

/* 0, or -1 where `world` is not a distributed world. */
int mpi_halo_transport_read(const sph_world* world, mpi_halo_transport* out);
/* Every rank, before the same step: each call of the transport waits at a timed MPI_Barrier
 * first (MpiTransport::wait_at_barriers). 0, or -1 as above. */
int mpi_halo_wait_at_barriers(const sph_world* world);
const char* mpi_halo_call_name(int call);
const char* mpi_halo_phase_name(int phase);

#ifdef __cplusplus
}
#endif

#endif
