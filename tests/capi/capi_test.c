// SPDX-License-Identifier: MIT
#include "capi_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void capi_expect_error(sph_result got, sph_result expected, const char* name, const char* call,
                       const char* file, int line) {
  const char* message = sph_get_last_error();
  if (message == NULL) {
    print_error("%s: sph_get_last_error() returned NULL\n", call);
    _fail(file, line);
  }
  if (got != expected) {
    print_error("%s returned %d (%s), expected %d (%s); last error: \"%s\"\n", call, (int)got,
                sph_result_string(got), (int)expected, sph_result_string(expected), message);
    _fail(file, line);
  }
  if (expected >= 0 && message[0] != '\0') {
    print_error("%s succeeded but sph_get_last_error() is \"%s\", expected \"\"\n", call, message);
    _fail(file, line);
  }
  if (name != NULL && strstr(message, name) == NULL) {
    print_error("%s: the message \"%s\" does not name \"%s\"\n", call, message, name);
    _fail(file, line);
  }
}

void capi_set_float(void* object, size_t offset, float value) {
  memcpy((unsigned char*)object + offset, &value, sizeof value);
}

float capi_non_finite(int i) {
  switch (i) {
    case 0:
      return NAN;
    case 1:
      return INFINITY;
    default:
      return -INFINITY;
  }
}

int capi_fixture_setup(void** state) {
  capi_fixture* f = (capi_fixture*)calloc(1, sizeof *f);
  sph_world_def def;
  sph_fill_box_desc box;
  uint32_t added = 0;
  if (f == NULL) return -1;
  *state = f;
  if (sph_test_context_create(&f->context) != SPH_OK) return -1;
  if (sph_world_def_init(&def) != SPH_OK) return -1;
  def.capacity = CAPI_FIXTURE_CAPACITY;
  if (sph_world_create(f->context, &def, &f->world) != SPH_OK) return -1;
  /* 108 particles: a 6 x 6 x 6 FCC block. */
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 0.1f;
  box.velocity.x = 0.05f;
  if (sph_world_fill_box(f->world, &box, &added) != SPH_OK || added == 0) return -1;
  /* Every field differs from its default, so a call that resets params shows. */
  sph_world_params_init(&f->params);
  f->params.max_substeps = 777;
  f->params.gravity.x = 0.5f;
  f->params.gravity.y = -9.0f;
  f->params.gravity.z = 0.25f;
  f->params.stiffness = 120.0f;
  f->params.viscosity = 3.0f;
  f->params.step_factor = 0.3f;
  f->params.dt_min = 2e-6f;
  f->params.dt_max = 5e-4f;
  if (sph_world_set_params(f->world, &f->params) != SPH_OK) return -1;
  /* One frame, so that order, velocities and densities are no longer the initial ones. */
  if (sph_world_step(f->world, 0.005f) != SPH_OK) return -1;
  return 0;
}

int capi_fixture_teardown(void** state) {
  capi_fixture* f = (capi_fixture*)*state;
  int failed = 0;
  if (f == NULL) return 0;
  failed |= sph_world_destroy(f->world) != SPH_OK;
  failed |= sph_context_destroy(f->context) != SPH_OK;
  free(f);
  *state = NULL;
  return failed ? -1 : 0;
}

void capi_snapshot_take(const sph_world* world, capi_snapshot* out) {
  sph_stats stats;
  uint32_t n = 0;
  memset(out, 0, sizeof *out);
  assert_int_equal(sph_world_get_particle_count(world, &out->count), SPH_OK);
  assert_true(out->count <= CAPI_SNAPSHOT_MAX);
  out->def.struct_size = sizeof out->def;
  assert_int_equal(sph_world_get_def(world, &out->def), SPH_OK);
  sph_world_params_init(&out->params);
  assert_int_equal(sph_world_get_params(world, &out->params), SPH_OK);
  sph_stats_init(&stats);
  assert_int_equal(sph_world_get_stats(world, &stats), SPH_OK);
  out->simulated_time = stats.simulated_time;
  assert_int_equal(support_read(world, SPH_ATTRIBUTE_POSITION, out->positions, CAPI_SNAPSHOT_MAX, &n),
                   SPH_OK);
  assert_int_equal(support_read(world, SPH_ATTRIBUTE_VELOCITY, out->velocities, CAPI_SNAPSHOT_MAX, &n),
                   SPH_OK);
  assert_int_equal(support_read(world, SPH_ATTRIBUTE_DENSITY, out->densities, CAPI_SNAPSHOT_MAX, &n), SPH_OK);
  assert_int_equal(support_read(world, SPH_ATTRIBUTE_ID, out->ids, CAPI_SNAPSHOT_MAX, &n), SPH_OK);
  assert_int_equal(n, out->count);
}

void capi_expect_unchanged(const sph_world* world, const capi_snapshot* before, const char* file, int line) {
  /* Static: a snapshot is ~14 KiB and the tests are single-threaded. */
  static capi_snapshot now;
  const char* what = NULL;
  capi_snapshot_take(world, &now);
  if (now.count != before->count)
    what = "particle count";
  else if (memcmp(&now.def, &before->def, sizeof now.def) != 0)
    what = "def";
  else if (memcmp(&now.params, &before->params, sizeof now.params) != 0)
    what = "params";
  else if (now.simulated_time != before->simulated_time)
    what = "simulated time";
  else if (memcmp(now.positions, before->positions, sizeof(float) * 3 * now.count) != 0)
    what = "positions";
  else if (memcmp(now.velocities, before->velocities, sizeof(float) * 3 * now.count) != 0)
    what = "velocities";
  else if (memcmp(now.densities, before->densities, sizeof(float) * now.count) != 0)
    what = "densities";
  else if (memcmp(now.ids, before->ids, sizeof(uint32_t) * now.count) != 0)
    what = "ids";
  if (what != NULL) {
    print_error("the world changed after a failed call: %s differ (count %u -> %u)\n", what, before->count,
                now.count);
    _fail(file, line);
  }
}

unsigned char* capi_save(const sph_world* world, uint64_t* size) {
  unsigned char* bytes;
  EXPECT_OK(sph_world_save(world, NULL, 0, size));
  bytes = (unsigned char*)malloc((size_t)*size);
  assert_non_null(bytes);
  EXPECT_OK(sph_world_save(world, bytes, *size, size));
  return bytes;
}

sph_world* capi_world_copy(sph_context* context, const sph_world* world) {
  uint64_t size = 0;
  unsigned char* bytes = capi_save(world, &size);
  sph_world* copy = NULL;
  EXPECT_OK(sph_world_load(context, bytes, size, &copy));
  free(bytes);
  return copy;
}

void capi_expect_same_particles(const sph_world* a, const sph_world* b) {
  uint32_t na = 0, nb = 0;
  int attribute;
  EXPECT_OK(sph_world_get_particle_count(a, &na));
  EXPECT_OK(sph_world_get_particle_count(b, &nb));
  assert_int_equal(na, nb);
  for (attribute = 0; attribute <= SPH_ATTRIBUTE_ID; ++attribute) {
    float* x = (float*)calloc(3u * na + 1u, sizeof(float));
    float* y = (float*)calloc(3u * na + 1u, sizeof(float));
    assert_true(x && y);
    EXPECT_OK(sph_world_copy_attribute(a, (sph_attribute)attribute, x, 12ull * na + 4, 0, 0, na, NULL));
    EXPECT_OK(sph_world_copy_attribute(b, (sph_attribute)attribute, y, 12ull * na + 4, 0, 0, na, NULL));
    assert_memory_equal(x, y, 12u * na);
    free(x);
    free(y);
  }
}

int capi_run_named_cases(const char* group, const struct CMUnitTest* tests, size_t count, int argc,
                         char** argv) {
  struct CMUnitTest chosen[64];
  size_t n = 0, i;
  if (argc < 2) return _cmocka_run_group_tests(group, tests, count, NULL, NULL);
  if ((size_t)(argc - 1) > count || (size_t)(argc - 1) > sizeof chosen / sizeof chosen[0]) {
    fprintf(stderr, "%s: at most %zu case names\n", group, count);
    return 2;
  }
  for (int arg = 1; arg < argc; ++arg) {
    for (i = 0; i < count; ++i)
      if (strcmp(argv[arg], tests[i].name) == 0) break;
    if (i == count) {
      fprintf(stderr, "%s: no case named '%s'\n", group, argv[arg]);
      return 2;
    }
    chosen[n++] = tests[i];
  }
  return _cmocka_run_group_tests(group, chosen, n, NULL, NULL);
}

sph_collider_loads capi_loads_of(const sph_world* world, sph_collider_id id) {
  sph_collider_loads l;
  EXPECT_OK(sph_collider_loads_init(&l));
  EXPECT_OK(sph_collider_get_loads(world, id, &l));
  return l;
}

void capi_collider_case(sph_context* context, uint32_t features, sph_shape shape, float voxel,
                        sph_world** world, sph_sdf** sdf) {
  sph_world_def wdef;
  sph_shape_desc desc;
  sph_world_def_init(&wdef);
  wdef.capacity = 64;
  wdef.particle_spacing = 0.02f;
  wdef.features = features;
  EXPECT_OK(sph_world_create(context, &wdef, world));
  sph_shape_desc_init(&desc);
  desc.shape = shape;
  desc.half_extents = (sph_vec3){0.1f, 0.1f, 0.1f};
  desc.voxel_size = voxel;
  EXPECT_OK(sph_sdf_create_shape(context, &desc, sdf));
}

void capi_coarse_collider_case(sph_context* context, sph_world** world, sph_sdf** sdf) {
  capi_collider_case(context, SPH_FEATURE_BOUNDARY_DENSITY, SPH_SHAPE_BOX, 0.01f, world, sdf);
}

sph_result capi_add_collider(sph_world* world, sph_sdf* sdf) {
  sph_collider_def cdef;
  sph_collider_id id;
  sph_collider_def_init(&cdef);
  cdef.sdf = sdf;
  return sph_collider_create(world, &cdef, &id);
}

void capi_fluid_momentum(const sph_world* world, float mass, double p[3]) {
  float* v = NULL;
  uint32_t n = 0;
  EXPECT_OK(support_copy(world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &n));
  p[0] = p[1] = p[2] = 0.0;
  for (uint32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) p[k] += (double)mass * v[3 * i + k];
  free(v);
}

void capi_set_dfsph_flags(sph_world* world, uint32_t flags) {
  sph_dfsph_params dp;
  EXPECT_OK(sph_dfsph_params_init(&dp));
  EXPECT_OK(sph_world_get_dfsph_params(world, &dp));
  dp.flags = flags;
  EXPECT_OK(sph_world_set_dfsph_params(world, &dp));
}
