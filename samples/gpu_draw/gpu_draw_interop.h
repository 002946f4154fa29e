// SPDX-License-Identifier: MIT
/* The zero-copy half of gpu_draw: a GL vertex buffer registered with CUDA, filled from a CUDA
 * world's device buffers (sph_cuda.h) by a kernel on the sample's own stream, ordered against
 * the world's stream with events both ways. No particle crosses the host. */
#ifndef SPH_SAMPLE_GPU_DRAW_INTEROP_H
#define SPH_SAMPLE_GPU_DRAW_INTEROP_H

#include <stdint.h>

#include "sph_c.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct draw_interop draw_interop;

/* Registers the GL buffer `gl_buffer` (capacity particle_vertex) with CUDA on the current
 * device (cudaGraphicsGLRegisterBuffer, write-discard: every fill rewrites what it draws), and
 * creates the sample's stream and events. The GL context that owns the buffer must be current
 * on this thread and live on the current CUDA device. Returns 0, or 1 with the reason on stderr. */
int draw_interop_create(unsigned gl_buffer, uint32_t capacity, draw_interop** out);

/* Fills the buffer with the world's particles as they are now (between sph_world_step_wait and
 * the next sph_world_step_begin):
 *   1. map the buffer on the sample's stream (GL work already issued on it comes first);
 *   2. make that stream wait for the world's device work (sph_cuda_world_record_event);
 *   3. the kernel: positions and velocities (sph_cuda_world_get_attribute) to particle_vertex;
 *   4. unmap (GL work issued after this waits for the kernel);
 *   5. make the world's next device work wait for the kernel (sph_cuda_world_wait_event), so
 *      the next step cannot overwrite the positions while the kernel still reads them.
 * Nothing waits on the host. *out_count receives the vertices written. Returns 0 or 1. */
int draw_interop_fill(draw_interop* interop, sph_world* world, uint32_t* out_count);

/* Unregisters the buffer (before the GL context goes) and frees the stream and events. */
void draw_interop_destroy(draw_interop* interop);

#ifdef __cplusplus
}
#endif

#endif
