// SPDX-License-Identifier: MIT
// A sticky CUDA error (here an illegal address in a kernel of the caller's, which poisons the
// whole process's context) puts a CUDA world in the device-lost state: every later call says
// SPH_ERROR_DEVICE_LOST, destroy still works, and nothing aborts. Run as its own process.
#include <cuda_runtime.h>

#include "gpu_check.h"

using namespace gpu_check;

__global__ void write_to_nowhere(int* p) { p[threadIdx.x] = 1; }

int main() {
  exit_if_no_cuda();
  SceneSpec spec;
  spec.radius = 0.1f;
  Loaded l = load_scene(SPH_BACKEND_CUDA, spec);
  require_ok(sph_world_step(l.world, 0.01f), "step before the fault");
  write_to_nowhere<<<1, 32>>>(reinterpret_cast<int*>(0x10));
  const cudaError_t fault = cudaDeviceSynchronize();
  const sph_result step = sph_world_step(l.world, 0.01f);
  const sph_result again = sph_world_step(l.world, 0.01f);
  float x[3];
  const sph_result copy =
      sph_world_copy_attribute(l.world, SPH_ATTRIBUTE_POSITION, x, sizeof x, 0, 0, 1, nullptr);
  const sph_result destroy = sph_world_destroy(l.world);
  const sph_result destroy_context = sph_context_destroy(l.context);
  report(fault != cudaSuccess && step == SPH_ERROR_DEVICE_LOST && again == SPH_ERROR_DEVICE_LOST &&
             copy == SPH_ERROR_DEVICE_LOST && destroy == SPH_OK && destroy_context == SPH_OK,
         "errors/device_lost", "after %s: step %s, step again %s, copy %s, destroy %s, context destroy %s",
         cudaGetErrorName(fault), sph_result_string(step), sph_result_string(again), sph_result_string(copy),
         sph_result_string(destroy), sph_result_string(destroy_context));
  return finish();
}
