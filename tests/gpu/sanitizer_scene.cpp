// SPDX-License-Identifier: MIT
// A small scene for compute-sanitizer (memcheck, racecheck, synccheck): Euler and RK4 frames,
// a spawn between frames, a rollback, and the copy-out of every attribute; then the scene
// kernels: colliders (tank, paddle, deforming ball), every force field, sinks and a source.
#include "gpu_check.h"
#include "scene_parity.h"

using namespace gpu_check;

int main() {
  exit_if_no_cuda();
  SceneSpec spec;
  spec.radius = 0.12f;
  spec.random_speed = 0.1f;
  spec.gravity = sph_vec3{0.0f, -9.81f, 0.0f};
  spec.spare_capacity = 100;
  for (sph_integrator integrator : {SPH_INTEGRATOR_SYMPLECTIC_EULER, SPH_INTEGRATOR_RK4}) {
    spec.integrator = integrator;
    Loaded l = load_scene(SPH_BACKEND_CUDA, spec);
    require_ok(sph_world_step(l.world, 0.004f), "step");
    const float extra[6] = {0.5f, 0.5f, 0.5f, 0.51f, 0.5f, 0.5f};
    sph_spawn_desc spawn;
    sph_spawn_desc_init(&spawn);
    spawn.count = 2;
    spawn.positions = extra;
    require_ok(sph_world_spawn(l.world, &spawn, nullptr), "spawn");
    require_ok(sph_world_step(l.world, 0.004f), "step");
    sph_world_params params;
    sph_world_params_init(&params);
    params.stiffness = 1e37f;
    require_ok(sph_world_set_params(l.world, &params), "set_params");
    require(sph_world_step(l.world, 0.004f), SPH_ERROR_NON_FINITE, "non-finite step");
    const State s = read_state(l.world);
    report(s.count == l.count + 2,
           integrator == SPH_INTEGRATOR_RK4 ? "sanitizer_scene/rk4" : "sanitizer_scene/euler",
           "%u particles stepped, spawned, rolled back and read", s.count);
    l.destroy();
  }
  spec.integrator = SPH_INTEGRATOR_SYMPLECTIC_EULER;
  spec.spare_capacity = 2000;
  for (void (*build)(sph_context*, sph_world*) :
       {build_tank, build_paddle, build_deforming, build_fields, build_sinks, build_source}) {
    Loaded l = load_scene(SPH_BACKEND_CUDA, spec);
    build(l.context, l.world);
    for (int frame = 0; frame < 2; ++frame) require_ok(sph_world_step(l.world, 0.004f), "scene step");
    const RawState s = read_raw(l.world);
    report(true, "sanitizer_scene/scene", "%u particles after two scene frames", s.count);
    l.destroy();
  }
  return finish();
}
