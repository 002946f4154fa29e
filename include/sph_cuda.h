/* SPDX-License-Identifier: MIT */
/*
 * sph_cuda.h - the zero-copy tier of the sph library for worlds on the CUDA backend.
 *
 * Lets a CUDA application read a world's particles where they live (device memory) and order
 * its own GPU work against the world's, without copies through the host. Optional: nothing
 * in sph_c.h needs it. C99; CUDA types cross as void* (cudaStream_t, cudaEvent_t) and
 * uint64_t (device addresses), so this header compiles without the CUDA toolkit.
 *
 * Every call here returns SPH_ERROR_UNSUPPORTED for a world on the CPU backend and in a
 * library built without CUDA. The thread rules of sph_c.h apply: a world is used from one
 * thread at a time (a concurrent call returns SPH_ERROR_WORLD_LOCKED). A world whose device
 * reported a sticky error returns SPH_ERROR_DEVICE_LOST from every call.
 *
 * Ordering: sph_world_step and the particle calls of sph_c.h return once their device work
 * is done, so data read after they return is complete. To overlap with the world's work, or
 * to make the world wait for yours, use sph_cuda_world_record_event and
 * sph_cuda_world_wait_event with events you create on the world's device, or begin a step on
 * your own stream (sph_cuda_world_step_begin_on_stream).
 */
#ifndef SPH_CUDA_H
#define SPH_CUDA_H

#include <stddef.h>
#include <stdint.h>

#include "sph_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Where one attribute of a world lives in device memory. Particle i's element starts at
 * device_address + i * stride (bytes) for i in [0, count), in the world's current order (the
 * order sph_world_copy_attribute uses; SPH_ATTRIBUTE_ID gives each particle's id).
 *   POSITION, VELOCITY: 3 x float32 (element_size 12) inside 16-byte records (stride 16);
 *                       the fourth float of the record is internal and may change.
 *   PRESSURE:           float32 (element_size 4), stride 16.
 *   DENSITY:            float32, stride 4.       ID: uint32, stride 4.
 * The address and layout stay valid until the world's capacity grows (a world with
 * sph_world_def.max_capacity above its capacity reallocates its particles when a spawn, fill or
 * source needs room: sph_stats.capacity_growths counts it, and the epoch changes; a fixed world
 * never moves them), and sph_world_restore or sph_mpi_world_restore_file replaces them (the
 * epoch then moves past every earlier one): take the view again after any call that may add
 * particles or restore. The
 * contents are those of data epoch `epoch`: every call that changes particles (spawn, fill, step, also a step
 * that failed and rolled back) increments the world's epoch and rewrites them in place; compare with
 * sph_cuda_world_get_epoch. The memory is the world's: read it, never write or free it.
 */
typedef struct sph_cuda_attribute_view {
  uint32_t struct_size;    /* sizeof(sph_cuda_attribute_view), set by the init function */
  sph_attribute attribute; /* the attribute described (written by the call) */
  uint64_t device_address; /* CUdeviceptr / void* on the device of device_ordinal */
  uint64_t stride;         /* bytes between consecutive particles */
  uint32_t element_size;   /* bytes of one element: 12 or 4 */
  uint32_t count;          /* particles in the world at this epoch */
  uint64_t epoch;          /* the world's data epoch when the view was taken */
  int32_t device_ordinal;  /* the CUDA device that holds the memory */
  uint32_t reserved0;      /* 0 */
} sph_cuda_attribute_view;
SPH_STATIC_ASSERT(sizeof(sph_cuda_attribute_view) == 48, sph_cuda_attribute_view_size);

/** Zeroes *view and sets struct_size (size = sizeof(*view)). Prefer sph_cuda_attribute_view_init. */
SPH_API sph_result SPH_CALL sph_cuda_attribute_view_init_sized(sph_cuda_attribute_view* view, uint32_t size);
static inline sph_result sph_cuda_attribute_view_init(sph_cuda_attribute_view* view) {
  return sph_cuda_attribute_view_init_sized(view, (uint32_t)sizeof(*view));
}

/**
 * Describes where `attribute` lives (see sph_cuda_attribute_view). out->struct_size must be
 * set (sph_cuda_attribute_view_init); only that many bytes are written. Non-blocking.
 * Errors: INVALID_HANDLE, INVALID_ARGUMENT (out NULL), VERSION_MISMATCH (struct_size too
 * small), UNSUPPORTED (unknown attribute, CPU world, no CUDA build), DEVICE_LOST, WORLD_LOCKED.
 */
SPH_API sph_result SPH_CALL sph_cuda_world_get_attribute(const sph_world* world, sph_attribute attribute,
                                                         sph_cuda_attribute_view* out);

/**
 * The world's data epoch: starts at 1 and increments on every call that changes particles (a
 * restore sets it past every epoch the world had).
 * A view whose epoch equals it describes the current contents. Non-blocking.
 * Errors: INVALID_HANDLE, INVALID_ARGUMENT (NULL), UNSUPPORTED, DEVICE_LOST, WORLD_LOCKED.
 */
SPH_API sph_result SPH_CALL sph_cuda_world_get_epoch(const sph_world* world, uint64_t* out_epoch);

/** The CUDA device the world runs on. Errors: as sph_cuda_world_get_epoch. */
SPH_API sph_result SPH_CALL sph_cuda_world_get_device(const sph_world* world, int32_t* out_device_ordinal);

/**
 * The world's own stream (a cudaStream_t, non-blocking with respect to the legacy default
 * stream), on which all its device work runs. It is owned by the world and destroyed with
 * it: enqueue work on it (it then runs before the world's next work), never destroy it.
 * Errors: as sph_cuda_world_get_epoch.
 */
SPH_API sph_result SPH_CALL sph_cuda_world_get_stream(const sph_world* world, void** out_stream);

/**
 * Records `event` (a cudaEvent_t the caller created on the world's device and still owns)
 * on the world's stream: it completes when all the world's device work enqueued so far has.
 * Non-blocking. Errors: INVALID_HANDLE, INVALID_ARGUMENT (event NULL), UNSUPPORTED,
 * DEVICE (CUDA refused the event, e.g. one from another device), DEVICE_LOST, WORLD_LOCKED.
 */
SPH_API sph_result SPH_CALL sph_cuda_world_record_event(sph_world* world, void* event);

/**
 * Makes the world's later device work wait for `event` (a cudaEvent_t the caller recorded on
 * its own stream): e.g. a kernel of the caller that must finish before the next step.
 * Non-blocking. Errors: as sph_cuda_world_record_event.
 */
SPH_API sph_result SPH_CALL sph_cuda_world_wait_event(sph_world* world, void* event);

/**
 * sph_world_step_begin ordered on the caller's CUDA stream `stream` (a cudaStream_t on the
 * world's device; NULL: the legacy default stream): the frame's device work runs after the work
 * enqueued on `stream` before this call, and work the caller enqueues on `stream` after this
 * call returns runs after the frame's device work. So an engine can enqueue its own kernels
 * that read the world's device buffers (sph_cuda_world_get_attribute) right behind the step,
 * and draw them, without the host waiting for the GPU.
 *
 * Returns once the frame's device work is enqueued: at once for a frame the world runs as one
 * device graph, but only after the frame has run for a frame the host drives substep by substep
 * (frames with sinks or a step budget). As after sph_world_step_begin, the world is held
 * until sph_world_step_wait, which must be called and reports the step's result. If the step
 * fails (non-finite state, a crowded cell), the caller's stream may already have read the
 * failed frame's particles: the world then rolls back, sph_world_step_wait reports the error,
 * and the data epoch tells (sph_cuda_world_get_epoch).
 * Errors: INVALID_HANDLE, INVALID_ARGUMENT (frame_dt not positive and finite), UNSUPPORTED (CPU
 * world, no CUDA build), DEVICE (CUDA refused the stream, e.g. one of another device),
 * DEVICE_LOST, WORLD_LOCKED (a step is pending or another call holds the world), OUT_OF_HOST_MEMORY
 * (no thread for the step). On error nothing was started.
 */
SPH_API sph_result SPH_CALL sph_cuda_world_step_begin_on_stream(sph_world* world, float frame_dt,
                                                                void* stream);

/* ---- the engine's device allocator --------------------------------------------------------- */

/**
 * The engine's device allocator (docs/embedding.md, "Memory"). alloc_fn returns `size` bytes
 * (never 0) of device memory on device_ordinal, aligned to at least 256 bytes (as cudaMalloc
 * gives), or NULL when it has none (the call then fails with SPH_ERROR_OUT_OF_DEVICE_MEMORY and
 * the world is unchanged). free_fn gives back memory that alloc_fn returned, with its size and
 * device. The library calls them with that device current, from the thread inside an sph_
 * call on the context (for sph_world_step_begin: the world's step thread), so several worlds
 * on several threads may call them at once: they must be thread-safe. The memory must stay
 * valid until freed (stream-ordered pools: free it only after the device's work is done).
 */
typedef void*(SPH_CALL* sph_cuda_alloc_fn)(size_t size, int32_t device_ordinal, void* user_context);
typedef void(SPH_CALL* sph_cuda_free_fn)(void* device_memory, size_t size, int32_t device_ordinal,
                                         void* user_context);

typedef struct sph_cuda_allocator {
  uint32_t struct_size;       /* sizeof(sph_cuda_allocator), set by the init function */
  uint32_t reserved0;         /* must be 0 */
  sph_cuda_alloc_fn alloc_fn; /* both or neither; NULL (default): cudaMalloc / cudaFree */
  sph_cuda_free_fn free_fn;
  void* user_context; /* passed to alloc_fn and free_fn */
} sph_cuda_allocator;
SPH_STATIC_ASSERT(sizeof(sph_cuda_allocator) == 8 + 3 * sizeof(void*), sph_cuda_allocator_size);

/** Zeroes *allocator and sets struct_size (size = sizeof(*allocator)). */
SPH_API sph_result SPH_CALL sph_cuda_allocator_init_sized(sph_cuda_allocator* allocator, uint32_t size);
static inline sph_result sph_cuda_allocator_init(sph_cuda_allocator* allocator) {
  return sph_cuda_allocator_init_sized(allocator, (uint32_t)sizeof(*allocator));
}

/**
 * Makes every device allocation of the context's worlds (particle arrays, grids, sort and
 * reduction scratch, SDF grids and boundary maps, probes, loads) go through `allocator`; NULL
 * or a zeroed allocator goes back to cudaMalloc. Set it before the context has any world or
 * SDF asset: it cannot change under memory already taken. Page-locked host staging buffers
 * (cudaMallocHost) and CUDA's own allocations (graphs, streams, events, the runtime's context)
 * do not go through it. Thread-safe.
 * Errors: INVALID_HANDLE, INVALID_ARGUMENT (one of alloc_fn / free_fn without the other,
 * reserved0 not 0; the message names it), VERSION_MISMATCH, UNSUPPORTED (a CPU context or a
 * build without CUDA), BUSY (the context has worlds or SDF assets).
 */
SPH_API sph_result SPH_CALL sph_cuda_context_set_allocator(sph_context* context,
                                                           const sph_cuda_allocator* allocator);

#ifdef __cplusplus
}
#endif

#endif /* SPH_CUDA_H */
