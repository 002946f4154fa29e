// SPDX-License-Identifier: MIT
/* Two-way coupling through the C API (issue 17): a wooden box (500 kg/m^3) dropped onto water
 * floats. The box is a collider the fluid cannot enter; a small rigid-body integrator, standing in
 * for a game engine's, owns its motion: every frame it reads the fluid's force and torque on the
 * collider (sph_collider_get_loads, SPH_FEATURE_COLLIDER_LOADS, the torque about the box's centre
 * of mass set with sph_collider_set_load_point), adds gravity, integrates the body over the frame
 * and sends the pose it reaches as the collider's target (sph_collider_set_target_transform); the
 * library moves the collider there through the next frame's substeps, pushing the water. The walls
 * count in the density (SPH_FEATURE_BOUNDARY_DENSITY), so the pressure reaches the box's faces.
 * Every frame is written as CSV; every 15 frames a line gives the box's height and its draft
 * against Archimedes' (m / (rho0 A) = 5 cm here).
 *
 * The coupling is explicit: the body sees the loads of the frame before. A body much lighter than
 * the water it moves (its added mass) would overshoot with that lag; this one is half as dense as
 * water, and the frames are 1/120 s.
 *
 * Usage: floating_box [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda]
 *        (default out/floating_box_c, 360 frames, 3 s) */
#include <stdio.h>

#include "rigid_body.h" /* the engine's side: the body, its step and its pose */
#include "sample_io.h"
#include "sph_c.h"
#include "support.h"

int main(int argc, char** argv) {
  const char* out_dir = "out/floating_box_c";
  int frames = 360, frame, status = 1;
  sph_backend backend = SPH_BACKEND_AUTO;
  sph_context_def context_def;
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_world_def world_def;
  sph_world_params params;
  sph_shape_desc shape;
  sph_collider_def def;
  sph_collider_id box_id;
  /* The tank: inside 40 x 50 x 40 cm, floor at y = 0; water 20 cm deep. */
  const support_tank tank = {{0.0f, 0.25f, 0.0f}, {0.2f, 0.25f, 0.2f}, 0.01f, 0.0f};
  sph_fill_box_desc water;
  sph_sdf *tank_sdf = NULL, *box_sdf = NULL;
  const double half = 0.05, density = 500.0, rho0 = 1000.0, g = 9.81, dt = 1.0 / 120.0, water_depth = 0.2;
  const sph_vec3 centre_of_mass = {0.0f, 0.0f, 0.0f}; /* the box's origin */
  rigid_body body = {0};
  status = sample_parse_args(argc, argv, "floating_box", &out_dir, &frames, &backend);
  if (status != 0) return status;
  status = 1;
  body.mass = density * 8.0 * half * half * half;
  body.inertia = body.mass * (2.0 * half) * (2.0 * half) / 6.0;
  body.position[1] = water_depth + half + 0.01; /* 1 cm above the water */
  body.rotation[3] = 1.0;

  sph_context_def_init(&context_def);
  context_def.backend = backend;
  if (sample_failed(sph_context_create(&context_def, &context), "sph_context_create")) return 1;
  sph_world_def_init(&world_def);
  world_def.capacity = 12000;
  world_def.particle_spacing = 0.02f;
  world_def.features = SPH_FEATURE_COLLIDER_LOADS | SPH_FEATURE_BOUNDARY_DENSITY;
  if (sample_failed(sph_world_create(context, &world_def, &world), "sph_world_create")) goto done;
  sph_world_params_init(&params);
  if (sample_failed(sph_world_set_params(world, &params), "sph_world_set_params")) goto done;
  if (sample_failed(support_tank_create(context, world, &tank, &tank_sdf, NULL), "support_tank_create"))
    goto done;

  /* The box: a 10 cm cube; its SDF reaches 8 voxels beyond it, more than the kernel radius, as
   * the walls in the density need. */
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = (float)half;
  shape.voxel_size = 0.01f;
  shape.padding_voxels = 8;
  if (sample_failed(sph_sdf_create_shape(context, &shape, &box_sdf), "sph_sdf_create_shape")) goto done;
  sph_collider_def_init(&def);
  def.sdf = box_sdf;
  def.transform = rigid_body_pose(&body);
  if (sample_failed(sph_collider_create(world, &def, &box_id), "sph_collider_create")) goto done;
  if (sample_failed(sph_collider_set_load_point(world, box_id, &centre_of_mass),
                    "sph_collider_set_load_point"))
    goto done;

  sph_fill_box_desc_init(&water);
  water.min.x = -0.2f, water.min.y = 0.0f, water.min.z = -0.2f;
  water.max.x = 0.2f, water.max.y = (float)water_depth, water.max.z = 0.2f;
  if (sample_failed(sph_world_fill_box(world, &water, NULL), "sph_world_fill_box")) goto done;

  printf("floating_box: %d frames -> %s/ (Archimedes' draft %.1f cm)\n", frames, out_dir,
         100.0 * body.mass / (rho0 * 4.0 * half * half));
  if (sample_write_frame(world, out_dir, 0)) goto done;
  for (frame = 1; frame <= frames; ++frame) {
    sph_collider_loads loads;
    sph_transform target;
    if (sample_failed(sph_world_step(world, (float)dt), "sph_world_step")) goto done;
    sph_collider_loads_init(&loads);
    if (sample_failed(sph_collider_get_loads(world, box_id, &loads), "sph_collider_get_loads")) goto done;
    rigid_body_step(&body, &loads, g, dt);
    target = rigid_body_pose(&body);
    if (sample_failed(sph_collider_set_target_transform(world, box_id, &target),
                      "sph_collider_set_target_transform"))
      goto done;
    if (sample_write_frame(world, out_dir, frame)) goto done;
    if (frame % 15 == 0 || frame == frames)
      printf(
          "floating_box: t = %.3f s: centre at y = %.4f m (draft %.2f cm below y = %.3f m), "
          "vertical speed %+.3f m/s, fluid's force %.3f N (weight %.3f N)\n",
          frame * dt, body.position[1], 100.0 * (water_depth - (body.position[1] - half)), water_depth,
          body.velocity[1], loads.force.y, body.mass * g);
  }
  status = 0;

done:
  sph_sdf_destroy(tank_sdf);
  sph_sdf_destroy(box_sdf);
  sph_world_destroy(world);
  sph_context_destroy(context);
  return status;
}
