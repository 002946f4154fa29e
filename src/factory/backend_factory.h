// SPDX-License-Identifier: MIT
// The one place that knows which backends exist: picks the CPU or CUDA implementation. It sits
// above the core (which knows a backend only as the interface of core/backend.h) and below the C
// layer, which calls it to make a world's backend; nothing else includes a backend.
#pragma once

#include <memory>

#include "../core/backend.h"
#include "../core/task_system.h"

namespace sph {

enum class BackendKind : uint32_t { Auto = 0, Cpu = 1, Cuda = 2 };

// Number of usable CUDA devices; 0 when the library was built without CUDA or none is present.
int cuda_device_count();
bool cuda_built();

// Resolves Auto to Cpu or Cuda. Throws Error(Unsupported) for Cuda without a device.
BackendKind resolve_backend(BackendKind requested, int device_ordinal);

// Copies caller data given in device memory to the host (CUDA builds only).
void copy_device_to_host(void* host_dst, const void* device_src, size_t bytes, int device_ordinal);

// The CUDA backend's tuning, from sph_context_def's cuda_* fields (read and checked in one place,
// sph_context_create; docs/cuda.md). Zero means the backend's default; no choice changes results.
struct CudaTuning {
  bool stream_frames = false;  // every frame on the stream driver, never as a graph
  uint32_t density_block = 0;  // threads per block of the density kernels (a power of two, 32..1024)
  uint32_t force_block = 0;    // threads per block of the force kernels
  uint32_t particle_lanes =
      0;  // threads per particle of the neighbour passes: 0 (the backend's choice), 1, 2, 4, 8
  bool dfsph_masks = true;   // DFSPH's candidate masks (physics/neighbor_walk.h)
  bool dfsph_lists = false;  // and the solves' neighbour lists, written with them
};

// cpu_tasks: the engine's task system for a CPU backend's loops (none: OpenMP's cpu_workers).
std::unique_ptr<Backend> make_backend(BackendKind kind, const WorldConfig& config, int device_ordinal,
                                      unsigned cpu_workers, const TaskSystem& cpu_tasks,
                                      const CudaTuning& cuda_tuning);

}  // namespace sph
