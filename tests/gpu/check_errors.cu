// SPDX-License-Identifier: MIT
// Error paths and the zero-copy tier of the CUDA backend: device allocation failure, the
// caller's current device, an out-of-range device, the non-finite rollback (bitwise, and the
// same particle named as on the CPU), and sph_cuda.h (views, epoch, stream, events).
#include <cuda_runtime.h>

#include "gpu_check.h"
#include "sph_cuda.h"

using namespace gpu_check;

namespace {

// The first particle id a non-finite step's message names: "1 particle, id 17", "3 particles,
// ids 17, 20, 31" (CPU) or "3 particles, first id 17" (CUDA); "?" when there is none.
std::string message_id(const char* message) {
  for (const char* key : {"particle, id ", "particles, ids ", "particles, first id "}) {
    const char* at = std::strstr(message, key);
    if (at) {
      at += std::strlen(key);
      const size_t digits = std::strspn(at, "0123456789");
      if (digits > 0) return std::string(at, digits);
    }
  }
  return "?";
}

void out_of_device_memory() {
  sph_context* context = make_context(SPH_BACKEND_CUDA);
  std::vector<sph_world*> worlds;
  sph_result r = SPH_OK;
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 1u << 30;  // about 120 GiB of device memory per world
  for (int k = 0; k < 8 && r == SPH_OK; ++k) {
    sph_world* w = nullptr;
    r = sph_world_create(context, &def, &w);
    if (r == SPH_OK) worlds.push_back(w);
  }
  report(r == SPH_ERROR_OUT_OF_DEVICE_MEMORY, "errors/out_of_device_memory",
         "world of capacity 2^30 number %zu: %s (%s)", worlds.size() + 1, sph_result_string(r),
         sph_get_last_error());
  for (sph_world* w : worlds) sph_world_destroy(w);
  // The context and device are fine afterwards: a small world steps.
  SceneSpec small;
  small.radius = 0.1f;
  Loaded l = load_scene(SPH_BACKEND_CUDA, small);
  const sph_result step = sph_world_step(l.world, 0.01f);
  report(step == SPH_OK, "errors/after_out_of_device_memory", "a new world steps: %s",
         sph_result_string(step));
  l.destroy();
  sph_context_destroy(context);
}

void caller_device_kept() {
  int devices = 0;
  cudaGetDeviceCount(&devices);
  const int caller = devices - 1;
  cudaSetDevice(caller);
  sph_context_def def;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CUDA;
  def.device_ordinal = 0;
  sph_context* context = nullptr;
  require_ok(sph_context_create(&def, &context), "sph_context_create");
  SceneSpec small;
  small.radius = 0.1f;
  const std::vector<float> pos = fcc_sphere(0, 0, 0, small.radius, small.spacing);
  sph_world_def wdef;
  sph_world_def_init(&wdef);
  wdef.capacity = static_cast<uint32_t>(pos.size() / 3);
  sph_world* world = nullptr;
  require_ok(sph_world_create(context, &wdef, &world), "sph_world_create");
  int after_create = -1;
  cudaGetDevice(&after_create);
  sph_spawn_desc spawn;
  sph_spawn_desc_init(&spawn);
  spawn.count = wdef.capacity;
  spawn.positions = pos.data();
  require_ok(sph_world_spawn(world, &spawn, nullptr), "spawn");
  require_ok(sph_world_step(world, 0.01f), "step");
  std::vector<float> out(pos.size());
  require_ok(sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, out.data(), out.size() * 4, 0, 0,
                                      spawn.count, nullptr),
             "copy");
  int after_calls = -1;
  cudaGetDevice(&after_calls);
  sph_world_destroy(world);
  sph_context_destroy(context);
  int after_destroy = -1;
  cudaGetDevice(&after_destroy);
  report(after_create == caller && after_calls == caller && after_destroy == caller,
         "errors/caller_device_kept",
         "caller's device %d, world on device 0 (%d device(s)%s): current device after create %d, after "
         "spawn/step/copy %d, after destroy %d",
         caller, devices, devices < 2 ? ", so this only shows it is not disturbed" : "", after_create,
         after_calls, after_destroy);
}

void device_out_of_range() {
  int devices = 0;
  cudaGetDeviceCount(&devices);
  sph_context_def def;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CUDA;
  def.device_ordinal = devices;
  sph_context* context = nullptr;
  const sph_result r = sph_context_create(&def, &context);
  report(r == SPH_ERROR_UNSUPPORTED && context == nullptr, "errors/device_out_of_range",
         "device %d of %d: %s", devices, devices, sph_result_string(r));
}

void non_finite_rollback() {
  // A block compressed to half the spacing under an absurd stiffness: the first substep
  // overflows to Inf.
  std::string ids[2];
  bool restored[2] = {false, false};
  bool steps_after[2] = {false, false};
  sph_result results[2] = {SPH_OK, SPH_OK};
  const sph_backend backends[2] = {SPH_BACKEND_CPU, SPH_BACKEND_CUDA};
  for (int b = 0; b < 2; ++b) {
    sph_context* context = make_context(backends[b]);
    const std::vector<float> pos = fcc_sphere(0, 0, 0, 0.1f, 0.01f);
    sph_world_def def;
    sph_world_def_init(&def);
    def.capacity = static_cast<uint32_t>(pos.size() / 3);
    sph_world* world = nullptr;
    require_ok(sph_world_create(context, &def, &world), "sph_world_create");
    sph_spawn_desc spawn;
    sph_spawn_desc_init(&spawn);
    spawn.count = def.capacity;
    spawn.positions = pos.data();
    require_ok(sph_world_spawn(world, &spawn, nullptr), "spawn");
    require_ok(sph_world_step(world, 0.002f), "first step");
    const State before = read_state(world);
    sph_world_params params;
    sph_world_params_init(&params);
    params.stiffness = 1e37f;
    require_ok(sph_world_set_params(world, &params), "set_params");
    results[b] = sph_world_step(world, 0.01f);
    ids[b] = message_id(sph_get_last_error());
    const State after = read_state(world);
    restored[b] = states_identical(before, after);
    sph_world_params_init(&params);
    require_ok(sph_world_set_params(world, &params), "set_params");
    steps_after[b] = sph_world_step(world, 0.002f) == SPH_OK;
    sph_world_destroy(world);
    sph_context_destroy(context);
  }
  report(results[1] == SPH_ERROR_NON_FINITE && restored[1] && steps_after[1], "errors/non_finite_rollback",
         "GPU: %s; state after the failed step bitwise equal to before: %s; steps again: %s",
         sph_result_string(results[1]), restored[1] ? "yes" : "NO", steps_after[1] ? "yes" : "NO");
  // Under a stiffness of 1e37 nearly every compressed particle overflows, and which one has the
  // lowest storage index depends on densities at round-off (CPU and GPU agree to 1e-7, not
  // bitwise), so that step names some particle on each backend without naming the same one.
  report(results[0] == SPH_ERROR_NON_FINITE && ids[0] != "?" && ids[1] != "?",
         "errors/non_finite_names_a_particle", "CPU names particle id %s, GPU names particle id %s",
         ids[0].c_str(), ids[1].c_str());

  // The same particle on both backends: one particle thrown at 1.84e19 m/s, far from the others,
  // whose squared speed overflows in the integration of the first substep; nothing else fails.
  std::string named[2];
  uint32_t thrown_id[2] = {0, 0};
  for (int b = 0; b < 2; ++b) {
    sph_context* context = make_context(backends[b]);
    const std::vector<float> pos = fcc_sphere(0, 0, 0, 0.1f, 0.02f);
    sph_world_def def;
    sph_world_def_init(&def);
    def.capacity = static_cast<uint32_t>(pos.size() / 3) + 1;
    sph_world* world = nullptr;
    require_ok(sph_world_create(context, &def, &world), "sph_world_create");
    sph_spawn_desc spawn;
    sph_spawn_desc_init(&spawn);
    spawn.count = def.capacity - 1;
    spawn.positions = pos.data();
    require_ok(sph_world_spawn(world, &spawn, nullptr), "spawn");
    require_ok(sph_world_step(world, 0.002f), "first step");
    const float thrown_position[3] = {0.0f, 0.5f, 0.0f};
    // Spawning refuses a speed whose square overflows float32 (1.8e19 m/s), so the thrown
    // particle starts just inside that limit and a uniform field of 1e20 m/s^2 over one fixed
    // 2 ms substep pushes it past: its |v|^2 overflows in the integration while every other
    // particle's speed (2e17 m/s) stays finite.
    const float thrown_velocity[3] = {1.84e19f, 0.0f, 0.0f};
    sph_spawn_desc_init(&spawn);
    spawn.count = 1;
    spawn.positions = thrown_position;
    spawn.velocities = thrown_velocity;
    require_ok(sph_world_spawn(world, &spawn, &thrown_id[b]), "spawn the thrown particle");
    sph_world_params params;
    sph_world_params_init(&params);
    require_ok(sph_world_get_params(world, &params), "get params");
    params.dt_min = params.dt_max = 0.002f;
    require_ok(sph_world_set_params(world, &params), "one 2 ms substep");
    sph_force_field_def field;
    sph_force_field_def_init(&field);
    field.kind = SPH_FORCE_FIELD_UNIFORM;
    field.vector.x = 1e20f;
    sph_force_field_id field_id;
    require_ok(sph_force_field_create(world, &field, &field_id), "the pushing field");
    const sph_result r = sph_world_step(world, 0.002f);
    named[b] = r == SPH_ERROR_NON_FINITE ? message_id(sph_get_last_error())
                                         : std::string("(step: ") + sph_result_string(r) + ")";
    sph_world_destroy(world);
    sph_context_destroy(context);
  }
  report(named[0] == std::to_string(thrown_id[0]) && named[1] == std::to_string(thrown_id[1]) &&
             thrown_id[0] == thrown_id[1],
         "errors/non_finite_same_particle", "thrown particle id %u; CPU names %s, GPU names %s", thrown_id[1],
         named[0].c_str(), named[1].c_str());
}

__global__ void scale_kernel(float* data, int n) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) data[i] *= 1.0f;
}

void zero_copy_tier() {
  SceneSpec spec;
  spec.radius = 0.15f;
  spec.random_speed = 0.1f;
  Loaded l = load_scene(SPH_BACKEND_CUDA, spec);
  require_ok(sph_world_step(l.world, 0.01f), "step");
  const State by_id = read_state(l.world);
  (void)by_id;
  // Compare each device view with sph_world_copy_attribute, element by element.
  const uint32_t n = l.count;
  bool views_match = true;
  uint64_t view_epoch = 0;
  const sph_attribute attributes[5] = {SPH_ATTRIBUTE_POSITION, SPH_ATTRIBUTE_VELOCITY, SPH_ATTRIBUTE_DENSITY,
                                       SPH_ATTRIBUTE_PRESSURE, SPH_ATTRIBUTE_ID};
  for (sph_attribute a : attributes) {
    sph_cuda_attribute_view view;
    sph_cuda_attribute_view_init(&view);
    require_ok(sph_cuda_world_get_attribute(l.world, a, &view), "sph_cuda_world_get_attribute");
    view_epoch = view.epoch;
    std::vector<unsigned char> device_copy(static_cast<size_t>(view.stride) * n);
    cudaMemcpy(device_copy.data(), reinterpret_cast<const void*>(view.device_address),
               static_cast<size_t>(view.stride) * (n - 1) + view.element_size, cudaMemcpyDeviceToHost);
    std::vector<unsigned char> host_copy(static_cast<size_t>(view.element_size) * n);
    require_ok(sph_world_copy_attribute(l.world, a, host_copy.data(), host_copy.size(), 0, 0, n, nullptr),
               "copy");
    for (uint32_t i = 0; i < n && views_match; ++i)
      views_match = std::memcmp(device_copy.data() + i * view.stride,
                                host_copy.data() + i * view.element_size, view.element_size) == 0;
    views_match = views_match && view.count == n && view.device_ordinal == 0;
  }
  report(views_match, "zero_copy/views", "device views of all 5 attributes equal sph_world_copy_attribute");
  uint64_t e0 = 0, e1 = 0;
  require_ok(sph_cuda_world_get_epoch(l.world, &e0), "epoch");
  require_ok(sph_world_step(l.world, 0.01f), "step");
  require_ok(sph_cuda_world_get_epoch(l.world, &e1), "epoch");
  report(e0 == view_epoch && e1 > e0, "zero_copy/epoch", "epoch %llu at the view, %llu after a step",
         static_cast<unsigned long long>(e0), static_cast<unsigned long long>(e1));
  void* stream = nullptr;
  int32_t device = -1;
  require_ok(sph_cuda_world_get_stream(l.world, &stream), "stream");
  require_ok(sph_cuda_world_get_device(l.world, &device), "device");
  // The caller's work on its own stream, then the world waits for it; and the other way round.
  cudaStream_t mine = nullptr;
  cudaStreamCreateWithFlags(&mine, cudaStreamNonBlocking);
  cudaEvent_t done_mine = nullptr, done_world = nullptr;
  cudaEventCreateWithFlags(&done_mine, cudaEventDisableTiming);
  cudaEventCreateWithFlags(&done_world, cudaEventDisableTiming);
  sph_cuda_attribute_view dview;
  sph_cuda_attribute_view_init(&dview);
  require_ok(sph_cuda_world_get_attribute(l.world, SPH_ATTRIBUTE_DENSITY, &dview), "view");
  float* scratch = nullptr;
  cudaMalloc(&scratch, sizeof(float) * n);
  require_ok(sph_cuda_world_record_event(l.world, done_world), "record_event");
  cudaStreamWaitEvent(mine, done_world, 0);
  cudaMemcpyAsync(scratch, reinterpret_cast<const void*>(dview.device_address), sizeof(float) * n,
                  cudaMemcpyDeviceToDevice, mine);
  scale_kernel<<<(n + 255) / 256, 256, 0, mine>>>(scratch, static_cast<int>(n));
  cudaEventRecord(done_mine, mine);
  require_ok(sph_cuda_world_wait_event(l.world, done_mine), "wait_event");
  const sph_result step = sph_world_step(l.world, 0.01f);
  const cudaError_t e = cudaStreamSynchronize(mine);
  report(stream != nullptr && device == 0 && step == SPH_OK && e == cudaSuccess,
         "zero_copy/stream_and_events",
         "stream %p, device %d; caller work ordered after the world (record_event) and the world's next step "
         "after "
         "the caller's kernel (wait_event): step %s, caller stream %s",
         stream, device, sph_result_string(step), cudaGetErrorString(e));
  cudaFree(scratch);
  cudaEventDestroy(done_mine);
  cudaEventDestroy(done_world);
  cudaStreamDestroy(mine);
  l.destroy();

  // A CPU world refuses the whole tier.
  Loaded cpu = load_scene(SPH_BACKEND_CPU, spec);
  sph_cuda_attribute_view view;
  sph_cuda_attribute_view_init(&view);
  uint64_t epoch = 0;
  void* s = nullptr;
  const bool refused =
      sph_cuda_world_get_attribute(cpu.world, SPH_ATTRIBUTE_POSITION, &view) == SPH_ERROR_UNSUPPORTED &&
      sph_cuda_world_get_epoch(cpu.world, &epoch) == SPH_ERROR_UNSUPPORTED &&
      sph_cuda_world_get_stream(cpu.world, &s) == SPH_ERROR_UNSUPPORTED &&
      sph_cuda_world_record_event(cpu.world, &s) == SPH_ERROR_UNSUPPORTED;
  report(refused, "zero_copy/cpu_world_unsupported",
         "every sph_cuda_* call on a CPU world returns UNSUPPORTED");
  cpu.destroy();
}

}  // namespace

int main() {
  exit_if_no_cuda();
  device_out_of_range();
  caller_device_kept();
  zero_copy_tier();
  non_finite_rollback();
  out_of_device_memory();
  return finish();
}
