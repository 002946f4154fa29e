// SPDX-License-Identifier: MIT
#include "gpu_draw_interop.h"

// clang-format off
#include <GL/gl.h> /* before cuda_gl_interop.h, which on aarch64 asks for GL's types first */
#include <cuda_gl_interop.h>
// clang-format on
#include <cuda_runtime.h>

#include <cstdio>
#include <new>

#include "particle_vertex.h"
#include "sph_cuda.h"

struct draw_interop {
  cudaGraphicsResource_t resource = nullptr;
  cudaStream_t stream = nullptr;
  cudaEvent_t world_done = nullptr; /* recorded on the world's stream, waited on ours */
  cudaEvent_t fill_done = nullptr;  /* recorded on ours, waited on by the world */
  uint32_t capacity = 0;
};

namespace {

bool cuda_failed(cudaError_t e, const char* what) {
  if (e == cudaSuccess) return false;
  std::fprintf(stderr, "gpu_draw: %s failed: %s\n", what, cudaGetErrorString(e));
  return true;
}

bool sph_failed(sph_result r, const char* what) {
  if (r >= 0) return false;
  std::fprintf(stderr, "gpu_draw: %s failed: %s\n  %s\n", what, sph_result_string(r), sph_get_last_error());
  return true;
}

/* One thread a particle: the 16-byte position record (x, y, z, internal) and the velocity
 * record give one vertex. The records are read as float4 (their stride is 16). */
__global__ void fill_vertices(const float4* __restrict__ positions, const float4* __restrict__ velocities,
                              uint32_t count, particle_vertex* __restrict__ vertices) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= count) return;
  const float4 x = positions[i];
  const float4 v = velocities[i];
  particle_vertex out;
  out.x = x.x;
  out.y = x.y;
  out.z = x.z;
  out.rgba = particle_vertex_colour(v.x, v.y, v.z);
  vertices[i] = out;
}

}  // namespace

extern "C" int draw_interop_create(unsigned gl_buffer, uint32_t capacity, draw_interop** out) {
  *out = nullptr;
  draw_interop* d = new (std::nothrow) draw_interop;
  if (!d) return 1;
  d->capacity = capacity;
  if (cuda_failed(
          cudaGraphicsGLRegisterBuffer(&d->resource, gl_buffer, cudaGraphicsRegisterFlagsWriteDiscard),
          "cudaGraphicsGLRegisterBuffer") ||
      cuda_failed(cudaStreamCreateWithFlags(&d->stream, cudaStreamNonBlocking),
                  "cudaStreamCreateWithFlags") ||
      cuda_failed(cudaEventCreateWithFlags(&d->world_done, cudaEventDisableTiming), "cudaEventCreate") ||
      cuda_failed(cudaEventCreateWithFlags(&d->fill_done, cudaEventDisableTiming), "cudaEventCreate")) {
    draw_interop_destroy(d);
    return 1;
  }
  *out = d;
  return 0;
}

extern "C" int draw_interop_fill(draw_interop* d, sph_world* world, uint32_t* out_count) {
  sph_cuda_attribute_view positions, velocities;
  sph_cuda_attribute_view_init(&positions);
  sph_cuda_attribute_view_init(&velocities);
  *out_count = 0;
  if (sph_failed(sph_cuda_world_get_attribute(world, SPH_ATTRIBUTE_POSITION, &positions), "get_attribute") ||
      sph_failed(sph_cuda_world_get_attribute(world, SPH_ATTRIBUTE_VELOCITY, &velocities), "get_attribute"))
    return 1;
  if (positions.stride != sizeof(float4) || velocities.stride != sizeof(float4)) {
    std::fprintf(stderr, "gpu_draw: position/velocity stride %llu/%llu, the kernel reads 16-byte records\n",
                 (unsigned long long)positions.stride, (unsigned long long)velocities.stride);
    return 1;
  }
  const uint32_t count = positions.count < d->capacity ? positions.count : d->capacity;

  void* mapped = nullptr;
  size_t mapped_bytes = 0;
  if (cuda_failed(cudaGraphicsMapResources(1, &d->resource, d->stream), "cudaGraphicsMapResources")) return 1;
  bool failed = cuda_failed(cudaGraphicsResourceGetMappedPointer(&mapped, &mapped_bytes, d->resource),
                            "cudaGraphicsResourceGetMappedPointer");
  if (!failed && mapped_bytes < count * sizeof(particle_vertex)) {
    std::fprintf(stderr, "gpu_draw: the mapped buffer has %zu bytes, %u vertices need more\n", mapped_bytes,
                 count);
    failed = true;
  }
  /* The world's work so far (the step that wrote the positions) before the kernel. */
  failed = failed ||
           sph_failed(sph_cuda_world_record_event(world, d->world_done), "sph_cuda_world_record_event") ||
           cuda_failed(cudaStreamWaitEvent(d->stream, d->world_done, 0), "cudaStreamWaitEvent");
  if (!failed && count > 0) {
    const unsigned block = 256;
    fill_vertices<<<(count + block - 1) / block, block, 0, d->stream>>>(
        reinterpret_cast<const float4*>(positions.device_address),
        reinterpret_cast<const float4*>(velocities.device_address), count,
        static_cast<particle_vertex*>(mapped));
    failed = cuda_failed(cudaGetLastError(), "fill_vertices");
  }
  /* Unmap even after a failure: a mapped buffer may not be drawn or unregistered. */
  failed =
      cuda_failed(cudaGraphicsUnmapResources(1, &d->resource, d->stream), "cudaGraphicsUnmapResources") ||
      failed;
  /* The kernel before the world's next work (the next step rewrites the positions in place). */
  failed = failed || cuda_failed(cudaEventRecord(d->fill_done, d->stream), "cudaEventRecord") ||
           sph_failed(sph_cuda_world_wait_event(world, d->fill_done), "sph_cuda_world_wait_event");
  if (failed) return 1;
  *out_count = count;
  return 0;
}

extern "C" void draw_interop_destroy(draw_interop* d) {
  if (!d) return;
  if (d->stream) cudaStreamSynchronize(d->stream);
  if (d->resource) cudaGraphicsUnregisterResource(d->resource);
  if (d->fill_done) cudaEventDestroy(d->fill_done);
  if (d->world_done) cudaEventDestroy(d->world_done);
  if (d->stream) cudaStreamDestroy(d->stream);
  delete d;
}
