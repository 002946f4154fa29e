// SPDX-License-Identifier: MIT
// What CUDA state and tuning from outside a frame do to a CUDA world (a code-reading audit of
// session 44 found each; none can be seen without a GPU):
//   - a CUDA error left pending in the library's runtime must not fail the next step, nor, on the
//     stream driver, make it "roll back" to the previous frame's snapshot (the frame was marked
//     enqueued before its snapshot was): the step succeeds and equals an undisturbed world's.
//     libsph.so links its own static CUDA runtime, so a caller's calls cannot reach it: this
//     program links the static sph_internal (one runtime with the library, as
//     gpu_check_allocation_faults does) and fails a cudaMalloc of its own. The stream driver's
//     case injects it before the third frame (the bug: the second frame's snapshot restored); the
//     graph's before the first, whose capture runs the launch checks (a later frame replays the
//     graph and checks nothing);
//   - block sizes of 512 and 1024 threads (sph_context_def.cuda_density_block, cuda_force_block,
//     accepted from 32 to 1024) on kernels whose registers do not let that many threads into one
//     block (the walls' density, the forces with colliders, DFSPH's walls pass): the steps run and
//     give the default blocks' bits;
//   - sph_world_restore replaces the device buffers: the data epoch moves past every earlier one,
//     so a view taken before the restore never matches (it restarted at the new world's count).
#include <cuda_runtime.h>

#include <cstdint>

#include "../../include/sph_cuda.h"
#include "gpu_check.h"

using namespace gpu_check;

namespace {

constexpr float kFrameDt = 1.0f / 60.0f;

struct Tank {
  sph_context* context = nullptr;
  sph_world* world = nullptr;
  sph_sdf* tank = nullptr;
  sph_sdf* box = nullptr;
  void destroy() {
    sph_world_destroy(world);
    sph_sdf_destroy(tank);
    sph_sdf_destroy(box);
    sph_context_destroy(context);
    *this = Tank{};
  }
};

// A dam break in a tank with a box standing in it, the walls in the density: the heaviest
// density and force kernels of its solver.
Tank make_tank(sph_solver solver) {
  Tank t;
  t.context = make_context(SPH_BACKEND_CUDA);
  sph_world_def def;
  sph_world_def_init(&def);
  def.capacity = 20000;
  def.particle_spacing = 0.02f;
  def.features = SPH_FEATURE_BOUNDARY_DENSITY;
  def.solver = solver;
  require_ok(sph_world_create(t.context, &def, &t.world), "sph_world_create");
  const TankWithBox scene = add_tank_with_box(t.context, t.world, 0.005);
  t.tank = scene.tank;
  t.box = scene.box;
  return t;
}

struct Run {
  sph_result result = SPH_OK;
  std::string message;
  State state;
};

Run run_tank(sph_solver solver, int frames) {
  Tank t = make_tank(solver);
  Run r;
  for (int f = 0; f < frames && r.result == SPH_OK; ++f) {
    r.result = sph_world_step(t.world, kFrameDt);
    if (r.result != SPH_OK) r.message = sph_get_last_error();
  }
  if (r.result == SPH_OK) r.state = read_state(t.world);
  t.destroy();
  return r;
}

void check_block_sizes(sph_solver solver, const char* label) {
  const Run reference = run_tank(solver, 4);
  require_ok(reference.result, "the default blocks' run");
  for (uint32_t block : {512u, 1024u}) {
    context_tuning().density_block = block;
    context_tuning().force_block = block;
    const Run r = run_tank(solver, 4);
    context_tuning().density_block = 0;
    context_tuning().force_block = 0;
    const bool same = r.result == SPH_OK && states_identical(r.state, reference.state);
    const std::string name = std::string("block_sizes/") + label + "/" + std::to_string(block);
    report(
        same, name.c_str(), "density and force blocks of %u threads: %s%s", block,
        r.result != SPH_OK ? sph_result_string(r.result) : (same ? "the default blocks' bits" : "OTHER BITS"),
        r.result != SPH_OK ? (" (" + r.message + ")").c_str() : "");
  }
}

void check_stale_error(bool stream, const char* label) {
  context_tuning().stream_frames = stream;
  Tank disturbed = make_tank(SPH_SOLVER_WCSPH), undisturbed = make_tank(SPH_SOLVER_WCSPH);
  const int before = stream ? 2 : 0;
  for (int f = 0; f < before; ++f) {
    require_ok(sph_world_step(disturbed.world, kFrameDt), "step");
    require_ok(sph_world_step(undisturbed.world, kFrameDt), "step");
  }
  require_ok(sph_world_step(undisturbed.world, kFrameDt), "step");
  void* never = nullptr;
  const cudaError_t caller = cudaMalloc(&never, size_t{1} << 62);  // fails; left pending
  const sph_result r = sph_world_step(disturbed.world, kFrameDt);
  const std::string message = r == SPH_OK ? std::string() : sph_get_last_error();
  const bool same =
      r == SPH_OK && states_identical(read_state(disturbed.world), read_state(undisturbed.world));
  (void)cudaGetLastError();
  const std::string name = std::string("stale_error/") + label;
  report(caller != cudaSuccess && same, name.c_str(),
         "frame %d after a failed cudaMalloc in the library's runtime (%s, not cleared): %s%s", before + 1,
         cudaGetErrorName(caller),
         r != SPH_OK ? sph_result_string(r)
                     : (same ? "SPH_OK, the undisturbed world's bits" : "SPH_OK, OTHER BITS"),
         message.empty() ? "" : (" (" + message + ")").c_str());
  disturbed.destroy();
  undisturbed.destroy();
  context_tuning().stream_frames = false;
}

void check_epoch_after_restore() {
  Tank t = make_tank(SPH_SOLVER_WCSPH);
  uint64_t size = 0;
  require_ok(sph_world_save(t.world, nullptr, 0, &size), "checkpoint size");
  std::vector<unsigned char> saved(size);
  require_ok(sph_world_save(t.world, saved.data(), size, &size), "sph_world_save");
  uint64_t largest = 0, epoch = 0;
  sph_cuda_attribute_view before;
  sph_cuda_attribute_view_init(&before);
  require_ok(sph_cuda_world_get_attribute(t.world, SPH_ATTRIBUTE_POSITION, &before), "view");
  for (int f = 0; f < 3; ++f) {
    require_ok(sph_world_step(t.world, kFrameDt), "step");
    require_ok(sph_cuda_world_get_epoch(t.world, &epoch), "epoch");
    largest = epoch > largest ? epoch : largest;
  }
  require_ok(sph_world_restore(t.world, saved.data(), size), "sph_world_restore");
  uint64_t restored = 0;
  require_ok(sph_cuda_world_get_epoch(t.world, &restored), "epoch after the restore");
  sph_cuda_attribute_view after;
  sph_cuda_attribute_view_init(&after);
  require_ok(sph_cuda_world_get_attribute(t.world, SPH_ATTRIBUTE_POSITION, &after), "view after the restore");
  const bool ok = restored > largest && restored > before.epoch && after.epoch == restored;
  report(
      ok, "epoch/after_restore",
      "epochs: %llu at the first view, %llu at most before the restore, %llu after it (a new view reads it)",
      static_cast<unsigned long long>(before.epoch), static_cast<unsigned long long>(largest),
      static_cast<unsigned long long>(restored));
  t.destroy();
}

}  // namespace

int main() {
  exit_if_no_cuda();
  check_stale_error(false, "graph");
  check_stale_error(true, "stream");
  check_block_sizes(SPH_SOLVER_WCSPH, "wcsph_walls_collider");
  check_block_sizes(SPH_SOLVER_DFSPH, "dfsph_walls_collider");
  check_epoch_after_restore();
  return finish();
}
