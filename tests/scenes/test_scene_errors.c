// SPDX-License-Identifier: MIT
/* Error paths of the scene API: every bad argument gets its code and a message naming it,
 * and the world keeps its objects (a failed create adds nothing; a stale id stays stale). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene_test.h"

#define EXPECT(expected, name, call) expect_error((call), (expected), (name), #call, __LINE__)

static void expect_error(sph_result got, sph_result expected, const char* name, const char* call, int line) {
  if (got != expected) {
    print_error("line %d: %s returned %d, expected %d (%s)\n", line, call, got, expected,
                sph_get_last_error());
    fail();
  }
  if (name && !strstr(sph_get_last_error(), name)) {
    print_error("line %d: %s: message '%s' does not name '%s'\n", line, call, sph_get_last_error(), name);
    fail();
  }
}

static void test_sdf_errors(void** state) {
  scene s;
  sph_sdf_desc desc;
  sph_shape_desc shape;
  sph_sdf* sdf = NULL;
  float data[8] = {-1, -1, -1, -1, 1, 1, 1, 1};
  uint32_t origin[3] = {0, 0, 0}, size[3] = {2, 2, 2}, too_big[3] = {3, 2, 2}, dims[3];
  float nan_data[8];
  (void)state;
  scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
  sph_sdf_desc_init(&desc);
  desc.distance.dims[0] = desc.distance.dims[1] = desc.distance.dims[2] = 2;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "data", sph_sdf_create(s.context, &desc, &sdf));
  desc.distance.data = data;
  EXPECT(SPH_ERROR_INVALID_HANDLE, "context", sph_sdf_create(NULL, &desc, &sdf));
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "out", sph_sdf_create(s.context, &desc, NULL));
  desc.distance.dims[1] = 0;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "dims", sph_sdf_create(s.context, &desc, &sdf));
  desc.distance.dims[1] = 2;
  desc.distance.index_to_local[0] = 0.0f; /* singular */
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "desc->distance.index_to_local", sph_sdf_create(s.context, &desc, &sdf));
  desc.distance.index_to_local[0] = 1.0f;
  memcpy(nan_data, data, sizeof data);
  nan_data[3] = NAN;
  desc.distance.data = nan_data;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "data[3]", sph_sdf_create(s.context, &desc, &sdf));
  desc.distance.data = data;
  desc.distance.memory = SPH_MEMORY_CUDA_DEVICE;
  if (sph_test_backend() == SPH_BACKEND_CPU)
    EXPECT(SPH_ERROR_UNSUPPORTED, "memory", sph_sdf_create(s.context, &desc, &sdf));
  desc.distance.memory = (sph_memory_kind)7;
  EXPECT(SPH_ERROR_UNSUPPORTED, "memory", sph_sdf_create(s.context, &desc, &sdf));
  desc.distance.memory = SPH_MEMORY_HOST;
  desc.distance.components = 3;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "components", sph_sdf_create(s.context, &desc, &sdf));
  desc.distance.components = 1;
  desc.struct_size = 8;
  EXPECT(SPH_ERROR_VERSION_MISMATCH, "struct_size", sph_sdf_create(s.context, &desc, &sdf));
  desc.struct_size = sizeof desc;
  assert_null(sdf); /* no failed call wrote its out-parameter */
  SCENE_OK(sph_sdf_create(s.context, &desc, &sdf));

  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "origin",
         sph_sdf_update(sdf, SPH_SDF_CHANNEL_DISTANCE, origin, too_big, data, SPH_MEMORY_HOST));
  EXPECT(SPH_ERROR_UNSUPPORTED, "channel",
         sph_sdf_update(sdf, (sph_sdf_channel)9, origin, size, data, SPH_MEMORY_HOST));
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "size",
         sph_sdf_update(sdf, SPH_SDF_CHANNEL_DISTANCE, origin, NULL, data, SPH_MEMORY_HOST));
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "data",
         sph_sdf_update(sdf, SPH_SDF_CHANNEL_DISTANCE, origin, size, NULL, SPH_MEMORY_HOST));
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "data[3]",
         sph_sdf_update(sdf, SPH_SDF_CHANNEL_DISTANCE, origin, size, nan_data, SPH_MEMORY_HOST));
  SCENE_OK(sph_sdf_get_dims(sdf, dims));
  assert_int_equal(dims[0], 2);

  sph_shape_desc_init(&shape);
  shape.shape = (sph_shape)42;
  EXPECT(SPH_ERROR_UNSUPPORTED, "shape", sph_sdf_create_shape(s.context, &shape, &sdf));
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = -1.0f;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "radius", sph_sdf_create_shape(s.context, &shape, &sdf));
  shape.radius = 0.1f;
  shape.voxel_size = -0.01f; /* (0 is the default) */
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "voxel_size", sph_sdf_create_shape(s.context, &shape, &sdf));
  shape.voxel_size = 1e-6f; /* 2e5 voxels per axis */
  EXPECT(SPH_ERROR_CAPACITY, "voxel", sph_sdf_create_shape(s.context, &shape, &sdf));
  shape.voxel_size = 0.01f;
  shape.shape = SPH_SHAPE_CUP;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "wall_thickness", sph_sdf_create_shape(s.context, &shape, &sdf));

  /* A context with live SDF assets cannot go. */
  SCENE_OK(sph_world_destroy(s.world));
  EXPECT(SPH_ERROR_BUSY, "SDF", sph_context_destroy(s.context));
  SCENE_OK(sph_sdf_destroy(sdf));
  EXPECT(SPH_ERROR_INVALID_HANDLE, "sdf", sph_sdf_destroy(sdf));
  SCENE_OK(sph_sdf_destroy(NULL));
  SCENE_OK(sph_context_destroy(s.context));
}

static void test_collider_errors(void** state) {
  scene s, other;
  sph_shape_desc shape;
  sph_sdf *sdf, *foreign;
  sph_collider_def def;
  sph_collider_id id, null_id = {0}, stale;
  sph_transform t = sph_transform_identity();
  (void)state;
  scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
  scene_open(&other, 16, 0.02f, 0.0f, 1e-3f);
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.1f;
  sdf = scene_shape(&s, &shape);
  foreign = scene_shape(&other, &shape);
  sph_collider_def_init(&def);
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "def->sdf", sph_collider_create(s.world, &def, &id));
  def.sdf = foreign;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "another context", sph_collider_create(s.world, &def, &id));
  def.sdf = sdf;
  def.restitution = 1.5f;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "restitution", sph_collider_create(s.world, &def, &id));
  def.restitution = 0.5f;
  def.friction = -1.0f;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "friction", sph_collider_create(s.world, &def, &id));
  def.friction = 0.0f;
  def.stickiness = NAN;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "stickiness", sph_collider_create(s.world, &def, &id));
  def.stickiness = 0.0f;
  def.flags = 0x80;
  EXPECT(SPH_ERROR_UNSUPPORTED, "flags", sph_collider_create(s.world, &def, &id));
  def.flags = 0;
  def.transform.rotation.w = 1e-7f; /* (all zero is the identity) */
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "rotation", sph_collider_create(s.world, &def, &id));
  def.transform.rotation.w = NAN;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "rotation", sph_collider_create(s.world, &def, &id));
  def.transform.rotation.w = 1.0f;
  def.transform.position.y = INFINITY;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "position", sph_collider_create(s.world, &def, &id));
  def.transform.position.y = 0.0f;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "out_id", sph_collider_create(s.world, &def, NULL));
  SCENE_OK(sph_collider_create(s.world, &def, &id));

  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "target", sph_collider_set_target_transform(s.world, id, NULL));
  EXPECT(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_set_target_transform(s.world, null_id, &t));
  EXPECT(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_set_target_transform(other.world, id, &t));
  {
    sph_collider_material material;
    sph_collider_material_init(&material);
    material.restitution = -0.1f;
    EXPECT(SPH_ERROR_INVALID_ARGUMENT, "restitution", sph_collider_set_material(s.world, id, &material));
  }
  stale = id;
  SCENE_OK(sph_collider_destroy(s.world, id));
  EXPECT(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_destroy(s.world, stale));
  EXPECT(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_teleport(s.world, stale, &t));
  EXPECT(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_get_transform(s.world, stale, &t));
  SCENE_OK(sph_collider_destroy(s.world, null_id)); /* null id: no-op */
  /* A new collider in the freed slot does not revive the stale id. */
  SCENE_OK(sph_collider_create(s.world, &def, &id));
  assert_true(id.bits != stale.bits);
  EXPECT(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_teleport(s.world, stale, &t));
  EXPECT(SPH_ERROR_INVALID_HANDLE, "world", sph_collider_create(NULL, &def, &id));

  SCENE_OK(sph_sdf_destroy(sdf));
  SCENE_OK(sph_sdf_destroy(foreign));
  /* The collider keeps its asset alive after the handle is gone: stepping still works. */
  SCENE_OK(sph_world_step(s.world, 0.01f));
  scene_close(&s);
  scene_close(&other);
}

static void test_source_sink_field_errors(void** state) {
  scene s;
  sph_shape_desc shape;
  sph_sdf* sdf;
  sph_source_def source;
  sph_source_id source_id;
  sph_sink_def sink;
  sph_sink_id sink_id;
  sph_force_field_def field;
  sph_force_field_id field_id;
  sph_grid_desc grid;
  uint32_t count = 0, ids[1];
  (void)state;
  scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.1f;
  sdf = scene_shape(&s, &shape);

  sph_source_def_init(&source);
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "def->region", sph_source_create(s.world, &source, &source_id));
  source.region = sdf;
  source.mode = (sph_source_mode)5;
  EXPECT(SPH_ERROR_UNSUPPORTED, "mode", sph_source_create(s.world, &source, &source_id));
  source.mode = SPH_SOURCE_CONTINUOUS;
  source.min_distance = 1.0f;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "min_distance", sph_source_create(s.world, &source, &source_id));
  source.min_distance = 0.0f;
  source.rate = -1.0f;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "rate", sph_source_create(s.world, &source, &source_id));
  source.rate = 0.0f;
  source.flags = SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "velocity", sph_source_create(s.world, &source, &source_id));
  source.flags = 0;
  source.spacing = 1e-5f;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "spacing", sph_source_create(s.world, &source, &source_id));
  source.spacing = 0.0f;
  SCENE_OK(sph_source_create(s.world, &source, &source_id));
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "transform", sph_source_set_transform(s.world, source_id, NULL));

  sph_sink_def_init(&sink);
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "def->region", sph_sink_create(s.world, &sink, &sink_id));
  sink.mode = SPH_SINK_OUTSIDE_BOUNDS;
  sink.bounds_min.x = 1.0f;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "bounds_max", sph_sink_create(s.world, &sink, &sink_id));
  sink.mode = (sph_sink_mode)3;
  EXPECT(SPH_ERROR_UNSUPPORTED, "mode", sph_sink_create(s.world, &sink, &sink_id));

  sph_force_field_def_init(&field);
  field.kind = SPH_FORCE_FIELD_VORTEX;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "vector", sph_force_field_create(s.world, &field, &field_id));
  field.kind = SPH_FORCE_FIELD_GRID;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "def->grid", sph_force_field_create(s.world, &field, &field_id));
  sph_grid_desc_init(&grid);
  grid.dims[0] = grid.dims[1] = grid.dims[2] = 1;
  grid.components = 1; /* (0 means 3 here) */
  field.grid = &grid;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "components", sph_force_field_create(s.world, &field, &field_id));
  {
    float zero3[3] = {0.0f, 0.0f, 0.0f};
    grid.components = 3;
    grid.data = zero3;
    grid.index_to_local[0] = NAN; /* the asset's own check, named by the caller's field */
    EXPECT(SPH_ERROR_INVALID_ARGUMENT, "def->grid->index_to_local",
           sph_force_field_create(s.world, &field, &field_id));
    grid.index_to_local[0] = 1.0f;
    grid.components = 1;
    grid.data = NULL;
  }
  field.kind = (sph_force_field_kind)11;
  EXPECT(SPH_ERROR_UNSUPPORTED, "kind", sph_force_field_create(s.world, &field, &field_id));
  field.kind = SPH_FORCE_FIELD_RADIAL;
  field.falloff_radius = -1.0f;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "falloff_radius", sph_force_field_create(s.world, &field, &field_id));

  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "out_count", sph_world_get_removed_ids(s.world, ids, 1, NULL));
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "ids", sph_world_get_removed_ids(s.world, NULL, 1, &count));
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "events", sph_world_get_events(s.world, NULL, 2, &count));
  SCENE_OK(sph_source_destroy(s.world, source_id));
  EXPECT(SPH_ERROR_INVALID_HANDLE, "id", sph_source_destroy(s.world, source_id));
  /* An id of one kind is not accepted as another. */
  sink_id.bits = source_id.bits;
  EXPECT(SPH_ERROR_INVALID_HANDLE, "id", sph_sink_destroy(s.world, sink_id));
  SCENE_OK(sph_sdf_destroy(sdf));
  scene_close(&s);
}

/* A failed step with a source undoes the emission: a source and an absurd dt that produces a
 * non-finite state leaves the world as it was (no particles, the source still pending). */
static void test_failed_step_undoes_emission(void** state) {
  scene s;
  sph_shape_desc shape;
  sph_sdf* sdf;
  sph_source_def source;
  sph_source_id id;
  sph_force_field_def field;
  sph_force_field_id field_id;
  uint32_t n = 0;
  (void)state;
  scene_open(&s, 4000, 0.02f, 0.0f, 1e-3f);
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.06f;
  sdf = scene_shape(&s, &shape);
  sph_source_def_init(&source);
  source.region = sdf;
  SCENE_OK(sph_source_create(s.world, &source, &id));
  /* A uniform field of 3e38 m/s^2 overflows float in the first substep. */
  sph_force_field_def_init(&field);
  field.vector.x = 3e38f;
  SCENE_OK(sph_force_field_create(s.world, &field, &field_id));
  EXPECT(SPH_ERROR_NON_FINITE, "non-finite", sph_world_step(s.world, 0.01f));
  SCENE_OK(sph_world_get_particle_count(s.world, &n));
  assert_int_equal(n, 0);
  SCENE_OK(sph_force_field_destroy(s.world, field_id));
  SCENE_OK(sph_world_step(s.world, 0.001f));
  SCENE_OK(sph_world_get_particle_count(s.world, &n));
  assert_true(n > 50);
  SCENE_OK(sph_sdf_destroy(sdf));
  scene_close(&s);
}

/* A source whose lattice would lie beyond the particles' reach (65536 spacings: 1310.72 m at
 * 2 cm) is refused like a spawn there, at create and at set_transform (naming transform, the
 * source kept where it was); before, emission put particles there unchecked (at 1e30 m every
 * one at the same float). */
static void test_source_reach(void** state) {
  scene s;
  sph_shape_desc shape;
  sph_sdf* sdf;
  sph_source_def source;
  sph_source_id id = {0};
  sph_transform far = scene_at(5000.0f, 0.0f, 0.0f), farther = scene_at(1e30f, 0.0f, 0.0f),
                edge = scene_at(1310.0f, 0.0f, 0.0f);
  static float positions[3 * 4000];
  uint32_t n, i;
  (void)state;
  scene_open(&s, 4000, 0.02f, 0.0f, 1e-3f);
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.05f;
  sdf = scene_shape(&s, &shape);
  sph_source_def_init(&source);
  source.region = sdf;
  source.transform = far;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "transform", sph_source_create(s.world, &source, &id));
  assert_true(strstr(sph_get_last_error(), "65536 particle spacings") != NULL);
  source.transform = farther;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "transform", sph_source_create(s.world, &source, &id));
  /* Within reach: the lattice (radius 5 cm) ends 1310.05 m out, inside the 1310.72 m bound. */
  source.transform = edge;
  SCENE_OK(sph_source_create(s.world, &source, &id));
  SCENE_OK(sph_source_destroy(s.world, id));
  source.transform = scene_at(0.0f, 0.0f, 0.0f);
  source.mode = SPH_SOURCE_CONTINUOUS;
  SCENE_OK(sph_source_create(s.world, &source, &id));
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "transform", sph_source_set_transform(s.world, id, &far));
  SCENE_OK(sph_world_step(s.world, 0.001f));
  n = scene_positions(&s, positions, 4000);
  assert_true(n > 0);
  for (i = 0; i < n; ++i) assert_true(fabsf(positions[3 * i]) < 0.1f); /* emitted where it was */
  SCENE_OK(sph_source_destroy(s.world, id));
  SCENE_OK(sph_sdf_destroy(sdf));
  scene_close(&s);
}

/* A velocity channel holds speeds a particle may have (below 1.8e19 m/s): sph_sdf_create and
 * sph_sdf_update refuse faster ones (a source with VELOCITY_FROM_FIELD gave its particles
 * 1e20 m/s, and every later step failed as non-finite), the asset unchanged on update. */
static void test_velocity_channel_speeds(void** state) {
  scene s;
  sph_sdf_desc desc;
  sph_grid_desc velocity;
  sph_sdf* sdf = NULL;
  float distance[8] = {-1, -1, -1, -1, -1, -1, -1, -1}, speeds[24], one[3] = {1e20f, 0.0f, 0.0f};
  uint32_t origin[3] = {1, 1, 1}, size[3] = {1, 1, 1}, i;
  sph_source_def source;
  sph_source_id id;
  float v[3 * 64];
  (void)state;
  scene_open(&s, 4000, 0.02f, 0.0f, 1e-3f);
  for (i = 0; i < 24; ++i) speeds[i] = (i % 3 == 0) ? 2.0f : 0.0f;
  speeds[9] = 1e20f; /* voxel 3's x */
  sph_sdf_desc_init(&desc);
  desc.distance.dims[0] = desc.distance.dims[1] = desc.distance.dims[2] = 2;
  desc.distance.index_to_local[0] = desc.distance.index_to_local[5] = desc.distance.index_to_local[10] =
      0.05f;
  desc.distance.index_to_local[3] = desc.distance.index_to_local[7] = desc.distance.index_to_local[11] =
      -0.025f;
  desc.distance.data = distance;
  sph_grid_desc_init(&velocity);
  velocity.dims[0] = velocity.dims[1] = velocity.dims[2] = 2;
  velocity.data = speeds;
  desc.velocity = &velocity;
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "desc->velocity->data[9..11]", sph_sdf_create(s.context, &desc, &sdf));
  assert_true(strstr(sph_get_last_error(), "1.8e19") != NULL);
  speeds[9] = 2.0f;
  SCENE_OK(sph_sdf_create(s.context, &desc, &sdf));
  EXPECT(SPH_ERROR_INVALID_ARGUMENT, "data[0..2]",
         sph_sdf_update(sdf, SPH_SDF_CHANNEL_VELOCITY, origin, size, one, SPH_MEMORY_HOST));
  /* Unchanged: a source taking its velocity from the field emits at 2 m/s, and steps. */
  sph_source_def_init(&source);
  source.region = sdf;
  source.flags = SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD;
  SCENE_OK(sph_source_create(s.world, &source, &id));
  SCENE_OK(sph_world_step(s.world, 0.001f));
  assert_true(scene_velocities(&s, v, 64) > 0);
  assert_true(fabsf(v[0] - 2.0f) < 0.5f);
  SCENE_OK(sph_source_destroy(s.world, id));
  SCENE_OK(sph_sdf_destroy(sdf));
  scene_close(&s);
}

/* A continuous source's rate, however large (any finite rate >= 0 is accepted), emits what its
 * region takes and leaves a world whose own checkpoint loads: before, the carried budget grew
 * without bound (rate 1e20 made the save unloadable after one step, 1e15 with the region held
 * full after about a hundred), and at 3e38 its cast to size_t overflowed and nothing was
 * emitted. The budget owed is at most one region's worth, so a region blocked for a while is
 * refilled once when it clears, not every frame for as long again. */
static void test_source_rate_extremes(void** state) {
  const float rates[3] = {1e15f, 1e20f, 3e38f};
  uint32_t counts[3], k;
  for (k = 0; k < 3; ++k) {
    scene s;
    sph_shape_desc shape;
    sph_sdf* sdf;
    sph_source_def source;
    sph_source_id id;
    uint64_t needed = 0, written = 0;
    void* bytes;
    sph_world* loaded = NULL;
    int step;
    (void)state;
    scene_open(&s, 4000, 0.02f, 0.0f, 1e-3f); /* no gravity: the region stays full */
    sph_shape_desc_init(&shape);
    shape.shape = SPH_SHAPE_SPHERE;
    shape.radius = 0.05f;
    sdf = scene_shape(&s, &shape);
    sph_source_def_init(&source);
    source.region = sdf;
    source.mode = SPH_SOURCE_CONTINUOUS;
    source.rate = rates[k];
    SCENE_OK(sph_source_create(s.world, &source, &id));
    for (step = 0; step < 120; ++step) SCENE_OK(sph_world_step(s.world, 0.01f));
    SCENE_OK(sph_world_get_particle_count(s.world, &counts[k]));
    assert_true(counts[k] > 0);
    SCENE_OK(sph_world_save(s.world, NULL, 0, &needed));
    bytes = malloc((size_t)needed);
    assert_non_null(bytes);
    SCENE_OK(sph_world_save(s.world, bytes, needed, &written));
    SCENE_OK(sph_world_load(s.context, bytes, written, &loaded));
    SCENE_OK(sph_world_step(loaded, 0.01f));
    SCENE_OK(sph_world_destroy(loaded));
    free(bytes);
    SCENE_OK(sph_source_destroy(s.world, id));
    SCENE_OK(sph_sdf_destroy(sdf));
    scene_close(&s);
  }
  /* Every rate far above the region's size per step: the same emission. */
  assert_int_equal(counts[1], counts[0]);
  assert_int_equal(counts[2], counts[0]);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sdf_errors),
      cmocka_unit_test(test_collider_errors),
      cmocka_unit_test(test_source_sink_field_errors),
      cmocka_unit_test(test_failed_step_undoes_emission),
      cmocka_unit_test(test_source_reach),
      cmocka_unit_test(test_velocity_channel_speeds),
      cmocka_unit_test(test_source_rate_extremes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
