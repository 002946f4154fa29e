// SPDX-License-Identifier: MIT
/* Particles in and out through the C API: spawn, the lattice fills, the particle count and
 * attribute copies. Every bad input returns its code, names the argument, writes nothing and
 * leaves the world unchanged; the successful paths do exactly what the header says. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "capi_test.h"

typedef struct {
  sph_spawn_desc desc;
  unsigned char extra[16];
} grown_spawn_desc;
typedef struct {
  sph_fill_box_desc desc;
  unsigned char extra[16];
} grown_fill_box_desc;
typedef struct {
  sph_fill_sphere_desc desc;
  unsigned char extra[16];
} grown_fill_sphere_desc;

static capi_snapshot before; /* static: a snapshot is large and the tests are single-threaded */

static uint32_t particle_count(const sph_world* world) {
  uint32_t n = 0;
  EXPECT_OK(sph_world_get_particle_count(world, &n));
  return n;
}

/* A world pointer that was valid once: created on the fixture's context, then destroyed. */
static sph_world* destroyed_world(const capi_fixture* f) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_world_def_init(&def);
  def.capacity = 8;
  EXPECT_OK(sph_world_create(f->context, &def, &world));
  EXPECT_OK(sph_world_destroy(world));
  return world;
}

/* Every world function that takes a world rejects NULL, foreign and destroyed handles. */
static void test_bad_world_handles(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  int foreign = 0;
  sph_world* const bad[] = {NULL, (sph_world*)(void*)&foreign, (sph_world*)(void*)f->context,
                            destroyed_world(f)};
  sph_spawn_desc spawn;
  sph_fill_box_desc box;
  sph_fill_sphere_desc sphere;
  sph_stats stats;
  sph_world_params params;
  sph_world_def def;
  const float position[3] = {0.0f, 0.0f, 0.0f};
  float buffer[16];
  float mass = 0.0f;
  uint32_t count = 0;
  sph_spawn_desc_init(&spawn);
  spawn.count = 1;
  spawn.positions = position;
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 0.1f;
  sph_fill_sphere_desc_init(&sphere);
  sphere.radius = 0.05f;
  sph_stats_init(&stats);
  sph_world_params_init(&params);
  sph_world_def_init(&def);
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    sph_world* w = bad[i];
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_spawn(w, &spawn, NULL));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_fill_box(w, &box, NULL));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_fill_sphere(w, &sphere, NULL));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_particle_count(w, &count));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world",
                 sph_world_copy_attribute(w, SPH_ATTRIBUTE_POSITION, buffer, sizeof buffer, 0, 0, 1, NULL));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_step(w, 0.01f));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_stats(w, &stats));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_set_params(w, &params));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_params(w, &params));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_def(w, &def));
    EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_particle_mass(w, &mass));
  }
}

/* ---- descriptor init functions ------------------------------------------------------------- */

static void test_desc_init(void** state) {
  sph_spawn_desc spawn;
  sph_fill_box_desc box;
  sph_fill_sphere_desc sphere;
  grown_spawn_desc gs;
  grown_fill_box_desc gb;
  grown_fill_sphere_desc gp;
  (void)state;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc", sph_spawn_desc_init_sized(NULL, sizeof spawn));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc", sph_fill_box_desc_init_sized(NULL, sizeof box));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc", sph_fill_sphere_desc_init_sized(NULL, sizeof sphere));
  memset(&spawn, 0xab, sizeof spawn);
  memset(&box, 0xab, sizeof box);
  memset(&sphere, 0xab, sizeof sphere);
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "desc", sph_spawn_desc_init_sized(&spawn, 4));
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "desc", sph_fill_box_desc_init_sized(&box, sizeof box - 4));
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "desc", sph_fill_sphere_desc_init_sized(&sphere, 0));
  assert_int_equal(spawn.struct_size, 0xababababu);
  assert_int_equal(box.struct_size, 0xababababu);
  assert_int_equal(sphere.struct_size, 0xababababu);
  /* Defaults: everything zero (no particles, zero velocity, packed strides). */
  EXPECT_OK(sph_spawn_desc_init(&spawn));
  assert_int_equal(spawn.struct_size, sizeof spawn);
  assert_int_equal(spawn.count, 0);
  assert_null(spawn.positions);
  assert_null(spawn.velocities);
  assert_int_equal(spawn.position_stride, 0);
  assert_int_equal(spawn.velocity_stride, 0);
  EXPECT_OK(sph_fill_box_desc_init(&box));
  assert_int_equal(box.struct_size, sizeof box);
  assert_int_equal(box.reserved0, 0);
  assert_true(box.velocity.x == 0.0f && box.velocity.y == 0.0f && box.velocity.z == 0.0f);
  EXPECT_OK(sph_fill_sphere_desc_init(&sphere));
  assert_int_equal(sphere.struct_size, sizeof sphere);
  assert_true(sphere.radius == 0.0f);
  memset(&gs, 0xab, sizeof gs);
  memset(&gb, 0xab, sizeof gb);
  memset(&gp, 0xab, sizeof gp);
  EXPECT_OK(sph_spawn_desc_init_sized(&gs.desc, sizeof gs));
  EXPECT_OK(sph_fill_box_desc_init_sized(&gb.desc, sizeof gb));
  EXPECT_OK(sph_fill_sphere_desc_init_sized(&gp.desc, sizeof gp));
  for (size_t i = 0; i < 16; ++i) {
    assert_int_equal(gs.extra[i], 0);
    assert_int_equal(gb.extra[i], 0);
    assert_int_equal(gp.extra[i], 0);
  }
  assert_int_equal(gs.desc.struct_size, sizeof gs);
}

/* ---- spawn ------------------------------------------------------------------------------------ */

static void expect_spawn_fails_at(int line, const capi_fixture* f, const sph_spawn_desc* desc,
                                  sph_result code, const char* name) {
  uint32_t first = 0xdeadbeefu;
  capi_snapshot_take(f->world, &before);
  EXPECT_ERROR_AT(line, code, name, sph_world_spawn(f->world, desc, &first));
  assert_int_equal(first, 0xdeadbeefu);
  EXPECT_UNCHANGED_AT(line, f->world, &before);
}
#define EXPECT_SPAWN_FAILS(...) expect_spawn_fails_at(__LINE__, __VA_ARGS__)

static void test_spawn_errors(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  float positions[3 * 4] = {0.3f, 0.3f, 0.3f, 0.32f, 0.3f, 0.3f, 0.3f, 0.32f, 0.3f, 0.3f, 0.3f, 0.32f};
  float velocities[3 * 4] = {0};
  grown_spawn_desc grown;
  sph_spawn_desc d;
  const uint32_t free_capacity = CAPI_FIXTURE_CAPACITY - particle_count(f->world);

  EXPECT_SPAWN_FAILS(f, NULL, SPH_ERROR_INVALID_ARGUMENT, "desc");
  memset(&grown, 0, sizeof grown);
  sph_spawn_desc_init(&grown.desc);
  grown.desc.count = 4;
  grown.desc.positions = positions;
  grown.desc.struct_size = sizeof grown.desc - 8;
  EXPECT_SPAWN_FAILS(f, &grown.desc, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  grown.desc.struct_size = 0;
  EXPECT_SPAWN_FAILS(f, &grown.desc, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  grown.desc.struct_size = sizeof grown;
  grown.extra[3] = 7;
  EXPECT_SPAWN_FAILS(f, &grown.desc, SPH_ERROR_UNSUPPORTED, "struct_size");

  sph_spawn_desc_init(&d);
  d.count = 4;
  EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "positions"); /* positions NULL */
  d.positions = positions;
  d.position_stride = 11;
  EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "position_stride");
  d.position_stride = 1;
  EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "position_stride");
  d.position_stride = 0;
  d.velocities = velocities;
  d.velocity_stride = 4;
  EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "velocity_stride");
  d.velocity_stride = 0;

  /* More than the free capacity: CAPACITY, nothing added. count = UINT32_MAX with a 4-element
   * array also proves the count is checked before anything is read. */
  d.count = free_capacity + 1;
  d.velocities = NULL;
  {
    float* many = (float*)test_calloc(3 * (size_t)d.count, sizeof(float));
    d.positions = many;
    EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_CAPACITY, "count");
    test_free(many);
  }
  d.positions = positions;
  d.count = UINT32_MAX;
  EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_CAPACITY, "count");

  /* A non-finite coordinate in any particle and component: nothing added (all-or-nothing),
   * and the message names the particle. */
  d.count = 4;
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c)
      for (int v = 0; v < CAPI_NON_FINITE_COUNT; ++v) {
        const float saved = positions[3 * k + c];
        char name[32];
        positions[3 * k + c] = capi_non_finite(v);
        snprintf(name, sizeof name, "positions[%d]", k);
        EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, name);
        positions[3 * k + c] = saved;
      }
  d.velocities = velocities;
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c)
      for (int v = 0; v < CAPI_NON_FINITE_COUNT; ++v) {
        char name[32];
        velocities[3 * k + c] = capi_non_finite(v);
        snprintf(name, sizeof name, "velocities[%d]", k);
        EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, name);
        velocities[3 * k + c] = 0.0f;
      }
  /* Finite but beyond what the neighbour grid can represent. */
  d.velocities = NULL;
  positions[3 * 2 + 1] = 1e30f;
  EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "positions[2]");
  positions[3 * 2 + 1] = -3e9f;
  EXPECT_SPAWN_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "positions[2]");
}

static void test_spawn_success(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  /* Strided input: 4 floats per position (16 bytes), 5 per velocity (20 bytes). */
  const float positions[4 * 3] = {0.5f, 0.1f,  -0.2f, 99.0f, -0.4f, 0.2f,
                                  0.3f, 99.0f, 1.0f,  2.0f,  3.0f,  99.0f};
  const float velocities[5 * 3] = {1.0f,  2.0f,  3.0f, 99.0f, 99.0f, -1.0f, 0.5f, 0.25f,
                                   99.0f, 99.0f, 0.0f, 0.0f,  -7.0f, 99.0f, 99.0f};
  const uint32_t n0 = particle_count(f->world);
  uint32_t first = 0xdeadbeefu, next = 0;
  grown_spawn_desc grown;
  sph_spawn_desc d;
  static float got_pos[3 * CAPI_SNAPSHOT_MAX], got_vel[3 * CAPI_SNAPSHOT_MAX];
  static uint32_t ids[CAPI_SNAPSHOT_MAX];

  /* count 0 adds nothing and still succeeds (positions may be NULL then). */
  sph_spawn_desc_init(&d);
  EXPECT_OK(sph_world_spawn(f->world, &d, &first));
  assert_int_equal(particle_count(f->world), n0);

  sph_spawn_desc_init(&d);
  d.count = 3;
  d.positions = positions;
  d.position_stride = 16;
  d.velocities = velocities;
  d.velocity_stride = 20;
  EXPECT_OK(sph_world_spawn(f->world, &d, &first));
  assert_int_equal(particle_count(f->world), n0 + 3);
  /* A grown desc with a zero tail is accepted; out_first_id may be NULL; ids are consecutive. */
  memset(&grown, 0, sizeof grown);
  sph_spawn_desc_init(&grown.desc);
  grown.desc.struct_size = sizeof grown;
  grown.desc.count = 1;
  grown.desc.positions = positions;
  EXPECT_OK(sph_world_spawn(f->world, &grown.desc, NULL));
  EXPECT_OK(sph_world_spawn(f->world, &grown.desc, &next));
  assert_int_equal(next, first + 4);
  assert_int_equal(particle_count(f->world), n0 + 5);

  /* Each new particle holds exactly what was given (found by id; order is the world's). */
  EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_ID, ids, sizeof ids, 0, 0, n0 + 5, NULL));
  EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_POSITION, got_pos, sizeof got_pos, 0, 0, n0 + 5,
                                     NULL));
  EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_VELOCITY, got_vel, sizeof got_vel, 0, 0, n0 + 5,
                                     NULL));
  {
    int found = 0;
    for (uint32_t i = 0; i < n0 + 5; ++i) {
      if (ids[i] < first || ids[i] >= first + 3) continue;
      const uint32_t k = ids[i] - first;
      ++found;
      for (int c = 0; c < 3; ++c) {
        assert_true(got_pos[3 * i + c] == positions[4 * k + c]);
        assert_true(got_vel[3 * i + c] == velocities[5 * k + c]);
      }
    }
    assert_int_equal(found, 3);
  }
}

/* ---- fills ------------------------------------------------------------------------------------ */

static void expect_box_fails_at(int line, const capi_fixture* f, const sph_fill_box_desc* desc,
                                sph_result code, const char* name) {
  uint32_t count = 0xdeadbeefu;
  capi_snapshot_take(f->world, &before);
  EXPECT_ERROR_AT(line, code, name, sph_world_fill_box(f->world, desc, &count));
  assert_int_equal(count, 0xdeadbeefu);
  EXPECT_UNCHANGED_AT(line, f->world, &before);
}
#define EXPECT_BOX_FAILS(...) expect_box_fails_at(__LINE__, __VA_ARGS__)

static void expect_sphere_fails_at(int line, const capi_fixture* f, const sph_fill_sphere_desc* desc,
                                   sph_result code, const char* name) {
  uint32_t count = 0xdeadbeefu;
  capi_snapshot_take(f->world, &before);
  EXPECT_ERROR_AT(line, code, name, sph_world_fill_sphere(f->world, desc, &count));
  assert_int_equal(count, 0xdeadbeefu);
  EXPECT_UNCHANGED_AT(line, f->world, &before);
}
#define EXPECT_SPHERE_FAILS(...) expect_sphere_fails_at(__LINE__, __VA_ARGS__)

static void small_box(sph_fill_box_desc* d) {
  sph_fill_box_desc_init(d);
  d->min.x = 0.5f;
  d->min.y = 0.5f;
  d->min.z = 0.5f;
  d->max.x = 0.55f;
  d->max.y = 0.55f;
  d->max.z = 0.55f;
}

static void test_fill_box_errors(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  const struct {
    size_t offset;
    const char* name;
  } fields[] = {
      {offsetof(sph_fill_box_desc, min.x), "min"},
      {offsetof(sph_fill_box_desc, min.y), "min"},
      {offsetof(sph_fill_box_desc, min.z), "min"},
      {offsetof(sph_fill_box_desc, max.x), "max"},
      {offsetof(sph_fill_box_desc, max.y), "max"},
      {offsetof(sph_fill_box_desc, max.z), "max"},
      {offsetof(sph_fill_box_desc, velocity.x), "velocity"},
      {offsetof(sph_fill_box_desc, velocity.y), "velocity"},
      {offsetof(sph_fill_box_desc, velocity.z), "velocity"},
  };
  grown_fill_box_desc grown;
  sph_fill_box_desc d;
  uint32_t count = 1;

  EXPECT_BOX_FAILS(f, NULL, SPH_ERROR_INVALID_ARGUMENT, "desc");
  memset(&grown, 0, sizeof grown);
  small_box(&grown.desc);
  grown.desc.struct_size = 8;
  EXPECT_BOX_FAILS(f, &grown.desc, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  grown.desc.struct_size = sizeof grown;
  grown.extra[15] = 1;
  EXPECT_BOX_FAILS(f, &grown.desc, SPH_ERROR_UNSUPPORTED, "struct_size");

  small_box(&d);
  d.reserved0 = 1;
  EXPECT_BOX_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "reserved0");
  for (size_t i = 0; i < sizeof fields / sizeof fields[0]; ++i)
    for (int v = 0; v < CAPI_NON_FINITE_COUNT; ++v) {
      small_box(&d);
      capi_set_float(&d, fields[i].offset, capi_non_finite(v));
      EXPECT_BOX_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, fields[i].name);
    }
  /* Inverted along each axis (negative size); an empty box (zero size) fills nothing. */
  small_box(&d);
  d.max.x = d.min.x;
  EXPECT_OK(sph_world_fill_box(f->world, &d, &count));
  assert_int_equal(count, 0);
  small_box(&d);
  d.max.y = d.min.y - 0.1f;
  EXPECT_BOX_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "max");
  small_box(&d);
  d.max.z = -d.max.z;
  EXPECT_BOX_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "max");
  /* Too many particles: a box just over the free capacity, and an enormous one (refused
   * before the lattice is generated, or this would run out of memory). */
  small_box(&d);
  d.max.x = d.max.y = d.max.z = 0.65f; /* ~ 500 points, capacity 256 */
  EXPECT_BOX_FAILS(f, &d, SPH_ERROR_CAPACITY, "capacity");
  d.min.x = d.min.y = d.min.z = -1e6f;
  d.max.x = d.max.y = d.max.z = 1e6f;
  EXPECT_BOX_FAILS(f, &d, SPH_ERROR_CAPACITY, "capacity");
  /* Finite, but outside the range the neighbour grid can represent. */
  /* (At 2e7 m float steps are 2 m: a 2 m x 3 cm x 3 cm box holds ~70 points, which fit.) */
  small_box(&d);
  d.min.x = 2e7f;
  d.max.x = 2e7f + 2.0f;
  d.max.y = d.min.y + 0.03f;
  d.max.z = d.min.z + 0.03f;
  EXPECT_BOX_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "desc");
}

static void test_fill_sphere_errors(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  const struct {
    size_t offset;
    const char* name;
  } fields[] = {
      {offsetof(sph_fill_sphere_desc, center.x), "center"},
      {offsetof(sph_fill_sphere_desc, center.y), "center"},
      {offsetof(sph_fill_sphere_desc, center.z), "center"},
      {offsetof(sph_fill_sphere_desc, radius), "radius"},
      {offsetof(sph_fill_sphere_desc, velocity.x), "velocity"},
      {offsetof(sph_fill_sphere_desc, velocity.y), "velocity"},
      {offsetof(sph_fill_sphere_desc, velocity.z), "velocity"},
  };
  grown_fill_sphere_desc grown;
  sph_fill_sphere_desc d;
  uint32_t count = 1;

  EXPECT_SPHERE_FAILS(f, NULL, SPH_ERROR_INVALID_ARGUMENT, "desc");
  memset(&grown, 0, sizeof grown);
  sph_fill_sphere_desc_init(&grown.desc);
  grown.desc.radius = 0.03f;
  grown.desc.struct_size = sizeof grown.desc - 4;
  EXPECT_SPHERE_FAILS(f, &grown.desc, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  grown.desc.struct_size = sizeof grown;
  grown.extra[0] = 0xff;
  EXPECT_SPHERE_FAILS(f, &grown.desc, SPH_ERROR_UNSUPPORTED, "struct_size");

  sph_fill_sphere_desc_init(&d);
  d.radius = 0.03f;
  d.reserved0 = 2;
  EXPECT_SPHERE_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "reserved0");
  for (size_t i = 0; i < sizeof fields / sizeof fields[0]; ++i)
    for (int v = 0; v < CAPI_NON_FINITE_COUNT; ++v) {
      sph_fill_sphere_desc_init(&d);
      d.radius = 0.03f;
      capi_set_float(&d, fields[i].offset, capi_non_finite(v));
      EXPECT_SPHERE_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, fields[i].name);
    }
  sph_fill_sphere_desc_init(&d);
  d.radius = 0.0f; /* zero means an empty sphere (a zeroed desc is valid) */
  EXPECT_OK(sph_world_fill_sphere(f->world, &d, &count));
  assert_int_equal(count, 0);
  d.radius = -0.1f;
  EXPECT_SPHERE_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "radius");
  d.radius = 0.2f; /* ~ 1400 points, capacity 256 */
  EXPECT_SPHERE_FAILS(f, &d, SPH_ERROR_CAPACITY, "capacity");
  d.radius = 1e6f; /* refused before generating ~1e26 points */
  EXPECT_SPHERE_FAILS(f, &d, SPH_ERROR_CAPACITY, "capacity");
  d.radius = 0.03f;
  d.center.z = -2e9f;
  EXPECT_SPHERE_FAILS(f, &d, SPH_ERROR_INVALID_ARGUMENT, "desc");
}

static void test_fills_success(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  const uint32_t n0 = particle_count(f->world);
  static float pos[3 * CAPI_SNAPSHOT_MAX], vel[3 * CAPI_SNAPSHOT_MAX];
  static uint32_t ids[CAPI_SNAPSHOT_MAX];
  sph_fill_box_desc box;
  sph_fill_sphere_desc sphere;
  uint32_t in_box = 0, in_sphere = 0, n0_far = 0;
  const float s = 0.02f; /* the fixture's spacing */

  small_box(&box);
  box.velocity.y = -2.0f;
  EXPECT_OK(sph_world_fill_box(f->world, &box, &in_box));
  assert_true(in_box > 0);
  assert_int_equal(particle_count(f->world), n0 + in_box);
  {
    /* Grown descs with a zero tail are accepted (and out_count is optional); removing what
     * they add is impossible, so they go far away where they do not disturb the checks below. */
    grown_fill_box_desc gb;
    grown_fill_sphere_desc gp;
    uint32_t n_before = particle_count(f->world), added = 0;
    memset(&gb, 0, sizeof gb);
    small_box(&gb.desc);
    gb.desc.struct_size = sizeof gb;
    gb.desc.min.y = gb.desc.min.y + 10.0f;
    gb.desc.max.y = gb.desc.max.y + 10.0f;
    EXPECT_OK(sph_world_fill_box(f->world, &gb.desc, NULL));
    assert_int_equal(particle_count(f->world), n_before + in_box);
    memset(&gp, 0, sizeof gp);
    sph_fill_sphere_desc_init(&gp.desc);
    gp.desc.struct_size = sizeof gp;
    gp.desc.center.y = 20.0f;
    gp.desc.radius = 0.01f;
    EXPECT_OK(sph_world_fill_sphere(f->world, &gp.desc, &added));
    assert_int_equal(added, 1);
    n0_far = in_box + 1;
  }
  sph_fill_sphere_desc_init(&sphere);
  sphere.center.x = -1.0f;
  sphere.radius = 0.03f;
  sphere.velocity.z = 3.0f;
  EXPECT_OK(sph_world_fill_sphere(f->world, &sphere, &in_sphere));
  assert_true(in_sphere > 0);
  assert_int_equal(particle_count(f->world), n0 + n0_far + in_box + in_sphere);
  /* out_count is optional. */
  sphere.center.x = -2.0f;
  sphere.radius = 0.01f;
  EXPECT_OK(sph_world_fill_sphere(f->world, &sphere, NULL));
  assert_int_equal(particle_count(f->world), n0 + n0_far + in_box + in_sphere + 1); /* just the centre */

  {
    const uint32_t n = particle_count(f->world);
    int box_seen = 0, sphere_seen = 0, centre_seen = 0;
    EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_ID, ids, sizeof ids, 0, 0, n, NULL));
    EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_POSITION, pos, sizeof pos, 0, 0, n, NULL));
    EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_VELOCITY, vel, sizeof vel, 0, 0, n, NULL));
    for (uint32_t i = 0; i < n; ++i) {
      const float* p = pos + 3 * i;
      const float* v = vel + 3 * i;
      if (p[1] > 5.0f) continue; /* the grown-desc fills */
      if (p[0] > 0.4f) {         /* the box: points at least spacing/2 inside each face */
        ++box_seen;
        for (int c = 0; c < 3; ++c)
          assert_true(p[c] >= 0.5f + 0.5f * s - 1e-6f && p[c] <= 0.55f - 0.5f * s + 1e-6f);
        assert_true(v[0] == 0.0f && v[1] == -2.0f && v[2] == 0.0f);
      } else if (p[0] < -1.5f) {
        ++centre_seen;
        assert_true(p[0] == -2.0f && p[1] == 0.0f && p[2] == 0.0f);
      } else if (p[0] < -0.5f) { /* the sphere: |p - c| <= r, zero-based on the centre */
        const double dx = p[0] + 1.0, r = sqrt(dx * dx + (double)p[1] * p[1] + (double)p[2] * p[2]);
        ++sphere_seen;
        assert_true(r <= 0.03 + 1e-6);
        assert_true(v[0] == 0.0f && v[1] == 0.0f && v[2] == 3.0f);
      }
    }
    assert_int_equal(box_seen, in_box);
    assert_int_equal(sphere_seen, in_sphere);
    assert_int_equal(centre_seen, 1);
    /* A radius-0.03 FCC ball at spacing 0.02: the centre and its 12 nearest neighbours
     * (0.02 away); the next shell (0.028) too, 6 points; 0.0346 is outside. */
    assert_int_equal(in_sphere, 19);
  }
}

/* ---- count and copy-out ---------------------------------------------------------------------- */

static void test_particle_count(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  uint32_t n = 0;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out_count", sph_world_get_particle_count(f->world, NULL));
  EXPECT_OK(sph_world_get_particle_count(f->world, &n));
  assert_int_equal(n, 108); /* the fixture's 6 x 6 x 6 FCC block */
}

#define SENTINEL 0x5au

static int untouched(const unsigned char* buffer, size_t size) {
  for (size_t i = 0; i < size; ++i)
    if (buffer[i] != SENTINEL) return 0;
  return 1;
}

static void expect_copy_fails_at(int line, const capi_fixture* f, sph_attribute a, void* dst,
                                 uint64_t dst_size, uint64_t stride, uint32_t first, uint32_t count,
                                 sph_result code, const char* name) {
  static unsigned char buffer[4096];
  uint32_t written = 0xdeadbeefu;
  memset(buffer, SENTINEL, sizeof buffer);
  if (dst == (void*)1) dst = buffer; /* "the buffer" */
  capi_snapshot_take(f->world, &before);
  EXPECT_ERROR_AT(line, code, name,
                  sph_world_copy_attribute(f->world, a, dst, dst_size, stride, first, count, &written));
  assert_int_equal(written, 0xdeadbeefu);
  assert_true(untouched(buffer, sizeof buffer));
  EXPECT_UNCHANGED_AT(line, f->world, &before);
}
#define EXPECT_COPY_FAILS(...) expect_copy_fails_at(__LINE__, __VA_ARGS__)

#define THE_BUFFER ((void*)1)

static void test_copy_errors(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  const int32_t unknown[] = {SPH_ATTRIBUTE_COUNT, 6, 1000, 0x7fffffff, -1};
  const uint32_t n = 108;
  for (size_t i = 0; i < sizeof unknown / sizeof unknown[0]; ++i)
    EXPECT_COPY_FAILS(f, (sph_attribute)unknown[i], THE_BUFFER, 4096, 0, 0, 1, SPH_ERROR_UNSUPPORTED,
                      "attribute");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_POSITION, NULL, 4096, 0, 0, 1, SPH_ERROR_INVALID_ARGUMENT, "dst");
  /* Strides smaller than the element: 12 bytes for vectors, 4 for scalars. */
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_POSITION, THE_BUFFER, 4096, 11, 0, 4, SPH_ERROR_INVALID_ARGUMENT,
                    "dst_stride");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_VELOCITY, THE_BUFFER, 4096, 4, 0, 4, SPH_ERROR_INVALID_ARGUMENT,
                    "dst_stride");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_DENSITY, THE_BUFFER, 4096, 3, 0, 4, SPH_ERROR_INVALID_ARGUMENT,
                    "dst_stride");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_ID, THE_BUFFER, 4096, 1, 0, 4, SPH_ERROR_INVALID_ARGUMENT, "dst_stride");
  /* first beyond the count (first == count is allowed and copies nothing). */
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_ID, THE_BUFFER, 4096, 0, n + 1, 1, SPH_ERROR_INVALID_ARGUMENT, "first");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_ID, THE_BUFFER, 4096, 0, UINT32_MAX, 1, SPH_ERROR_INVALID_ARGUMENT,
                    "first");
  /* Buffers too small by one byte, for packed and strided layouts, and empty buffers. */
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_POSITION, THE_BUFFER, 10 * 12 - 1, 0, 0, 10, SPH_ERROR_BUFFER_TOO_SMALL,
                    "dst_size");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_PRESSURE, THE_BUFFER, 9 * 32 + 4 - 1, 32, 0, 10,
                    SPH_ERROR_BUFFER_TOO_SMALL, "dst_size");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_DENSITY, THE_BUFFER, 0, 0, 0, 1, SPH_ERROR_BUFFER_TOO_SMALL, "dst_size");
  /* The whole world (count clamped to 108) into a buffer for 100. */
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_ID, THE_BUFFER, 100 * 4, 0, 0, UINT32_MAX, SPH_ERROR_BUFFER_TOO_SMALL,
                    "dst_size");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_ID, THE_BUFFER, 5 * 4, 0, n - 6, 100, SPH_ERROR_BUFFER_TOO_SMALL,
                    "dst_size");
  /* A stride so large that (count - 1) * stride overflows 64 bits is no array: refused even
   * with a dst_size of UINT64_MAX (a saturated size would pass that check). */
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_POSITION, THE_BUFFER, 4096, (uint64_t)1 << 63, 0, 3,
                    SPH_ERROR_INVALID_ARGUMENT, "dst_stride");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_DENSITY, THE_BUFFER, 4096, UINT64_MAX / 2 + 1, 0, 5,
                    SPH_ERROR_INVALID_ARGUMENT, "dst_stride");
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_DENSITY, THE_BUFFER, UINT64_MAX, UINT64_MAX / 2 + 1, 0, 5,
                    SPH_ERROR_INVALID_ARGUMENT, "dst_stride");
  /* A span that fits 64 bits but runs past the end of the address space from dst. */
  EXPECT_COPY_FAILS(f, SPH_ATTRIBUTE_DENSITY, (void*)(UINTPTR_MAX - 15), UINT64_MAX, 8, 0, 3,
                    SPH_ERROR_INVALID_ARGUMENT, "dst_stride");
}

static void test_copy_success(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  static unsigned char buffer[32 * 108 + 64];
  static float packed[3 * 108];
  uint32_t ids[108];
  uint32_t written = 0;
  float mass = 0.0f;

  /* first == count: nothing to copy, success, 0 written, dst untouched. */
  memset(buffer, SENTINEL, sizeof buffer);
  EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_ID, buffer, 0, 0, 108, 5, &written));
  assert_int_equal(written, 0);
  assert_true(untouched(buffer, sizeof buffer));
  /* Clamped count: 10 asked from first 100 gives 8, in a buffer of exactly 8 elements. */
  EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_ID, buffer, 8 * 4, 0, 100, 10, &written));
  assert_int_equal(written, 8);
  assert_true(untouched(buffer + 8 * 4, sizeof buffer - 8 * 4));
  /* Strided: elements at i * 32, the gaps untouched; the last element needs only 12 bytes. */
  memset(buffer, SENTINEL, sizeof buffer);
  EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_POSITION, buffer, 107 * 32 + 12, 32, 0, 108,
                                     &written));
  assert_int_equal(written, 108);
  EXPECT_OK(
      sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_POSITION, packed, sizeof packed, 0, 0, 108, NULL));
  for (int i = 0; i < 108; ++i) {
    assert_memory_equal(buffer + 32 * i, packed + 3 * i, 12);
    assert_true(untouched(buffer + 32 * i + 12, i == 107 ? sizeof buffer - 32 * 107 - 12 : 20));
  }
  /* Ids are a permutation of 0..107 (the fixture's only particles). */
  EXPECT_OK(sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_ID, ids, sizeof ids, 0, 0, 108, NULL));
  {
    int seen[108] = {0};
    for (int i = 0; i < 108; ++i) {
      assert_true(ids[i] < 108);
      assert_int_equal(seen[ids[i]]++, 0);
    }
  }
  /* Densities are positive and finite; pressures finite (the fixture stepped once). */
  EXPECT_OK(sph_world_get_particle_mass(f->world, &mass));
  EXPECT_OK(
      sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_DENSITY, packed, sizeof packed, 0, 0, 108, NULL));
  for (int i = 0; i < 108; ++i) assert_true(isfinite(packed[i]) && packed[i] > 0.0f);
  EXPECT_OK(
      sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_PRESSURE, packed, sizeof packed, 0, 0, 108, NULL));
  for (int i = 0; i < 108; ++i) assert_true(isfinite(packed[i]));
}

int main(void) {
#define FIXTURE(test) cmocka_unit_test_setup_teardown(test, capi_fixture_setup, capi_fixture_teardown)
  const struct CMUnitTest tests[] = {
      FIXTURE(test_bad_world_handles), cmocka_unit_test(test_desc_init), FIXTURE(test_spawn_errors),
      FIXTURE(test_spawn_success),     FIXTURE(test_fill_box_errors),    FIXTURE(test_fill_sphere_errors),
      FIXTURE(test_fills_success),     FIXTURE(test_particle_count),     FIXTURE(test_copy_errors),
      FIXTURE(test_copy_success),
  };
  return cmocka_run_group_tests_name("capi_particle_errors", tests, NULL, NULL);
}
