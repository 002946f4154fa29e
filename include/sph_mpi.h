/* SPDX-License-Identifier: MIT */
/*
 * sph_mpi.h - distributed worlds: one world spread over the ranks of an MPI communicator.
 *
 * Optional, in its own library (libsph_mpi, built when CMake finds MPI: SPH_WITH_MPI). That
 * library holds the whole of sph_c.h as well, so a program links libsph_mpi instead of libsph
 * (not both). This header needs no mpi.h: the communicator crosses as its Fortran handle
 * (MPI_Fint, from MPI_Comm_c2f(comm)) in an int32_t.
 *
 * A distributed world is an sph_world on every rank of the communicator; each rank holds the
 * particles of its slab of space (cells of one kernel radius along the world's longest axis),
 * plus, during a step, a halo one kernel radius deep from its neighbours. The calls marked
 * COLLECTIVE must be made by every rank of the communicator, in the same order, with the same
 * scalar arguments: sph_mpi_world_create, sph_mpi_world_add_particles, sph_mpi_world_step (and
 * sph_world_step on a distributed world, which is the same call), sph_mpi_world_get_counts,
 * sph_mpi_world_gather, sph_mpi_world_gather_removed_ids, sph_mpi_world_save_file,
 * sph_mpi_world_load_file, sph_mpi_world_restore_file. The scene (colliders, force fields,
 * sources, sinks, probes) is replicated: make the same calls of sph_c.h on every rank. The calls
 * of sph_c.h that read particles (copy_attribute, get_stats, get_removed_ids) read the calling
 * rank's own; collider loads and probe readings are the world's, the same on every rank.
 *
 * What works and what is refused (SPH_ERROR_UNSUPPORTED, naming the feature): docs/distributed.md.
 * A distributed world steps the same bits as one undivided world of the same particles (while
 * the neighbour grid's table covers the particles' extent; docs/distributed.md says when).
 *
 * Thread rules: as sph_c.h, per rank. Failures are agreed between the ranks: when a step, save,
 * load or restore fails on one rank (an allocation, a crowded cell, a non-finite state, a file),
 * every rank returns an error and rolls back (the failing rank its own code and message, the
 * others the first failing rank's code, the message naming that rank), rather than waiting in
 * MPI for it. So is a lost device: a rank whose world answers SPH_ERROR_DEVICE_LOST (a sticky
 * device error, seen by any call on that rank) refuses each later collective call inside the
 * call's first agreement, so every rank returns an error that names the lost device; destroy the
 * world on every rank. What is checked before the world's communicator can be used is not agreed:
 * a NULL or destroyed world (SPH_ERROR_INVALID_HANDLE) or a world in use by another thread of that
 * rank (SPH_ERROR_WORLD_LOCKED) returns at once on that rank while the others wait in MPI for it,
 * as with any MPI collective that some ranks do not call.
 */
#ifndef SPH_MPI_H
#define SPH_MPI_H

#include <stddef.h>
#include <stdint.h>

#include "sph_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Options of a distributed world. Zero-initialised fields mean the defaults. */
typedef struct sph_mpi_world_def {
  uint32_t struct_size; /* sizeof(sph_mpi_world_def), set by the init function */
  /* Rebalance the slabs at a frame's start when the fullest rank holds more than
   * (100 + this) percent of the mean particle count. 0: 20. Range [1, 10000]. */
  uint32_t rebalance_threshold_percent;
} sph_mpi_world_def;
SPH_STATIC_ASSERT(sizeof(sph_mpi_world_def) == 8, sph_mpi_world_def_size);

SPH_API sph_result SPH_CALL sph_mpi_world_def_init_sized(sph_mpi_world_def* def, uint32_t size);
static inline sph_result sph_mpi_world_def_init(sph_mpi_world_def* def) {
  return sph_mpi_world_def_init_sized(def, (uint32_t)sizeof(*def));
}

/**
 * COLLECTIVE. Creates this rank's part of a world spread over the communicator whose Fortran
 * handle is `comm` (MPI_Comm_c2f). MPI must be initialised (MPI_Init) and stay so until every
 * distributed world is destroyed (sph_world_destroy on every rank: it frees the duplicated
 * communicator, which MPI counts as collective). The library duplicates
 * the communicator, so its messages never meet the caller's. `def` as sph_world_create's (the
 * same on every rank); `mpi_def` may be NULL (defaults), its threshold the same on every rank
 * (compared: INVALID_ARGUMENT on every rank otherwise). `context`: a CPU or a CUDA context, of
 * the same backend on every rank. After the communicator's duplication the arguments are checked
 * and the world made inside one agreement: a failure on any rank is every rank's (the others'
 * messages name the failing rank), so no rank waits for another that returned. The world's ids
 * carry rank 0's next world tag on every rank (sph_c.h, "ids of objects inside a world"), so an
 * object made on every rank alike has the same id on every rank.
 * Errors: INVALID_ARGUMENT (NULL out, a bad def or mpi_def, MPI_COMM_NULL or a communicator
 * handle MPI itself refuses, contexts of different backends or rebalance thresholds that differ
 * on two ranks), VERSION_MISMATCH (an mpi_def whose struct_size is not this version's, as every
 * sized struct), INVALID_HANDLE (a NULL or destroyed context), UNSUPPORTED (a
 * feature, solver or integrator that does not work distributed yet, named in the message),
 * OUT_OF_HOST_MEMORY, and a CUDA context's device errors. *out is untouched on error.
 */
SPH_API sph_result SPH_CALL sph_mpi_world_create(sph_context* context, const sph_world_def* def, int32_t comm,
                                                 const sph_mpi_world_def* mpi_def, sph_world** out);

/**
 * COLLECTIVE. Adds `count` particles from this rank (positions and, unless NULL, velocities:
 * 3 x float32 each, packed; count may be 0). Ids are numbered across the ranks in rank order:
 * rank 0's first, so a world whose rank 0 adds everything numbers them as an undivided world
 * would. Particles may be anywhere: each moves to the rank that owns its slab in the next step.
 * All-or-nothing over the ranks: if any rank's particles are refused (INVALID_ARGUMENT as
 * sph_world_spawn's, CAPACITY), every rank returns SPH_ERROR_INVALID_ARGUMENT (the refusing
 * rank its own code, the others' messages naming the lowest refusing rank) and no rank adds
 * any. *out_first_id (may be NULL): this rank's first id. sph_world_spawn and the fills of
 * sph_c.h return UNSUPPORTED on a distributed world.
 */
SPH_API sph_result SPH_CALL sph_mpi_world_add_particles(sph_world* world, const float* positions,
                                                        const float* velocities, uint32_t count,
                                                        uint32_t* out_first_id);

/**
 * COLLECTIVE. Steps the world by frame_dt on every rank; the same codes as sph_world_step. The
 * ranks agree on frame_dt, the world's parameters (sph_world_set_params on each rank) and
 * definition (sph_world_def, capacities aside), the count
 * of each kind of scene object (colliders, sources, sinks, force fields, probes) and the
 * colliders' poses and targets before the frame: a frame_dt refused on one rank, or any of these
 * that differs between the ranks, is INVALID_ARGUMENT on every rank, the world unchanged.
 * sph_world_step_begin and sph_cuda_world_step_begin_on_stream refuse a distributed world
 * (UNSUPPORTED).
 */
SPH_API sph_result SPH_CALL sph_mpi_world_step(sph_world* world, float frame_dt);

/** Counts of a distributed world (sph_mpi_world_get_counts). */
typedef struct sph_mpi_counts {
  uint32_t struct_size;
  int32_t rank;           /* this rank in the world's communicator */
  int32_t rank_count;     /* ranks of the communicator */
  uint32_t local_count;   /* particles this rank holds */
  uint64_t global_count;  /* particles of the whole world */
  uint64_t global_ghosts; /* halo particles of the last substep, summed over the ranks */
  uint64_t migrated;      /* particles that moved between ranks so far, summed over the ranks */
  uint32_t local_ghosts;  /* halo particles this rank held in the last substep */
  uint32_t rebalances;    /* times the slabs were cut anew (the first cut counts) */
  int32_t axis;           /* the slabs' axis: 0 x, 1 y, 2 z */
  /* The cell layers this rank's slab meets, [slab_first, slab_last] along axis, cell k holding
   * floor(x / kernel_radius) = k (INT32_MIN / INT32_MAX: open; first > last: empty). Slabs are
   * cut between sixteenths of a layer, so a neighbour's slab may share an end layer. */
  int32_t slab_first;
  int32_t slab_last;
  uint32_t reserved0;
  /* This rank's slab exactly: the sub-layers [slab_sub_first, slab_sub_last], sub-layer 16 k + j
   * holding the points of layer k whose fraction x / kernel_radius - k lies in [j/16, (j+1)/16)
   * (INT32_MIN / INT32_MAX: open; first > last: empty). */
  int32_t slab_sub_first;
  int32_t slab_sub_last;
} sph_mpi_counts;
SPH_STATIC_ASSERT(sizeof(sph_mpi_counts) == 72, sph_mpi_counts_size);

SPH_API sph_result SPH_CALL sph_mpi_counts_init_sized(sph_mpi_counts* counts, uint32_t size);
static inline sph_result sph_mpi_counts_init(sph_mpi_counts* counts) {
  return sph_mpi_counts_init_sized(counts, (uint32_t)sizeof(*counts));
}

/**
 * COLLECTIVE. Fills *out (initialised by sph_mpi_counts_init) with this rank's and the world's
 * counts. Errors: INVALID_HANDLE, INVALID_ARGUMENT (NULL out), VERSION_MISMATCH (a struct_size
 * that is not this version's: set it with sph_mpi_counts_init), UNSUPPORTED (not a distributed
 * world).
 */
SPH_API sph_result SPH_CALL sph_mpi_world_get_counts(const sph_world* world, sph_mpi_counts* out);

/**
 * COLLECTIVE. Gathers every rank's particles onto rank `root`, ordered by id: positions and
 * velocities (3 x float32 each, packed) and ids (uint32), each array NULL to skip it. On root
 * the arrays hold `capacity` particles; *out_count (may be NULL) gets the world's count there
 * (0 elsewhere); other ranks pass NULL arrays. Errors: INVALID_ARGUMENT (root out of range or
 * not the same on every rank: every rank refuses; on root, capacity below the world's count),
 * UNSUPPORTED (not a distributed world). A rank's
 * own particles read with sph_world_copy_attribute, without the others.
 */
SPH_API sph_result SPH_CALL sph_mpi_world_gather(const sph_world* world, int32_t root, float* positions,
                                                 float* velocities, uint32_t* ids, uint64_t capacity,
                                                 uint64_t* out_count);

/**
 * COLLECTIVE. Gathers the ids every rank's sinks removed in the last step (each rank's
 * sph_world_get_removed_ids, which holds only its own particles) onto rank `root`, in ascending
 * order. On root: writes up to `capacity` ids and sets *out_count to the world's number of removed
 * ids; when root's capacity was too small every rank returns SPH_INCOMPLETE (call again, every
 * rank, with a larger array on root); other ranks may pass NULL ids, capacity 0 and a NULL
 * out_count. Root's argument errors are every rank's. Errors:
 * INVALID_ARGUMENT (root out of range or not the same on every rank: every rank refuses; on root,
 * a NULL out_count, or NULL ids with capacity > 0),
 * UNSUPPORTED (not a distributed world).
 */
SPH_API sph_result SPH_CALL sph_mpi_world_gather_removed_ids(const sph_world* world, int32_t root,
                                                             uint32_t* ids, uint32_t capacity,
                                                             uint32_t* out_count);

/* ---- checkpoints ---------------------------------------------------------------------------
 * A distributed world saves as one checkpoint file per rank (sph_c.h's format, marked as one
 * rank's part: its particles, their sort keys, its copy of the scene) plus a manifest that
 * rank 0 writes last: the rank count, the slabs and counters, the world's particle count, and
 * each rank file's name, size and hash. On the same number of ranks each rank takes its own file
 * back with the saved slabs; on another, each rank takes a block of the saved files (rank p of P
 * the files [p N / P, (p + 1) N / P) of N) and the first frame cuts the slabs anew. Either way
 * the world then steps on bit for bit as the saved world would have. The files are found beside
 * the manifest (the same directory), so the set moves together; every rank must see the manifest
 * and the files it takes (a shared file system, or copies). A rank's
 * file alone is not a world: sph_world_load refuses it (INVALID_ARGUMENT), and sph_world_save and
 * sph_world_restore refuse a distributed world (UNSUPPORTED). */

/**
 * COLLECTIVE. Saves the world at `path` (the same on every rank): each rank writes its file
 * under a staged name, path + ".rank" + its rank + ".staged", atomically as sph_world_save_file
 * does; once every rank has, each renames its file to path + ".rank" + its rank + "." + the
 * file's FNV-1a 64 hash in 16 hex digits (a name no file of the previous set has, unless its
 * bytes are the same), then rank 0 writes the manifest at `path`, atomically: the one step that
 * replaces the set. Then each rank removes its file of the previous set (only names of this
 * form, or the plain path + ".rank" + r that earlier builds wrote). Succeeds or fails on every
 * rank. A save that fails (on any rank), or a crash before the new manifest is in place, leaves
 * the previous set as it was and named by its manifest; a failed save removes the files it
 * wrote, a crash leaves them beside the set (files no manifest names).
 * Errors: INVALID_HANDLE, INVALID_ARGUMENT (NULL or empty path, or another path on another rank,
 * refused before any file is written; a file that cannot be written: the message says which and
 * why), UNSUPPORTED (not a distributed world), WORLD_LOCKED,
 * OUT_OF_HOST_MEMORY; a rank whose own save succeeded returns the failing rank's code.
 */
SPH_API sph_result SPH_CALL sph_mpi_world_save_file(const sph_world* world, const char* path);

/**
 * COLLECTIVE. Creates a distributed world over the communicator `comm` (as sph_mpi_world_create)
 * from the manifest at `path` and the rank files named in it, on any rank count (above). The
 * rebalance threshold is the saved world's. On any error on any rank, no rank creates a world
 * and *out is untouched (the arguments too are checked over the ranks: a NULL out on one rank is
 * every rank's refusal). Errors: INVALID_HANDLE (context), INVALID_ARGUMENT (NULL path or out;
 * another path on another rank; a file that cannot be read; a bad communicator), CORRUPT_DATA (a damaged
 * manifest or rank file, a rank file whose size or hash is not the manifest's, or files of different worlds:
 * the message names the file), CAPACITY (on fewer ranks, the particles a rank takes exceed the world's
 * max_capacity, which is per rank), VERSION_MISMATCH, UNSUPPORTED (a CUDA context), OUT_OF_HOST_MEMORY; a
 * rank that found nothing wrong returns the first failing rank's code.
 */
SPH_API sph_result SPH_CALL sph_mpi_world_load_file(sph_context* context, int32_t comm, const char* path,
                                                    sph_world** out);

/**
 * COLLECTIVE. Replaces the world's whole state with the one saved at `path`, keeping its handle
 * and communicator: afterwards it is as a world sph_mpi_world_load_file made from `path`.
 * All-or-nothing over the ranks: on any error on any rank, every rank's world is unchanged.
 * Errors: as sph_mpi_world_load_file, and INVALID_HANDLE, UNSUPPORTED (not a distributed world),
 * WORLD_LOCKED.
 */
SPH_API sph_result SPH_CALL sph_mpi_world_restore_file(sph_world* world, const char* path);

#ifdef __cplusplus
}
#endif

#endif /* SPH_MPI_H */
