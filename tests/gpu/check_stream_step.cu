// SPDX-License-Identifier: MIT
// sph_cuda_world_step_begin_on_stream on the GPU (issue 21, item 1): a frame begun on the
// caller's stream
//   - ends bitwise where sph_world_step ends it (same scene, three frames), on the frame graph
//     and on the stream driver (a step budget);
//   - is seen whole by the caller's kernel enqueued on that stream right after the begin returns,
//     before sph_world_step_wait: a copy of the positions equals the reference's after the frame
//     (a copy that ran early would read the start of the frame);
//   - runs after the caller's earlier work: a 0.3 s spin enqueued before the begin has finished
//     when sph_world_step_wait returns (a frame of this world takes a few milliseconds);
// and a world's creation and frames do not wait for the caller's work on a blocking stream.
#include <cuda_runtime.h>

#include <chrono>
#include <cstring>
#include <vector>

#include "gpu_check.h"
#include "sph_cuda.h"

using namespace gpu_check;

namespace {

__global__ void spin_kernel(unsigned long long nanoseconds) {
  unsigned long long start, now;
  asm volatile("mov.u64 %0, %%globaltimer;" : "=l"(start));
  do {
    __nanosleep(100000);
    asm volatile("mov.u64 %0, %%globaltimer;" : "=l"(now));
  } while (now - start < nanoseconds);
}

__global__ void copy_positions_kernel(const unsigned char* records, uint64_t stride, uint32_t n, float* out) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float* p = reinterpret_cast<const float*>(records + i * stride);
  out[3 * i] = p[0], out[3 * i + 1] = p[1], out[3 * i + 2] = p[2];
}

void cuda_require(cudaError_t e, const char* what) {
  if (e != cudaSuccess) {
    std::printf("FAIL %s: %s\n", what, cudaGetErrorString(e));
    std::exit(1);
  }
}

sph_world* make_world(sph_context* context) {
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 40000;
  sph_world* world = nullptr;
  require_ok(sph_world_create(context, &def, &world), "sph_world_create");
  sph_fill_box_desc box;
  sph_fill_box_desc_init(&box);
  box.max = sph_vec3{0.4f, 0.4f, 0.2f};
  require_ok(sph_world_fill_box(world, &box, nullptr), "sph_world_fill_box");
  return world;
}

std::vector<float> positions_of(const sph_world* world, uint32_t n) {
  std::vector<float> p(3u * n);
  uint32_t written = 0;
  require_ok(sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, p.data(), sizeof(float) * p.size(), 0, 0,
                                      n, &written),
             "sph_world_copy_attribute");
  return p;
}

void check_frames(bool budget) {
  const char* driver = budget ? "stream_driver" : "graph";
  sph_context* context = make_context(SPH_BACKEND_CUDA);
  sph_world* world = make_world(context);
  sph_world* reference = make_world(context);
  if (budget) {
    require_ok(sph_world_set_step_budget(world, 100.0), "sph_world_set_step_budget");
    require_ok(sph_world_set_step_budget(reference, 100.0), "sph_world_set_step_budget");
  }
  uint32_t n = 0;
  require_ok(sph_world_get_particle_count(world, &n), "sph_world_get_particle_count");
  sph_cuda_attribute_view view;
  sph_cuda_attribute_view_init(&view);
  require_ok(sph_cuda_world_get_attribute(world, SPH_ATTRIBUTE_POSITION, &view),
             "sph_cuda_world_get_attribute");
  cudaStream_t caller = nullptr;
  cuda_require(cudaStreamCreateWithFlags(&caller, cudaStreamNonBlocking), "cudaStreamCreate");
  float* copy = nullptr;
  cuda_require(cudaMalloc(&copy, sizeof(float) * 3 * n), "cudaMalloc");
  std::vector<float> seen(3u * n);
  bool seen_whole = true, same_as_step = true;
  for (int frame = 0; frame < 3; ++frame) {
    require_ok(sph_world_step(reference, 1.0f / 60.0f), "sph_world_step (reference)");
    require_ok(sph_cuda_world_step_begin_on_stream(world, 1.0f / 60.0f, caller),
               "sph_cuda_world_step_begin_on_stream");
    copy_positions_kernel<<<(n + 255) / 256, 256, 0, caller>>>(
        reinterpret_cast<const unsigned char*>(view.device_address), view.stride, n, copy);
    cuda_require(cudaMemcpyAsync(seen.data(), copy, sizeof(float) * 3 * n, cudaMemcpyDeviceToHost, caller),
                 "cudaMemcpyAsync");
    cuda_require(cudaStreamSynchronize(caller), "cudaStreamSynchronize (before the wait)");
    require_ok(sph_world_step_wait(world), "sph_world_step_wait");
    const std::vector<float> expected = positions_of(reference, n);
    seen_whole = seen_whole && std::memcmp(seen.data(), expected.data(), sizeof(float) * 3 * n) == 0;
    same_as_step = same_as_step && positions_of(world, n) == expected;
  }
  char name[96];
  std::snprintf(name, sizeof name, "stream_step/same_as_step/%s", driver);
  report(same_as_step, name, "3 frames of %u particles begun on the caller's stream: positions %s", n,
         same_as_step ? "bitwise those of sph_world_step" : "DIFFER");
  std::snprintf(name, sizeof name, "stream_step/caller_sees_the_frame/%s", driver);
  report(seen_whole, name, "the caller's copy kernel enqueued after the begin read %s",
         seen_whole ? "the end of each frame" : "OTHER positions (it ran before the frame ended)");

  // The frame waits for the caller's earlier work.
  cudaEvent_t spun;
  cuda_require(cudaEventCreateWithFlags(&spun, cudaEventDisableTiming), "cudaEventCreate");
  spin_kernel<<<1, 1, 0, caller>>>(300000000ull);
  cuda_require(cudaEventRecord(spun, caller), "cudaEventRecord");
  const auto t = std::chrono::steady_clock::now();
  require_ok(sph_cuda_world_step_begin_on_stream(world, 1.0f / 60.0f, caller),
             "sph_cuda_world_step_begin_on_stream");
  require_ok(sph_world_step_wait(world), "sph_world_step_wait");
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  const cudaError_t q = cudaEventQuery(spun);
  std::snprintf(name, sizeof name, "stream_step/frame_after_caller_work/%s", driver);
  report(q == cudaSuccess, name,
         "a 0.3 s spin enqueued before the begin: %s when the wait returned (after %.3f s)",
         q == cudaSuccess ? "finished" : "STILL RUNNING", waited);
  cuda_require(cudaStreamSynchronize(caller), "cudaStreamSynchronize");
  cudaEventDestroy(spun);
  cudaFree(copy);
  cudaStreamDestroy(caller);
  sph_world_destroy(reference);
  sph_world_destroy(world);
  sph_context_destroy(context);
}

// A world's set-up and frames run on its own non-blocking stream: none of them waits for an
// engine's work on a blocking stream (as a call on the legacy default stream, or a device-wide
// synchronisation, would: the grid's extent reset and the distributed halo's set-up did before
// session 46). A 1 s spin on the caller's blocking stream is still running after a world is
// created, filled, stepped one frame and read back.
void check_set_up_ignores_blocking_streams() {
  sph_context* context = make_context(SPH_BACKEND_CUDA);
  cudaStream_t engine = nullptr;
  cuda_require(cudaStreamCreate(&engine), "cudaStreamCreate (blocking)");
  cudaEvent_t spun;
  cuda_require(cudaEventCreateWithFlags(&spun, cudaEventDisableTiming), "cudaEventCreate");
  spin_kernel<<<1, 1, 0, engine>>>(1000000000ull);
  cuda_require(cudaEventRecord(spun, engine), "cudaEventRecord");
  const auto t = std::chrono::steady_clock::now();
  sph_world* world = make_world(context);
  require_ok(sph_world_step(world, 1.0f / 60.0f), "sph_world_step");
  uint32_t n = 0;
  require_ok(sph_world_get_particle_count(world, &n), "sph_world_get_particle_count");
  const std::vector<float> p = positions_of(world, n);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  const cudaError_t q = cudaEventQuery(spun);
  report(q == cudaErrorNotReady && took < 0.9, "stream_step/set_up_ignores_blocking_streams",
         "create, fill (%u particles), one frame and a read-back took %.3f s while the caller's 1 s spin on "
         "a blocking stream was %s",
         n, took, q == cudaErrorNotReady ? "still running" : "FINISHED (a call waited for it)");
  cuda_require(cudaStreamSynchronize(engine), "cudaStreamSynchronize");
  cudaEventDestroy(spun);
  cudaStreamDestroy(engine);
  sph_world_destroy(world);
  sph_context_destroy(context);
}

}  // namespace

int main() {
  exit_if_no_cuda();
  check_frames(false);
  check_frames(true);
  check_set_up_ignores_blocking_streams();
  return finish();
}
