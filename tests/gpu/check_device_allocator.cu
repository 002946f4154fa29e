// SPDX-License-Identifier: MIT
// The engine's device allocator (sph_cuda_context_set_allocator, issue 21 item 2) on the GPU:
//   - every device allocation of a CUDA world goes through it: while the world lives the live
//     bytes it handed out cover the world's device memory (sph_stats.memory_bytes), and after
//     the world and its SDF are destroyed they are 0;
//   - a world stepped on it ends bitwise where a world on cudaMalloc ends (the allocator changes
//     where memory is, never what is computed);
//   - an allocator that answers NULL makes world creation fail with OUT_OF_DEVICE_MEMORY and
//     leaves nothing allocated; it answers BUSY once the context holds a world.
#include <cuda_runtime.h>

#include <atomic>
#include <cstring>
#include <vector>

#include "gpu_check.h"
#include "sph_cuda.h"

using namespace gpu_check;

namespace {

struct Ledger {
  std::atomic<long long> live{0};
  std::atomic<long long> calls{0};
  std::atomic<bool> refuse{false};
};

void* SPH_CALL ledger_alloc(size_t size, int32_t device, void* user) {
  Ledger* l = static_cast<Ledger*>(user);
  if (l->refuse.load()) return nullptr;
  int current = -1;
  cudaGetDevice(&current);
  if (current != device) return nullptr;  // the library makes the world's device current
  void* p = nullptr;
  if (cudaMalloc(&p, size) != cudaSuccess) return nullptr;
  l->live += static_cast<long long>(size);
  ++l->calls;
  return p;
}

void SPH_CALL ledger_free(void* memory, size_t size, int32_t, void* user) {
  Ledger* l = static_cast<Ledger*>(user);
  l->live -= static_cast<long long>(size);
  cudaFree(memory);
}

sph_world* make_world(sph_context* context) {
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 30000;
  sph_world* world = nullptr;
  require_ok(sph_world_create(context, &def, &world), "sph_world_create");
  sph_fill_box_desc box;
  sph_fill_box_desc_init(&box);
  box.max = sph_vec3{0.3f, 0.3f, 0.3f};
  require_ok(sph_world_fill_box(world, &box, nullptr), "sph_world_fill_box");
  return world;
}

}  // namespace

int main() {
  exit_if_no_cuda();
  Ledger ledger;
  sph_context* context = make_context(SPH_BACKEND_CUDA);
  sph_cuda_allocator allocator;
  sph_cuda_allocator_init(&allocator);
  allocator.alloc_fn = ledger_alloc;
  allocator.free_fn = ledger_free;
  allocator.user_context = &ledger;
  require_ok(sph_cuda_context_set_allocator(context, &allocator), "sph_cuda_context_set_allocator");

  // Refused allocations: nothing is created, nothing stays allocated.
  ledger.refuse = true;
  sph_world_def def;
  sph_world_def_init(&def);
  sph_world* refused = nullptr;
  const sph_result r = sph_world_create(context, &def, &refused);
  report(r == SPH_ERROR_OUT_OF_DEVICE_MEMORY && refused == nullptr && ledger.live == 0,
         "device_allocator/refusal", "an allocator answering NULL: result %d, %lld bytes left live",
         static_cast<int>(r), ledger.live.load());
  ledger.refuse = false;

  sph_world* world = make_world(context);
  sph_stats stats;
  sph_stats_init(&stats);
  for (int frame = 0; frame < 5; ++frame) require_ok(sph_world_step(world, 1.0f / 60.0f), "sph_world_step");
  require_ok(sph_world_get_stats(world, &stats), "sph_world_get_stats");
  const long long live = ledger.live.load();
  report(live >= static_cast<long long>(stats.memory_bytes) && ledger.calls > 0,
         "device_allocator/holds_the_world",
         "%lld bytes live through the allocator in %lld calls, world reports %llu device bytes", live,
         ledger.calls.load(), static_cast<unsigned long long>(stats.memory_bytes));
  sph_cuda_allocator_init(&allocator);
  const sph_result busy = sph_cuda_context_set_allocator(context, &allocator);
  report(busy == SPH_ERROR_BUSY, "device_allocator/busy_with_a_world",
         "setting it again with a world: result %d", static_cast<int>(busy));

  sph_context* plain = make_context(SPH_BACKEND_CUDA);
  sph_world* reference = make_world(plain);
  for (int frame = 0; frame < 5; ++frame)
    require_ok(sph_world_step(reference, 1.0f / 60.0f), "sph_world_step");
  const bool same = states_identical(read_state(world), read_state(reference));
  report(same, "device_allocator/same_results", "5 frames on the engine's allocator against cudaMalloc: %s",
         same ? "bitwise identical" : "DIFFER");
  sph_world_destroy(reference);
  sph_context_destroy(plain);

  sph_world_destroy(world);
  report(ledger.live == 0, "device_allocator/everything_back", "after sph_world_destroy: %lld bytes live",
         ledger.live.load());
  sph_context_destroy(context);
  return finish();
}
