// SPDX-License-Identifier: MIT
#include "backend_factory.h"

#include <string>

#include "../core/status.h"
#include "../cpu/cpu_backend.h"

#if defined(SPH_HAVE_CUDA)
#include "../../cuda/cuda_backend.h"
#endif

namespace sph {

bool cuda_built() {
#if defined(SPH_HAVE_CUDA)
  return true;
#else
  return false;
#endif
}

int cuda_device_count() {
#if defined(SPH_HAVE_CUDA)
  return cuda_usable_device_count();
#else
  return 0;
#endif
}

BackendKind resolve_backend(BackendKind requested, int device_ordinal) {
  if (requested == BackendKind::Cpu) return BackendKind::Cpu;
  const int devices = cuda_device_count();
  if (requested == BackendKind::Auto) return devices > 0 ? BackendKind::Cuda : BackendKind::Cpu;
  if (!cuda_built())
    throw Error(Status::Unsupported,
                "backend: SPH_BACKEND_CUDA was asked for, but this library was built without CUDA");
  if (devices == 0)
    throw Error(Status::Unsupported,
                "backend: SPH_BACKEND_CUDA was asked for, but no CUDA device is present");
  if (device_ordinal >= devices)
    throw Error(Status::Unsupported, "device_ordinal: " + std::to_string(device_ordinal) +
                                         " is out of range; " + std::to_string(devices) +
                                         " CUDA device(s) present");
  return BackendKind::Cuda;
}

void copy_device_to_host(void* host_dst, const void* device_src, size_t bytes, int device_ordinal) {
#if defined(SPH_HAVE_CUDA)
  cuda_copy_to_host(host_dst, device_src, bytes, device_ordinal);
#else
  (void)host_dst;
  (void)device_src;
  (void)bytes;
  (void)device_ordinal;
  throw Error(Status::Unsupported, "memory: SPH_MEMORY_CUDA_DEVICE needs a library built with CUDA");
#endif
}

std::unique_ptr<Backend> make_backend(BackendKind kind, const WorldConfig& config, int device_ordinal,
                                      unsigned cpu_workers, const TaskSystem& cpu_tasks,
                                      const CudaTuning& cuda_tuning) {
#if defined(SPH_HAVE_CUDA)
  if (kind == BackendKind::Cuda) {
    CudaBackendOptions options;
    options.stream_frames = cuda_tuning.stream_frames;
    if (cuda_tuning.density_block != 0) options.density_block = cuda_tuning.density_block;
    if (cuda_tuning.force_block != 0) options.force_block = cuda_tuning.force_block;
    options.particle_lanes = cuda_tuning.particle_lanes;
    options.dfsph_masks = cuda_tuning.dfsph_masks;
    options.dfsph_lists = cuda_tuning.dfsph_lists;
    return make_cuda_backend(config, device_ordinal < 0 ? 0 : device_ordinal, options);
  }
#else
  (void)device_ordinal;
  (void)cuda_tuning;
#endif
  if (kind == BackendKind::Cuda)
    throw Error(Status::Unsupported, "backend: CUDA is not available in this build");
  return make_cpu_backend(config, cpu_workers, cpu_tasks);
}

}  // namespace sph
