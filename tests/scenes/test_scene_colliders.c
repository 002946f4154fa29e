// SPDX-License-Identifier: MIT
/* Colliders against analytic expectations (issue 4, item 6): restitution, Coulomb friction,
 * no penetration of a static tank, no tunnelling through a fast paddle, a rotating cup that
 * holds its water, and a deforming floor that carries a particle with its surface. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene_test.h"

static const float kG = 9.81f;

static sph_collider_id add_collider(scene* s, sph_sdf* sdf, sph_transform t, uint32_t flags,
                                    float restitution, float friction) {
  sph_collider_def def;
  sph_collider_id id;
  sph_collider_def_init(&def);
  def.sdf = sdf;
  def.transform = t;
  def.flags = flags;
  def.restitution = restitution;
  def.friction = friction;
  SCENE_OK(sph_collider_create(s->world, &def, &id));
  return id;
}

static sph_sdf* floor_plane(scene* s, float half_size, float half_thickness) {
  sph_shape_desc d;
  sph_shape_desc_init(&d);
  d.shape = SPH_SHAPE_PLANE;
  d.half_extents.x = half_size;
  d.half_extents.y = half_thickness;
  d.half_extents.z = half_size;
  d.voxel_size = 0.01f;
  return scene_shape(s, &d);
}

/* A particle dropped from 0.2 m leaves the floor with e times its impact speed
 * sqrt(2 g h). Tolerance 1 % (the issue's); symplectic Euler at dt = 1e-4 s misses the
 * impact speed by about g dt / v = 0.05 %. */
static void test_bounce_leaves_with_restitution(void** state) {
  const float restitutions[3] = {0.25f, 0.5f, 0.9f};
  int r;
  (void)state;
  for (r = 0; r < 3; ++r) {
    scene s;
    sph_sdf* plane;
    uint32_t id;
    float p[3], v[3], previous_vy = 0.0f, expected;
    int frame, bounced = 0;
    scene_open(&s, 16, 0.02f, -kG, 1e-4f);
    plane = floor_plane(&s, 0.5f, 0.1f);
    add_collider(&s, plane, sph_transform_identity(), 0, restitutions[r], 0.0f);
    id = scene_spawn_one(&s, 0.0f, 0.2f, 0.0f, 0.0f, 0.0f, 0.0f);
    for (frame = 0; frame < 3000 && !bounced; ++frame) {
      SCENE_OK(sph_world_step(s.world, 1e-4f));
      scene_particle(&s, id, p, v);
      if (v[1] > 0.0f && previous_vy < 0.0f)
        bounced = 1;
      else
        previous_vy = v[1];
    }
    assert_true(bounced);
    expected = restitutions[r] * sqrtf(2.0f * kG * 0.2f);
    assert_true(fabsf(v[1] - expected) <= 0.01f * expected);
    assert_true(p[1] >= -1e-4f); /* it left from the surface, not from inside */
    SCENE_OK(sph_sdf_destroy(plane));
    scene_close(&s);
  }
}

/* A particle sliding at v0 on a floor with Coulomb friction mu decelerates at mu g and stops
 * after v0^2 / (2 mu g). Tolerance 2 %: the discrete impulses (dt = 1e-4 s) shift the
 * stopping distance by about v0 dt / d = 0.1 %. */
static void test_sliding_stops_where_coulomb_predicts(void** state) {
  const float v0 = 1.0f, mu = 0.4f;
  const float expected_distance = v0 * v0 / (2.0f * mu * kG);
  const float expected_time = v0 / (mu * kG);
  scene s;
  sph_sdf* plane;
  uint32_t id;
  float p[3], v[3], stop_time = -1.0f;
  int frame;
  (void)state;
  scene_open(&s, 16, 0.02f, -kG, 1e-4f);
  plane = floor_plane(&s, 0.5f, 0.1f);
  add_collider(&s, plane, sph_transform_identity(), 0, 0.0f, mu);
  id = scene_spawn_one(&s, -0.2f, 0.0f, 0.0f, v0, 0.0f, 0.0f);
  for (frame = 0; frame < 400; ++frame) {
    SCENE_OK(sph_world_step(s.world, 1e-3f));
    scene_particle(&s, id, p, v);
    if (stop_time < 0.0f && v[0] <= 1e-6f) stop_time = (float)(frame + 1) * 1e-3f;
  }
  assert_true(stop_time > 0.0f);
  assert_true(fabsf(v[0]) < 1e-6f);
  assert_true(fabsf((p[0] + 0.2f) - expected_distance) <= 0.02f * expected_distance);
  assert_true(fabsf(stop_time - expected_time) <= 0.02f * expected_time);
  assert_true(fabsf(p[1]) < 1e-3f);
  SCENE_OK(sph_sdf_destroy(plane));
  scene_close(&s);
}

/* A dam break in a closed tank (an inverted box collider): over 1,020 substeps no particle
 * goes deeper into a wall than half a spacing (the bound). */
static void test_dam_break_stays_in_tank(void** state) {
  const float spacing = 0.02f;
  const support_tank tank = {{0.0f, 0.3f, 0.0f}, {0.5f, 0.3f, 0.1f}, 0.01f, 0.0f};
  const sph_vec3 column_min = {-0.5f, 0.0f, -0.1f}, column_max = {-0.2f, 0.4f, 0.1f};
  scene s;
  sph_sdf* box;
  uint32_t n = 0, total_substeps = 0, i;
  float* x;
  float worst = -1.0f;
  int frame;
  (void)state;
  scene_open(&s, 8000, spacing, -kG, 1e-3f);
  SCENE_OK(support_dam_break(s.context, s.world, &tank, column_min, column_max, &box, NULL, &n));
  assert_true(n > 1000);
  x = malloc(12 * (size_t)n);
  assert_non_null(x);
  for (frame = 0; frame < 60; ++frame) {
    sph_stats st;
    SCENE_OK(sph_world_step(s.world, 1.0f / 60.0f));
    sph_stats_init(&st);
    SCENE_OK(sph_world_get_stats(s.world, &st));
    total_substeps += st.substeps;
    assert_int_equal(scene_positions(&s, x, n), n);
    for (i = 0; i < n; ++i) {
      /* depth beyond the tank's interior [-0.5, 0.5] x [0, 0.6] x [-0.1, 0.1] */
      const float depth =
          fmaxf(fmaxf(fabsf(x[3 * i]) - 0.5f, fabsf(x[3 * i + 1] - 0.3f) - 0.3f), fabsf(x[3 * i + 2]) - 0.1f);
      worst = fmaxf(worst, depth);
    }
  }
  assert_true(total_substeps >= 1000);
  assert_true(worst < 0.5f * spacing);
  free(x);
  SCENE_OK(sph_sdf_destroy(box));
  scene_close(&s);
}

/* A thin paddle (2 cm) driven at 4 m/s through water in a channel it fills: no particle may
 * end up behind it. The paddle spans the channel's whole cross-section, so a particle behind
 * it could only have passed through. */
static void test_fast_paddle_does_not_tunnel(void** state) {
  const float spacing = 0.02f, speed = 4.0f, half_thickness = 0.01f;
  scene s;
  sph_shape_desc d;
  sph_sdf *channel, *paddle;
  sph_collider_id paddle_id;
  sph_fill_box_desc fill;
  uint32_t n = 0, i;
  float* x;
  float paddle_x = -0.3f;
  int frame;
  (void)state;
  scene_open(&s, 8000, spacing, -kG, 1e-3f);
  sph_shape_desc_init(&d);
  d.shape = SPH_SHAPE_BOX;
  d.half_extents.x = 0.4f;
  d.half_extents.y = 0.2f;
  d.half_extents.z = 0.06f;
  d.voxel_size = 0.01f;
  channel = scene_shape(&s, &d);
  add_collider(&s, channel, scene_at(0.0f, 0.2f, 0.0f), SPH_COLLIDER_FLAG_INVERTED, 0.0f, 0.0f);
  d.half_extents.x = half_thickness;
  d.half_extents.y = 0.3f;
  d.half_extents.z = 0.1f;
  d.voxel_size = 0.005f;
  paddle = scene_shape(&s, &d);
  paddle_id = add_collider(&s, paddle, scene_at(paddle_x, 0.2f, 0.0f), 0, 0.0f, 0.0f);
  sph_fill_box_desc_init(&fill);
  fill.min.x = -0.25f;
  fill.min.y = 0.0f;
  fill.min.z = -0.06f;
  fill.max.x = 0.3f;
  fill.max.y = 0.12f;
  fill.max.z = 0.06f;
  SCENE_OK(sph_world_fill_box(s.world, &fill, &n));
  x = malloc(12 * (size_t)n);
  assert_non_null(x);
  for (frame = 0; frame < 10; ++frame) {
    sph_transform target;
    paddle_x += speed * 0.01f;
    target = scene_at(paddle_x, 0.2f, 0.0f);
    SCENE_OK(sph_collider_set_target_transform(s.world, paddle_id, &target));
    SCENE_OK(sph_world_step(s.world, 0.01f));
    assert_int_equal(scene_positions(&s, x, n), n);
    for (i = 0; i < n; ++i) assert_true(x[3 * i] >= paddle_x + half_thickness - 0.25f * spacing);
  }
  free(x);
  SCENE_OK(sph_sdf_destroy(channel));
  SCENE_OK(sph_sdf_destroy(paddle));
  scene_close(&s);
}

/* Poses handed back: a rotation read with sph_collider_get_transform and given again (teleport or
 * target) is the same rotation bit for bit, for 2,000 rotations that the library normalised from
 * non-unit quaternions (dividing a unit quaternion by its float length again moved a last bit in
 * about a third of them, so a collider told to stay counted as moving); quaternions and vortex
 * axes far from unit length (1e20, 1e-30) are normalised, not refused. A step that stops early
 * (max_substeps 1, SPH_INCOMPLETE) leaves a moving collider at the pose of the time reached, its
 * target pending; the next step takes it the rest of the way. */
static void test_pose_round_trip_and_incomplete_motion(void** state) {
  scene s;
  sph_shape_desc d;
  sph_sdf* ball;
  sph_collider_id id;
  sph_transform t, a, b;
  sph_stats stats;
  sph_force_field_def field;
  sph_force_field_id field_id;
  uint32_t seed = 12345u, i, moved = 0;
  float expected;
  (void)state;
  scene_open(&s, 64, 0.02f, -kG, 1e-3f);
  sph_shape_desc_init(&d);
  d.shape = SPH_SHAPE_SPHERE;
  d.radius = 0.05f;
  d.voxel_size = 0.01f;
  ball = scene_shape(&s, &d);
  id = add_collider(&s, ball, scene_at(-1.0f, 0.5f, 0.0f), 0, 0.0f, 0.0f);
  for (i = 0; i < 2000; ++i) {
    float q[4];
    int k;
    for (k = 0; k < 4; ++k) {
      seed = seed * 1664525u + 1013904223u;
      q[k] = (float)(seed >> 8) / 16777216.0f * 2.0f - 1.0f;
    }
    t = scene_at(-1.0f, 0.5f, 0.0f);
    t.rotation.x = q[0], t.rotation.y = q[1], t.rotation.z = q[2], t.rotation.w = q[3] + 2.0f;
    SCENE_OK(sph_collider_teleport(s.world, id, &t));
    SCENE_OK(sph_collider_get_transform(s.world, id, &a));
    moved += memcmp(&a.rotation, &t.rotation, sizeof a.rotation) != 0;
    SCENE_OK(sph_collider_teleport(s.world, id, &a));
    SCENE_OK(sph_collider_get_transform(s.world, id, &b));
    assert_memory_equal(&a, &b, sizeof a);
    SCENE_OK(sph_collider_set_target_transform(s.world, id, &a));
    SCENE_OK(sph_collider_get_transform(s.world, id, &b));
    assert_memory_equal(&a, &b, sizeof a);
  }
  assert_true(moved > 1000); /* the inputs were not unit quaternions: the library normalised them */
  SCENE_OK(sph_world_step(s.world, 0.01f));
  SCENE_OK(sph_collider_get_transform(s.world, id, &b));
  assert_memory_equal(&a, &b, sizeof a);

  /* Far from unit length: normalised in double. */
  t = scene_at(-1.0f, 0.5f, 0.0f);
  t.rotation.x = t.rotation.y = t.rotation.z = 0.0f;
  t.rotation.w = 1e20f;
  SCENE_OK(sph_collider_teleport(s.world, id, &t));
  SCENE_OK(sph_collider_get_transform(s.world, id, &a));
  assert_true(a.rotation.w == 1.0f && a.rotation.x == 0.0f && a.rotation.y == 0.0f && a.rotation.z == 0.0f);
  sph_force_field_def_init(&field);
  field.kind = SPH_FORCE_FIELD_VORTEX;
  field.vector.x = 1e-30f;
  field.strength = 1.0f;
  SCENE_OK(sph_force_field_create(s.world, &field, &field_id));
  field.vector.x = 1e20f;
  SCENE_OK(sph_force_field_create(s.world, &field, &field_id));

  /* Stopped early: the pose of the time reached, then the rest of the way. */
  SCENE_OK(sph_collider_teleport(s.world, id, &t));
  scene_spawn_one(&s, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f);
  s.params.max_substeps = 1;
  scene_set_params(&s);
  t = scene_at(1.0f, 0.5f, 0.0f);
  SCENE_OK(sph_collider_set_target_transform(s.world, id, &t));
  assert_int_equal(sph_world_step(s.world, 1.0f / 30.0f), SPH_INCOMPLETE);
  sph_stats_init(&stats);
  SCENE_OK(sph_world_get_stats(s.world, &stats));
  assert_true(stats.frame_time > 0.0f && stats.frame_time < 0.5f / 30.0f);
  SCENE_OK(sph_collider_get_transform(s.world, id, &a));
  expected = -1.0f + 2.0f * stats.frame_time * 30.0f;
  print_message("  stopped after %.6f s of 1/30: the collider at x = %.6f (expected %.6f)\n",
                (double)stats.frame_time, (double)a.position.x, (double)expected);
  assert_true(fabsf(a.position.x - expected) < 1e-5f);
  s.params.max_substeps = 0; /* the default */
  scene_set_params(&s);
  SCENE_OK(sph_world_step(s.world, 1.0f / 30.0f));
  SCENE_OK(sph_collider_get_transform(s.world, id, &a));
  assert_true(a.position.x == 1.0f);
  SCENE_OK(sph_sdf_destroy(ball));
  scene_close(&s);
}

/* Water in a cup spun about its axis at 4 rad/s for a second: every particle stays inside the
 * cup's cavity (radius 8 cm, floor at -6 cm), within a quarter spacing. */
static void test_rotating_cup_holds_water(void** state) {
  const float spacing = 0.01f, omega = 4.0f, inner = 0.08f, floor_y = -0.06f;
  scene s;
  sph_shape_desc d;
  sph_sdf* cup;
  sph_collider_id cup_id;
  sph_fill_box_desc fill;
  uint32_t n = 0, i;
  float* x;
  int frame;
  (void)state;
  scene_open(&s, 4000, spacing, -kG, 1e-3f);
  sph_shape_desc_init(&d);
  d.shape = SPH_SHAPE_CUP;
  d.radius = inner;
  d.half_height = 0.08f;
  d.wall_thickness = 0.02f;
  d.voxel_size = 0.005f;
  cup = scene_shape(&s, &d);
  cup_id = add_collider(&s, cup, sph_transform_identity(), 0, 0.0f, 0.3f);
  sph_fill_box_desc_init(&fill);
  fill.min.x = -0.05f;
  fill.min.y = floor_y;
  fill.min.z = -0.05f;
  fill.max.x = 0.05f;
  fill.max.y = 0.0f;
  fill.max.z = 0.05f;
  SCENE_OK(sph_world_fill_box(s.world, &fill, &n));
  assert_true(n > 300);
  x = malloc(12 * (size_t)n);
  assert_non_null(x);
  for (frame = 0; frame < 75; ++frame) {
    if (frame >= 15) { /* settle first, then spin */
      const float angle = omega * (float)(frame - 14) / 60.0f;
      sph_transform target = sph_transform_identity();
      target.rotation.y = sinf(0.5f * angle);
      target.rotation.w = cosf(0.5f * angle);
      SCENE_OK(sph_collider_set_target_transform(s.world, cup_id, &target));
    }
    SCENE_OK(sph_world_step(s.world, 1.0f / 60.0f));
    assert_int_equal(scene_positions(&s, x, n), n);
    for (i = 0; i < n; ++i) {
      const float r = sqrtf(x[3 * i] * x[3 * i] + x[3 * i + 2] * x[3 * i + 2]);
      assert_true(r <= inner + 0.25f * spacing);
      assert_true(x[3 * i + 1] >= floor_y - 0.25f * spacing);
    }
  }
  free(x);
  SCENE_OK(sph_sdf_destroy(cup));
  scene_close(&s);
}

/* A floor whose surface rises at 0.5 m/s, given as a velocity field and distance updates per
 * frame: the particle on it rides with the surface (the collider's normal velocity is matched
 * because it is faster than the falling particle's). After 0.5 s the surface is at 0.25 m. */
static void test_deforming_floor_carries_particle(void** state) {
  const float rise = 0.5f;
  scene s;
  sph_sdf* plane;
  uint32_t dims[3], origin[3] = {0, 0, 0}, id, i, j, k;
  float *velocity, *distance, p[3], v[3];
  float probe_at_zero = 0.0f;
  int frame;
  sph_vec3 zero = {0.0f, 0.0f, 0.0f};
  (void)state;
  scene_open(&s, 16, 0.02f, -kG, 1e-3f);
  plane = floor_plane(&s, 0.1f, 0.4f);
  SCENE_OK(sph_sdf_get_dims(plane, dims));
  velocity = malloc(sizeof(float) * 3 * dims[0] * dims[1] * dims[2]);
  distance = malloc(sizeof(float) * dims[0] * dims[1] * dims[2]);
  assert_non_null(velocity);
  assert_non_null(distance);
  for (i = 0; i < dims[0] * dims[1] * dims[2]; ++i) {
    velocity[3 * i] = 0.0f;
    velocity[3 * i + 1] = rise;
    velocity[3 * i + 2] = 0.0f;
  }
  SCENE_OK(sph_sdf_update(plane, SPH_SDF_CHANNEL_VELOCITY, origin, dims, velocity, SPH_MEMORY_HOST));
  SCENE_OK(sph_sdf_sample(plane, zero, &probe_at_zero));
  assert_true(fabsf(probe_at_zero) < 1e-6f);
  add_collider(&s, plane, sph_transform_identity(), 0, 0.0f, 0.0f);
  id = scene_spawn_one(&s, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f);
  for (frame = 0; frame < 30; ++frame) {
    const float surface = rise * (float)frame / 60.0f;
    /* The grid's voxel centres: y = (j - (ny - 1) / 2) * 0.01 m. */
    for (k = 0; k < dims[2]; ++k)
      for (j = 0; j < dims[1]; ++j)
        for (i = 0; i < dims[0]; ++i)
          distance[i + dims[0] * (j + dims[1] * k)] =
              ((float)j - 0.5f * (float)(dims[1] - 1)) * 0.01f - surface;
    SCENE_OK(sph_sdf_update(plane, SPH_SDF_CHANNEL_DISTANCE, origin, dims, distance, SPH_MEMORY_HOST));
    SCENE_OK(sph_world_step(s.world, 1.0f / 60.0f));
  }
  scene_particle(&s, id, p, v);
  /* The surface is at 0.25 m; the particle sits on it (within a millimetre: one substep of
   * gravity) and moves with it (within 1 %). */
  assert_true(fabsf(p[1] - 0.25f) < 1e-3f);
  assert_true(fabsf(v[1] - rise) <= 0.01f * rise);
  free(velocity);
  free(distance);
  SCENE_OK(sph_sdf_destroy(plane));
  scene_close(&s);
}

/* sph_world_restore of a checkpoint whose floor the caller has not changed since the save keeps
 * the caller's asset: a later sph_sdf_update of it moves the restored world's floor (the particle
 * resting on it is lifted with it), as it moves the world before the restore. A world loaded from
 * the same checkpoint holds its own copy, which the update does not reach (docs/checkpoint.md).
 * Before, the restored world held a copy too, and its floor stayed where it was. */
static void test_restore_keeps_the_callers_asset(void** state) {
  const float lift = 0.1f;
  scene s, l;
  sph_sdf* plane;
  sph_world* loaded = NULL;
  uint32_t dims[3], origin[3] = {0, 0, 0}, id, i, j, k;
  uint64_t size = 0;
  unsigned char* saved;
  float *distance, p[3], v[3], q[3];
  int frame;
  (void)state;
  scene_open(&s, 16, 0.02f, -kG, 1e-3f);
  plane = floor_plane(&s, 0.1f, 0.4f);
  add_collider(&s, plane, sph_transform_identity(), 0, 0.0f, 0.0f);
  id = scene_spawn_one(&s, 0.0f, 0.03f, 0.0f, 0.0f, 0.0f, 0.0f);
  for (frame = 0; frame < 20; ++frame) SCENE_OK(sph_world_step(s.world, 1.0f / 60.0f));
  SCENE_OK(sph_world_save(s.world, NULL, 0, &size));
  saved = (unsigned char*)malloc((size_t)size);
  assert_non_null(saved);
  SCENE_OK(sph_world_save(s.world, saved, size, &size));
  SCENE_OK(sph_world_step(s.world, 1.0f / 60.0f));
  SCENE_OK(sph_world_restore(s.world, saved, size));
  SCENE_OK(sph_world_load(s.context, saved, size, &loaded));
  /* The floor rises by 10 cm: the grid's voxel centres are at y = (j - (ny - 1) / 2) * 0.01 m. */
  SCENE_OK(sph_sdf_get_dims(plane, dims));
  distance = (float*)malloc(sizeof(float) * dims[0] * dims[1] * dims[2]);
  assert_non_null(distance);
  for (k = 0; k < dims[2]; ++k)
    for (j = 0; j < dims[1]; ++j)
      for (i = 0; i < dims[0]; ++i)
        distance[i + dims[0] * (j + dims[1] * k)] = ((float)j - 0.5f * (float)(dims[1] - 1)) * 0.01f - lift;
  SCENE_OK(sph_sdf_update(plane, SPH_SDF_CHANNEL_DISTANCE, origin, dims, distance, SPH_MEMORY_HOST));
  for (frame = 0; frame < 30; ++frame) {
    SCENE_OK(sph_world_step(s.world, 1.0f / 60.0f));
    SCENE_OK(sph_world_step(loaded, 1.0f / 60.0f));
  }
  scene_particle(&s, id, p, v);
  l = s;
  l.world = loaded;
  scene_particle(&l, id, q, v);
  /* Restored: on the lifted floor (within a few millimetres: the push-out's placement and a
   * substep of gravity). Loaded: still on the old floor at y = 0. */
  assert_true(fabsf(p[1] - lift) < 5e-3f);
  assert_true(fabsf(q[1]) < 5e-3f);
  SCENE_OK(sph_world_destroy(loaded));
  free(distance);
  free(saved);
  SCENE_OK(sph_sdf_destroy(plane));
  scene_close(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bounce_leaves_with_restitution),
      cmocka_unit_test(test_sliding_stops_where_coulomb_predicts),
      cmocka_unit_test(test_dam_break_stays_in_tank),
      cmocka_unit_test(test_fast_paddle_does_not_tunnel),
      cmocka_unit_test(test_pose_round_trip_and_incomplete_motion),
      cmocka_unit_test(test_rotating_cup_holds_water),
      cmocka_unit_test(test_deforming_floor_carries_particle),
      cmocka_unit_test(test_restore_keeps_the_callers_asset),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
