// SPDX-License-Identifier: MIT
/* Writing particles (issue 21, item 3): attribute ranges written and read back bit for bit, a
 * written velocity against the analytic free fall, removal by id, the user attribute through
 * sorting, checkpoints, sinks and sources, and every bad input refused with the world unchanged
 * bit for bit (its checkpoint bytes, which hold every particle array, the clock and the scene).
 * Runs on the test backend (SPH_TEST_BACKEND=cuda for the GPU). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

/* The value the tests give each particle: a hash of its id, so a particle that met another's
 * value (a gather through the wrong index) shows. */
static uint32_t tag_of(uint32_t id) { return (id * 2654435761u) ^ 0x5bd1e995u; }

static sph_world* make_world(sph_context** context, sph_feature_flags features, uint32_t capacity) {
  sph_world_def def;
  sph_world* world = NULL;
  EXPECT_OK(sph_test_context_create(context));
  sph_world_def_init(&def);
  def.capacity = capacity;
  def.features = features;
  EXPECT_OK(sph_world_create(*context, &def, &world));
  return world;
}

static void close_world(sph_context* context, sph_world* world) {
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* An FCC block of side `size` at the world's spacing, 0.2 m above the origin, at rest. */
static uint32_t fill_block(sph_world* world, float size) {
  sph_fill_box_desc box;
  uint32_t added = 0;
  sph_fill_box_desc_init(&box);
  box.min.y = 0.2f;
  box.max.x = box.max.z = size;
  box.max.y = 0.2f + size;
  EXPECT_OK(sph_world_fill_box(world, &box, &added));
  assert_true(added > 0);
  return added;
}

/* The world's checkpoint is what it was: nothing in it changed. */
static void expect_same_state(const sph_world* world, const unsigned char* before, uint64_t before_size) {
  uint64_t size = 0;
  unsigned char* now = capi_save(world, &size);
  assert_int_equal(size, before_size);
  assert_memory_equal(now, before, (size_t)size);
  free(now);
}

static void* read_all(const sph_world* world, sph_attribute a, uint32_t* n) {
  void* out = NULL;
  EXPECT_OK(support_copy(world, a, &out, n));
  return out;
}

static void set_tags(sph_world* world) {
  uint32_t n = 0, i;
  uint32_t* ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  uint32_t* tags = (uint32_t*)malloc(4u * (n + 1));
  for (i = 0; i < n; ++i) tags[i] = tag_of(ids[i]);
  EXPECT_OK(sph_world_set_attribute(world, SPH_ATTRIBUTE_USER, tags, 4ull * n, 0, 0, n));
  free(ids);
  free(tags);
}

/* Every particle still carries the tag of its own id; returns how many particles there are. */
static uint32_t expect_tags(const sph_world* world) {
  uint32_t n = 0, m = 0, i;
  uint32_t* ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  uint32_t* tags = (uint32_t*)read_all(world, SPH_ATTRIBUTE_USER, &m);
  assert_int_equal(n, m);
  for (i = 0; i < n; ++i) assert_int_equal(tags[i], tag_of(ids[i]));
  free(ids);
  free(tags);
  return n;
}

/* Writes with a stride, reads back bit for bit; the particles outside the range and every other
 * attribute stay as they were. */
static void test_write_read_back(void** state) {
  typedef struct {
    float position[3];
    uint32_t pad0;
    float velocity[3];
    uint32_t user;
  } record; /* an engine's interleaved particle: every attribute at a 32-byte stride */
  sph_context* context = NULL;
  sph_world* world = make_world(&context, SPH_FEATURE_USER_ATTRIBUTE, 1024);
  uint32_t n = fill_block(world, 0.1f), m = 0, i;
  const uint32_t first = 10, count = 20;
  record src[20];
  float *pos_before, *vel_before, *pos, *vel, *dens_before, *dens;
  uint32_t *ids_before, *ids, *user;
  (void)state;
  EXPECT_OK(sph_world_step(world, 0.01f)); /* sorted, densities computed */
  pos_before = (float*)read_all(world, SPH_ATTRIBUTE_POSITION, &n);
  vel_before = (float*)read_all(world, SPH_ATTRIBUTE_VELOCITY, &n);
  dens_before = (float*)read_all(world, SPH_ATTRIBUTE_DENSITY, &n);
  ids_before = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  for (i = 0; i < count; ++i) {
    int k;
    for (k = 0; k < 3; ++k) {
      /* Values no float arithmetic in the library would reproduce by chance. */
      src[i].position[k] = pos_before[3 * (first + i) + k] + 0.001f * (float)(i + 1) / 3.0f;
      src[i].velocity[k] = -1.7f + 0.37f * (float)(3 * i + k) / 7.0f;
    }
    src[i].user = 0xdeadbeefu - i;
  }
  EXPECT_OK(sph_world_set_attribute(world, SPH_ATTRIBUTE_POSITION, &src[0].position, sizeof src,
                                    sizeof(record), first, count));
  EXPECT_OK(sph_world_set_attribute(world, SPH_ATTRIBUTE_VELOCITY, &src[0].velocity,
                                    sizeof src - offsetof(record, velocity), sizeof(record), first, count));
  EXPECT_OK(sph_world_set_attribute(world, SPH_ATTRIBUTE_USER, &src[0].user,
                                    sizeof src - offsetof(record, user), sizeof(record), first, count));
  pos = (float*)read_all(world, SPH_ATTRIBUTE_POSITION, &m);
  assert_int_equal(m, n);
  vel = (float*)read_all(world, SPH_ATTRIBUTE_VELOCITY, &m);
  dens = (float*)read_all(world, SPH_ATTRIBUTE_DENSITY, &m);
  ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &m);
  user = (uint32_t*)read_all(world, SPH_ATTRIBUTE_USER, &m);
  for (i = 0; i < n; ++i) {
    const int written = i >= first && i < first + count;
    assert_int_equal(ids[i], ids_before[i]);
    assert_memory_equal(&dens[i], &dens_before[i], 4);
    if (written) {
      assert_memory_equal(&pos[3 * i], src[i - first].position, 12);
      assert_memory_equal(&vel[3 * i], src[i - first].velocity, 12);
      assert_int_equal(user[i], src[i - first].user);
    } else {
      assert_memory_equal(&pos[3 * i], &pos_before[3 * i], 12);
      assert_memory_equal(&vel[3 * i], &vel_before[3 * i], 12);
      assert_int_equal(user[i], 0); /* fills start at 0 */
    }
  }
  /* count 0 with NULL src writes nothing and succeeds, also at the end of the range. */
  EXPECT_OK(sph_world_set_attribute(world, SPH_ATTRIBUTE_POSITION, NULL, 0, 0, n, 0));
  free(pos_before), free(vel_before), free(dens_before), free(ids_before);
  free(pos), free(vel), free(dens), free(ids), free(user);
  close_world(context, world);
}

/* Writing what is there changes nothing: the world steps on bit for bit as an untouched twin
 * (the write goes through the checkpoint path, which must not perturb the state). */
static void test_identity_write_keeps_the_trajectory(void** state) {
  sph_context *ca = NULL, *cb = NULL;
  sph_world* a = make_world(&ca, SPH_FEATURE_NONE, 1024);
  sph_world* b = make_world(&cb, SPH_FEATURE_NONE, 1024);
  uint32_t n = 0, m = 0;
  int k;
  float *pos, *vel;
  (void)state;
  fill_block(a, 0.1f);
  fill_block(b, 0.1f);
  EXPECT_OK(sph_world_step(a, 0.01f));
  EXPECT_OK(sph_world_step(b, 0.01f));
  pos = (float*)read_all(b, SPH_ATTRIBUTE_POSITION, &n);
  vel = (float*)read_all(b, SPH_ATTRIBUTE_VELOCITY, &n);
  EXPECT_OK(sph_world_set_attribute(b, SPH_ATTRIBUTE_POSITION, pos, 12ull * n, 0, 0, n));
  EXPECT_OK(sph_world_set_attribute(b, SPH_ATTRIBUTE_VELOCITY, vel, 12ull * n, 0, 0, n));
  EXPECT_OK(sph_world_step(a, 0.02f));
  EXPECT_OK(sph_world_step(b, 0.02f));
  for (k = 0; k <= SPH_ATTRIBUTE_ID; ++k) { /* (the checkpoints differ in their step's wall times) */
    void* x = read_all(a, (sph_attribute)k, &n);
    void* y = read_all(b, (sph_attribute)k, &m);
    assert_int_equal(n, m);
    assert_memory_equal(x, y, support_attribute_size((sph_attribute)k) * n);
    free(x), free(y);
  }
  free(pos), free(vel);
  close_world(ca, a);
  close_world(cb, b);
}

/* A particle alone (no neighbour within h) given a velocity falls as x0 + v0 t + g t^2 / 2. */
static void test_written_velocity_free_fall(void** state) {
  const float g = -9.81f, dt = 1e-3f, frame = 0.1f;
  const float positions[9] = {0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, -1.0f, 0.5f, 0.0f};
  const float v0[3] = {0.8f, 2.5f, -0.6f};
  sph_context* context = NULL;
  sph_world* world = make_world(&context, SPH_FEATURE_NONE, 16);
  sph_world_params params;
  uint32_t n = 0, i, target = 0, found = 0;
  uint32_t* ids;
  float *pos0, *pos, *vel;
  (void)state;
  EXPECT_OK(support_spawn(world, positions, NULL, 3));
  EXPECT_OK(support_params_gravity_and_steps(&params, 0.0f, g, 0.0f, dt, dt));
  params.max_substeps = 1000;
  EXPECT_OK(sph_world_set_params(world, &params));
  EXPECT_OK(sph_world_step(world, 0.01f)); /* the particles have fallen a little and been sorted */
  ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  for (i = 0; i < n; ++i)
    if (ids[i] == 1) target = i; /* the one spawned at x = 1 */
  pos0 = (float*)read_all(world, SPH_ATTRIBUTE_POSITION, &n);
  EXPECT_OK(sph_world_set_attribute(world, SPH_ATTRIBUTE_VELOCITY, v0, 12, 0, target, 1));
  EXPECT_OK(sph_world_step(world, frame));
  free(ids);
  ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  pos = (float*)read_all(world, SPH_ATTRIBUTE_POSITION, &n);
  vel = (float*)read_all(world, SPH_ATTRIBUTE_VELOCITY, &n);
  for (i = 0; i < n; ++i) {
    int k;
    if (ids[i] != 1) continue;
    ++found;
    for (k = 0; k < 3; ++k) {
      const double gk = k == 1 ? g : 0.0;
      const double x = pos0[3 * target + k] + v0[k] * (double)frame + 0.5 * gk * frame * frame;
      /* Symplectic Euler with a fixed dt lands g dt t / 2 below the parabola (0.49 mm here);
       * float rounding over 100 substeps adds far less than 0.02 mm at |x| < 2 m. A write that
       * did not reach the particle would miss by |v0| t >= 6 cm. */
      assert_true(fabs(pos[3 * i + k] - x) <= 0.5 * fabs(gk) * dt * frame + 2e-5);
      /* v = v0 + g t: 100 float additions of g dt, each rounded by at most half an ulp of
       * |v| < 4 m/s (1.2e-7), 1.2e-5 m/s in all. */
      assert_true(fabs(vel[3 * i + k] - (v0[k] + gk * frame)) <= 2e-5);
    }
  }
  assert_int_equal(found, 1);
  free(ids), free(pos0), free(pos), free(vel);
  close_world(context, world);
}

/* Removes some particles by id: the count drops by as many, exactly the others stay in their
 * order with their state, and the ids are reported with the removed ones until the next step. */
static void remove_and_check(sph_feature_flags features) {
  sph_context* context = NULL;
  sph_world* world = make_world(&context, features, 1024);
  uint32_t n = 0, m = 0, i, k = 0, got = 0;
  uint32_t *ids_before, *ids, *tags_before = NULL, removed[5], reported[8];
  float *pos_before, *pos;
  fill_block(world, 0.1f);
  if (features & SPH_FEATURE_USER_ATTRIBUTE) set_tags(world);
  EXPECT_OK(sph_world_step(world, 0.01f));
  ids_before = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  pos_before = (float*)read_all(world, SPH_ATTRIBUTE_POSITION, &n);
  if (features & SPH_FEATURE_USER_ATTRIBUTE) tags_before = (uint32_t*)read_all(world, SPH_ATTRIBUTE_USER, &n);
  /* First, last and three inside, given out of order. */
  removed[0] = ids_before[n / 2];
  removed[1] = ids_before[0];
  removed[2] = ids_before[n - 1];
  removed[3] = ids_before[7];
  removed[4] = ids_before[n / 3];
  EXPECT_OK(sph_world_remove_particles(world, removed, 5));
  ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &m);
  pos = (float*)read_all(world, SPH_ATTRIBUTE_POSITION, &m);
  assert_int_equal(m, n - 5);
  for (i = 0; i < n; ++i) {
    int gone = 0, r;
    for (r = 0; r < 5; ++r) gone |= ids_before[i] == removed[r];
    if (gone) continue;
    assert_int_equal(ids[k], ids_before[i]);
    assert_memory_equal(&pos[3 * k], &pos_before[3 * i], 12);
    ++k;
  }
  assert_int_equal(k, m);
  if (tags_before) assert_int_equal(expect_tags(world), m);
  EXPECT_OK(sph_world_get_removed_ids(world, reported, 8, &got));
  assert_int_equal(got, 5);
  assert_memory_equal(reported, removed, sizeof removed);
  /* The world steps on (springs: their partners were renumbered) and a checkpoint of it loads,
   * which checks every spring's partner index. */
  EXPECT_OK(sph_world_step(world, 0.01f));
  EXPECT_OK(sph_world_get_removed_ids(world, reported, 8, &got));
  assert_int_equal(got, 0);
  {
    uint64_t size = 0;
    unsigned char* bytes = capi_save(world, &size);
    sph_world* loaded = NULL;
    EXPECT_OK(sph_world_load(context, bytes, size, &loaded));
    EXPECT_OK(sph_world_destroy(loaded));
    free(bytes);
  }
  free(ids_before), free(ids), free(pos_before), free(pos), free(tags_before);
  close_world(context, world);
}

static void test_remove_by_id(void** state) {
  (void)state;
  remove_and_check(SPH_FEATURE_NONE);
  remove_and_check(SPH_FEATURE_USER_ATTRIBUTE);
  remove_and_check(SPH_FEATURE_SPRINGS);
}

/* Removing every particle leaves an empty world that still steps. */
static void test_remove_all(void** state) {
  sph_context* context = NULL;
  sph_world* world = make_world(&context, SPH_FEATURE_USER_ATTRIBUTE, 1024);
  uint32_t n = 0, left = 1;
  uint32_t* ids;
  (void)state;
  fill_block(world, 0.06f);
  ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  EXPECT_OK(sph_world_remove_particles(world, ids, n));
  EXPECT_OK(sph_world_get_particle_count(world, &left));
  assert_int_equal(left, 0);
  EXPECT_OK(sph_world_step(world, 0.01f));
  free(ids);
  close_world(context, world);
}

/* The user attribute follows its particle through many sorts (a block collapsing on a floor
 * shuffles the storage order), both integrators, a checkpoint and a sink. */
static void tags_through_steps(sph_integrator integrator, sph_feature_flags features) {
  sph_context* context = NULL;
  sph_world_def def;
  sph_world* world = NULL;
  sph_sink_def sink;
  sph_sink_id sink_id;
  uint32_t n = 0, i, moved = 0, frame, kept;
  uint32_t* ids_before;
  uint32_t* ids;
  uint64_t size = 0, size2 = 0;
  unsigned char *bytes, *bytes2;
  sph_world* loaded = NULL;
  sph_sdf* tank = NULL;
  sph_collider_id tank_id;
  EXPECT_OK(sph_test_context_create(&context));
  sph_world_def_init(&def);
  def.capacity = 2048;
  def.features = SPH_FEATURE_USER_ATTRIBUTE | features;
  def.integrator = integrator;
  EXPECT_OK(sph_world_create(context, &def, &world));
  EXPECT_OK(support_set_gravity_and_steps(world, 0.0f, -9.81f, 0.0f, 0.0f, 0.0f));
  {
    const double lo[3] = {-0.05, 0.0, -0.05}, hi[3] = {0.25, 0.5, 0.25};
    EXPECT_OK(support_tank_between(context, world, lo, hi, 0.01, 0.0f, &tank, &tank_id));
  }
  fill_block(world, 0.12f);
  set_tags(world);
  ids_before = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  for (frame = 0; frame < 20; ++frame) EXPECT_OK(sph_world_step(world, 0.01f));
  ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  for (i = 0; i < n; ++i) moved += ids[i] != ids_before[i];
  assert_true(moved > n / 4); /* the order did change: the test could fail */
  assert_int_equal(expect_tags(world), n);
  /* A checkpoint round trip: the loaded world carries the same values and saves the same bytes. */
  bytes = capi_save(world, &size);
  EXPECT_OK(sph_world_load(context, bytes, size, &loaded));
  assert_int_equal(expect_tags(loaded), n);
  bytes2 = capi_save(loaded, &size2);
  assert_int_equal(size, size2);
  assert_memory_equal(bytes, bytes2, (size_t)size);
  EXPECT_OK(sph_world_destroy(loaded));
  /* A sink takes the upper half; the survivors keep their own values. */
  sph_sink_def_init(&sink);
  sink.mode = SPH_SINK_OUTSIDE_BOUNDS;
  sink.bounds_min.x = sink.bounds_min.y = sink.bounds_min.z = -1.0f;
  sink.bounds_max.x = sink.bounds_max.z = 1.0f;
  sink.bounds_max.y = 0.05f;
  EXPECT_OK(sph_sink_create(world, &sink, &sink_id));
  EXPECT_OK(sph_world_step(world, 0.01f));
  kept = expect_tags(world);
  assert_true(kept > 0 && kept < n);
  for (frame = 0; frame < 5; ++frame) EXPECT_OK(sph_world_step(world, 0.01f));
  expect_tags(world);
  free(bytes), free(bytes2), free(ids), free(ids_before);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(tank));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_user_attribute_survives(void** state) {
  (void)state;
  tags_through_steps(SPH_INTEGRATOR_SYMPLECTIC_EULER, SPH_FEATURE_NONE);
  tags_through_steps(SPH_INTEGRATOR_RK4, SPH_FEATURE_NORMALIZED_DENSITY);
}

/* A source gives its particles its value; the others keep theirs. */
static void test_source_user_attribute(void** state) {
  sph_context* context = NULL;
  sph_world* world = make_world(&context, SPH_FEATURE_USER_ATTRIBUTE, 2048);
  sph_world* plain;
  sph_context* plain_context = NULL;
  sph_shape_desc shape;
  sph_sdf* region = NULL;
  sph_source_def def;
  sph_source_id id;
  uint32_t n = 0, m = 0, i, emitted = 0, first_new;
  uint32_t *ids, *user;
  (void)state;
  fill_block(world, 0.06f);
  set_tags(world);
  EXPECT_OK(sph_world_get_particle_count(world, &first_new)); /* ids 0 .. first_new - 1 so far */
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.05f;
  shape.voxel_size = 0.01f;
  EXPECT_OK(sph_sdf_create_shape(context, &shape, &region));
  sph_source_def_init(&def);
  def.region = region;
  def.transform = sph_transform_identity();
  def.transform.position.x = 0.5f;
  def.user_attribute = 7u;
  EXPECT_OK(sph_source_create(world, &def, &id));
  EXPECT_OK(sph_world_step(world, 0.005f));
  ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  user = (uint32_t*)read_all(world, SPH_ATTRIBUTE_USER, &m);
  for (i = 0; i < n; ++i) {
    if (ids[i] >= first_new) {
      assert_int_equal(user[i], 7u);
      ++emitted;
    } else {
      assert_int_equal(user[i], tag_of(ids[i]));
    }
  }
  assert_true(emitted > 0);
  /* A world without the feature refuses a non-zero value, and a zero one is fine. */
  plain = make_world(&plain_context, SPH_FEATURE_NONE, 64);
  {
    sph_sdf* r2 = NULL;
    EXPECT_OK(sph_sdf_create_shape(plain_context, &shape, &r2));
    def.region = r2;
    EXPECT_ERROR(SPH_ERROR_FEATURE_DISABLED, "def->user_attribute", sph_source_create(plain, &def, &id));
    def.user_attribute = 0;
    EXPECT_OK(sph_source_create(plain, &def, &id));
    EXPECT_OK(sph_world_destroy(plain));
    EXPECT_OK(sph_sdf_destroy(r2));
    EXPECT_OK(sph_context_destroy(plain_context));
  }
  free(ids), free(user);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(region));
  EXPECT_OK(sph_context_destroy(context));
}

/* Every bad input is refused with its code, names the argument, and leaves the world bit for bit
 * as it was. */
static void test_bad_input_changes_nothing(void** state) {
  sph_context* context = NULL;
  sph_world* world = make_world(&context, SPH_FEATURE_USER_ATTRIBUTE, 1024);
  sph_context* plain_context = NULL;
  sph_world* plain = make_world(&plain_context, SPH_FEATURE_NONE, 64);
  uint32_t n = 0, i, k, out[4];
  float* pos;
  uint32_t* ids;
  uint64_t size = 0;
  unsigned char* before;
  const float nan = capi_non_finite(0), inf = capi_non_finite(1);
  float bad[3 * 8];
  uint32_t user[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  int foreign = 0;
  (void)state;
  fill_block(world, 0.1f);
  EXPECT_OK(sph_world_step(world, 0.01f));
  fill_block(plain, 0.06f);
  pos = (float*)read_all(world, SPH_ATTRIBUTE_POSITION, &n);
  ids = (uint32_t*)read_all(world, SPH_ATTRIBUTE_ID, &n);
  before = capi_save(world, &size);
  memcpy(bad, pos, sizeof bad);

  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world",
               sph_world_set_attribute(NULL, SPH_ATTRIBUTE_POSITION, pos, 12, 0, 0, 1));
  EXPECT_ERROR(
      SPH_ERROR_INVALID_HANDLE, "world",
      sph_world_set_attribute((sph_world*)(void*)&foreign, SPH_ATTRIBUTE_POSITION, pos, 12, 0, 0, 1));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_remove_particles(NULL, ids, 1));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "src",
               sph_world_set_attribute(world, SPH_ATTRIBUTE_POSITION, NULL, 12, 0, 0, 1));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "first/count",
               sph_world_set_attribute(world, SPH_ATTRIBUTE_POSITION, pos, 12ull * n, 0, 1, n));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "first/count",
               sph_world_set_attribute(world, SPH_ATTRIBUTE_VELOCITY, pos, 12, 0, n + 1, 0));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "first/count",
               sph_world_set_attribute(world, SPH_ATTRIBUTE_USER, user, 32, 0, UINT32_MAX, 2));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "src_stride",
               sph_world_set_attribute(world, SPH_ATTRIBUTE_POSITION, pos, 12ull * n, 8, 0, 2));
  EXPECT_ERROR(SPH_ERROR_BUFFER_TOO_SMALL, "src_size",
               sph_world_set_attribute(world, SPH_ATTRIBUTE_POSITION, pos, 12ull * 8 - 1, 0, 0, 8));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "attribute",
               sph_world_set_attribute(world, SPH_ATTRIBUTE_DENSITY, pos, 4, 0, 0, 1));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "attribute",
               sph_world_set_attribute(world, SPH_ATTRIBUTE_PRESSURE, pos, 4, 0, 0, 1));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "attribute",
               sph_world_set_attribute(world, SPH_ATTRIBUTE_ID, ids, 4, 0, 0, 1));
  EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "attribute",
               sph_world_set_attribute(world, (sph_attribute)99, pos, 12, 0, 0, 1));
  EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "attribute",
               sph_world_set_attribute(world, (sph_attribute)-1, pos, 12, 0, 0, 1));
  /* A bad value in the last element: the seven good ones before it are not written either. */
  for (i = 0; i < 3; ++i) {
    const float values[3] = {nan, inf, 1e9f /* beyond 65536 spacings */};
    memcpy(bad, pos, sizeof bad);
    bad[3 * 7 + (i % 3)] = values[i];
    for (k = 0; k < 21; ++k) bad[k] += 0.001f; /* the good ones differ from what is there */
    EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "src[7]",
                 sph_world_set_attribute(world, SPH_ATTRIBUTE_POSITION, bad, sizeof bad, 0, 0, 8));
  }
  {
    const float values[3] = {nan, -inf, 2e19f /* its square overflows float32 */};
    for (i = 0; i < 3; ++i) {
      float v[3 * 8] = {0};
      v[3 * 7 + 1] = values[i];
      EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "src[7]",
                   sph_world_set_attribute(world, SPH_ATTRIBUTE_VELOCITY, v, sizeof v, 0, 0, 8));
    }
  }
  /* Removal: NULL, an id never issued, an id given twice (named at its second place). */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "ids", sph_world_remove_particles(world, NULL, 1));
  out[0] = ids[3];
  out[1] = 4000000u;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "ids[1]", sph_world_remove_particles(world, out, 2));
  out[1] = ids[5];
  out[2] = ids[3];
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "ids[2]", sph_world_remove_particles(world, out, 3));
  expect_same_state(world, before, size);

  /* An id that was removed is unknown afterwards. */
  EXPECT_OK(sph_world_remove_particles(world, &ids[3], 1));
  free(before);
  before = capi_save(world, &size);
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "ids[0]", sph_world_remove_particles(world, &ids[3], 1));
  expect_same_state(world, before, size);

  /* The user attribute needs its feature, for reading and writing. */
  EXPECT_ERROR(SPH_ERROR_FEATURE_DISABLED, "SPH_FEATURE_USER_ATTRIBUTE",
               sph_world_set_attribute(plain, SPH_ATTRIBUTE_USER, user, sizeof user, 0, 0, 1));
  EXPECT_ERROR(SPH_ERROR_FEATURE_DISABLED, "SPH_FEATURE_USER_ATTRIBUTE",
               sph_world_copy_attribute(plain, SPH_ATTRIBUTE_USER, out, sizeof out, 0, 0, 1, NULL));
  free(pos), free(ids), free(before);
  close_world(plain_context, plain);
  close_world(context, world);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_write_read_back),
      cmocka_unit_test(test_identity_write_keeps_the_trajectory),
      cmocka_unit_test(test_written_velocity_free_fall),
      cmocka_unit_test(test_remove_by_id),
      cmocka_unit_test(test_remove_all),
      cmocka_unit_test(test_user_attribute_survives),
      cmocka_unit_test(test_source_user_attribute),
      cmocka_unit_test(test_bad_input_changes_nothing),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
