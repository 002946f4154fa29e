// SPDX-License-Identifier: MIT
/* Writes tests/data/checkpoint_v1_options.sphckpt: a checkpoint of format version 1, the layout
 * before the physics methods became modules (issue 15), for the test that old files still load
 * (tests/reliability/test_checkpoint_formats.c).
 *
 * Made once, with the library of commit 179918a (the last one writing version 1):
 *   cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSPH_WITH_CUDA=OFF && ninja -C build sph
 *   cc -std=c99 -Iinclude tests/data/make_checkpoint_v1.c -Lbuild -lsph -o /tmp/make_checkpoint_v1
 *   LD_LIBRARY_PATH=build /tmp/make_checkpoint_v1 tests/data/checkpoint_v1_options.sphckpt
 * Built against a later library it writes that library's format instead: keep the committed file.
 *
 * The world turns every option on (surface tension, normalised density, springs, Clavet
 * viscosity, Tait, RK4) and sets every runtime parameter to a value other than its default, so
 * a field read into the wrong place shows. test_checkpoint_formats.c repeats these values. */
#include <stdio.h>
#include <stdlib.h>

#include "sph_c.h"

static void check(sph_result r, const char* what) {
  if (r != SPH_OK) {
    fprintf(stderr, "make_checkpoint_v1: %s: %s\n  %s\n", what, sph_result_string(r), sph_get_last_error());
    exit(1);
  }
}

int main(int argc, char** argv) {
  sph_context_def cdef;
  sph_context* context = NULL;
  sph_world_def def;
  sph_world* world = NULL;
  sph_world_params params;
  sph_surface_tension_params surface;
  sph_clavet_viscosity_params clavet;
  sph_tait_params tait;
  sph_spring_params springs;
  sph_fill_sphere_desc sphere;
  uint32_t added = 0;
  int frame;
  if (argc != 2) {
    fprintf(stderr, "usage: make_checkpoint_v1 OUT.sphckpt\n");
    return 2;
  }
  sph_context_def_init(&cdef);
  cdef.backend = SPH_BACKEND_CPU;
  cdef.cpu_worker_count = 1;
  check(sph_context_create(&cdef, &context), "sph_context_create");
  sph_world_def_init(&def);
  def.capacity = 200;
  def.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_SPRINGS;
  def.integrator = SPH_INTEGRATOR_RK4;
  def.viscosity_method = SPH_VISCOSITY_CLAVET;
  def.equation_of_state = SPH_EOS_TAIT;
  def.particle_spacing = 0.04f;
  check(sph_world_create(context, &def, &world), "sph_world_create");

  sph_world_params_init(&params);
  params.max_substeps = 5000;
  params.gravity.x = 0.5f;
  params.gravity.y = -9.0f;
  params.gravity.z = 0.25f;
  params.stiffness = 150.0f;
  params.viscosity = 0.75f;
  params.step_factor = 0.3f;
  params.dt_min = 2e-6f;
  params.dt_max = 2e-3f;
  params.step_limits = SPH_STEP_LIMIT_ACOUSTIC | SPH_STEP_LIMIT_FORCE;
  check(sph_world_set_params(world, &params), "sph_world_set_params");
  sph_surface_tension_params_init(&surface);
  surface.coefficient = 0.05f;
  surface.normal_threshold = 3.0f;
  check(sph_world_set_surface_tension_params(world, &surface), "surface tension");
  sph_clavet_viscosity_params_init(&clavet);
  clavet.linear = 12.0f;
  clavet.quadratic = 0.5f;
  check(sph_world_set_clavet_viscosity_params(world, &clavet), "Clavet");
  sph_tait_params_init(&tait);
  tait.speed_of_sound = 12.0f;
  check(sph_world_set_tait_params(world, &tait), "Tait");
  sph_spring_params_init(&springs);
  springs.stiffness = 2e3f;
  springs.link_radius = 0.05f;
  springs.yield_ratio = 0.2f;
  springs.plasticity = 1.5f;
  springs.damping = 3.0f;
  check(sph_world_set_spring_params(world, &springs), "springs");

  sph_fill_sphere_desc_init(&sphere);
  sphere.radius = 0.1f;
  sphere.velocity.x = 0.2f;
  check(sph_world_fill_sphere(world, &sphere, &added), "sph_world_fill_sphere");
  for (frame = 0; frame < 2; ++frame) check(sph_world_step(world, 1.0f / 60.0f), "sph_world_step");
  check(sph_world_save_file(world, argv[1]), "sph_world_save_file");
  printf("make_checkpoint_v1: %u particles, 2 frames, written to %s\n", added, argv[1]);
  sph_world_destroy(world);
  sph_context_destroy(context);
  return 0;
}
