// SPDX-License-Identifier: MIT
/* "Zero means default" (STYLE.md) for every def and desc of sph_c.h: a struct that is all zeros
 * except struct_size is accepted and gives the documented defaults (read back through the
 * getters, or compared with the struct its init function fills), or is refused with the
 * documented "required field" error. Also the collider material struct, null ids and the
 * all-zero quaternion. */
#include <math.h>
#include <string.h>

#include "capi_test.h"

#define ZEROED(var)                  \
  do {                               \
    memset(&(var), 0, sizeof(var));  \
    (var).struct_size = sizeof(var); \
  } while (0)

static sph_context* make_context(void) {
  sph_context* context = NULL;
  EXPECT_OK(sph_test_context_create(&context));
  return context;
}

/* A small world from the test backend's context with the def's defaults. */
static sph_world* make_world(sph_context* context) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_world_def_init(&def);
  def.capacity = 4096;
  EXPECT_OK(sph_world_create(context, &def, &world));
  return world;
}

static sph_sdf* make_sphere(sph_context* context, float radius) {
  sph_shape_desc shape;
  sph_sdf* sdf = NULL;
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = radius;
  EXPECT_OK(sph_sdf_create_shape(context, &shape, &sdf));
  return sdf;
}

static uint32_t count_of(const sph_world* world) {
  uint32_t n = 0;
  EXPECT_OK(sph_world_get_particle_count(world, &n));
  return n;
}

/* ---- context and world -------------------------------------------------------------------- */

static void test_context_def(void** state) {
  sph_context_def def;
  sph_context *zeroed = NULL, *initialised = NULL;
  sph_backend a, b;
  (void)state;
  ZEROED(def);
  EXPECT_OK(sph_context_create(&def, &zeroed));
  sph_context_def_init(&def);
  EXPECT_OK(sph_context_create(&def, &initialised));
  /* Both are AUTO on device 0: the same backend. */
  EXPECT_OK(sph_context_get_backend(zeroed, &a));
  EXPECT_OK(sph_context_get_backend(initialised, &b));
  assert_int_equal(a, b);
  assert_true(a == SPH_BACKEND_CPU || a == SPH_BACKEND_CUDA);
  EXPECT_OK(sph_context_destroy(zeroed));
  EXPECT_OK(sph_context_destroy(initialised));
}

static void test_world_def(void** state) {
  sph_context* context = make_context();
  sph_world_def def, out;
  sph_world* world = NULL;
  float mass = 0.0f, default_mass = 0.0f;
  (void)state;
  ZEROED(def);
  EXPECT_OK(sph_world_create(context, &def, &world));
  ZEROED(out);
  EXPECT_OK(sph_world_get_def(world, &out));
  /* The documented defaults, resolved. */
  assert_int_equal(out.capacity, 65536);
  assert_int_equal(out.features, SPH_FEATURE_NONE);
  assert_int_equal(out.integrator, SPH_INTEGRATOR_SYMPLECTIC_EULER);
  assert_int_equal(out.viscosity_method, SPH_VISCOSITY_MUELLER);
  assert_int_equal(out.equation_of_state, SPH_EOS_IDEAL_GAS);
  assert_true(out.particle_spacing == 0.02f);
  assert_true(out.kernel_radius == 1.8f * 0.02f);
  assert_true(out.rest_density == 1000.0f);
  EXPECT_OK(sph_world_get_particle_mass(world, &mass));
  EXPECT_OK(sph_world_destroy(world));
  /* The same world as sph_world_def_init's. */
  sph_world_def_init(&def);
  EXPECT_OK(sph_world_create(context, &def, &world));
  EXPECT_OK(sph_world_get_particle_mass(world, &default_mass));
  assert_true(mass == default_mass);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- particles in ------------------------------------------------------------------------- */

static void test_spawn_and_fill_descs(void** state) {
  sph_context* context = make_context();
  sph_world* world = make_world(context);
  sph_spawn_desc spawn;
  sph_fill_box_desc box;
  sph_fill_sphere_desc sphere;
  uint32_t first = 7, n = 7;
  (void)state;
  ZEROED(spawn); /* count 0: adds nothing */
  EXPECT_OK(sph_world_spawn(world, &spawn, &first));
  assert_int_equal(first, 0);
  spawn.count = 1; /* positions become required */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc->positions", sph_world_spawn(world, &spawn, &first));
  ZEROED(box); /* an empty box */
  EXPECT_OK(sph_world_fill_box(world, &box, &n));
  assert_int_equal(n, 0);
  ZEROED(sphere); /* radius 0 */
  n = 7;
  EXPECT_OK(sph_world_fill_sphere(world, &sphere, &n));
  assert_int_equal(n, 0);
  assert_int_equal(count_of(world), 0);
  /* The zeroed velocity is zero: a filled box starts at rest (max speed 0 before a step). */
  box.max.x = box.max.y = box.max.z = 0.1f;
  EXPECT_OK(sph_world_fill_box(world, &box, &n));
  assert_true(n > 0);
  {
    float v[3 * 64];
    uint32_t written = 0, i;
    EXPECT_OK(sph_world_copy_attribute(world, SPH_ATTRIBUTE_VELOCITY, v, sizeof v, 0, 0, 64, &written));
    for (i = 0; i < 3 * written; ++i) assert_true(v[i] == 0.0f);
  }
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- SDF assets ----------------------------------------------------------------------------- */

static void test_grid_and_sdf_descs(void** state) {
  sph_context* context = make_context();
  sph_sdf_desc desc, reference;
  sph_grid_desc velocity;
  sph_sdf *zeroed = NULL, *initialised = NULL, *moving = NULL;
  const float distance[8] = {-1, -0.5f, -0.5f, 0, -0.5f, 0, 0, 0.5f};
  const float speeds[24] = {0};
  const sph_vec3 point = {0.25f, 0.5f, 0.75f};
  float a = 0.0f, b = 1.0f;
  uint32_t dims[3];
  (void)state;
  ZEROED(desc); /* the distance grid is required: dims first, then data */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc->distance.dims", sph_sdf_create(context, &desc, &zeroed));
  desc.distance.dims[0] = desc.distance.dims[1] = desc.distance.dims[2] = 2;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc->distance.data", sph_sdf_create(context, &desc, &zeroed));
  assert_null(zeroed);
  /* With them, the zero rest is valid: embedded struct_size 0, components 0 (= 1), an all-zero
   * index_to_local (= identity) and host memory. */
  desc.distance.data = distance;
  EXPECT_OK(sph_sdf_create(context, &desc, &zeroed));
  sph_sdf_desc_init(&reference);
  reference.distance.dims[0] = reference.distance.dims[1] = reference.distance.dims[2] = 2;
  reference.distance.components = 1;
  reference.distance.data = distance;
  EXPECT_OK(sph_sdf_create(context, &reference, &initialised));
  EXPECT_OK(sph_sdf_get_dims(zeroed, dims));
  assert_int_equal(dims[0], 2);
  EXPECT_OK(sph_sdf_sample(zeroed, point, &a));
  EXPECT_OK(sph_sdf_sample(initialised, point, &b));
  assert_true(a == b); /* the same grid in the same frame: the same trilinear sample */
  /* And the identity frame itself: the corners hold 0.5 (x + y + z) - 1 at x, y, z in {0, 1},
   * a linear field that trilinear sampling reproduces exactly (-0.25 here). */
  assert_true(fabsf(a - (0.5f * (0.25f + 0.5f + 0.75f) - 1.0f)) < 1e-6f);
  /* A zeroed optional grid (dims and data set) takes its channel's count: 3 for velocity. */
  ZEROED(velocity);
  velocity.dims[0] = velocity.dims[1] = velocity.dims[2] = 2;
  velocity.data = speeds;
  desc.velocity = &velocity;
  EXPECT_OK(sph_sdf_create(context, &desc, &moving));
  EXPECT_OK(sph_sdf_destroy(zeroed));
  EXPECT_OK(sph_sdf_destroy(initialised));
  EXPECT_OK(sph_sdf_destroy(moving));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_shape_desc(void** state) {
  sph_context* context = make_context();
  sph_shape_desc desc;
  sph_sdf *zeroed = NULL, *plane = NULL;
  uint32_t dims_zeroed[3], dims_plane[3];
  const sph_vec3 points[3] = {{0.0f, 0.0f, 0.0f}, {0.1f, 0.3f, -0.2f}, {0.4f, -0.6f, 0.45f}};
  (void)state;
  ZEROED(desc); /* shape 0 is the plane; every size takes its default */
  EXPECT_OK(sph_sdf_create_shape(context, &desc, &zeroed));
  sph_shape_desc_init(&desc);
  desc.shape = SPH_SHAPE_PLANE;
  EXPECT_OK(sph_sdf_create_shape(context, &desc, &plane));
  EXPECT_OK(sph_sdf_get_dims(zeroed, dims_zeroed));
  EXPECT_OK(sph_sdf_get_dims(plane, dims_plane));
  assert_memory_equal(dims_zeroed, dims_plane, sizeof dims_zeroed);
  /* Sized by the defaults (0.5 m half extents at 0.01 m voxels, 4 voxels of padding: 111 per
   * axis), not by the zeros (a grid of a few voxels). */
  assert_true(dims_zeroed[0] >= 100 && dims_zeroed[0] <= 112);
  for (int i = 0; i < 3; ++i) {
    float a = 0.0f, b = 1.0f;
    EXPECT_OK(sph_sdf_sample(zeroed, points[i], &a));
    EXPECT_OK(sph_sdf_sample(plane, points[i], &b));
    assert_true(a == b);
  }
  EXPECT_OK(sph_sdf_destroy(zeroed));
  EXPECT_OK(sph_sdf_destroy(plane));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- scene objects ------------------------------------------------------------------------ */

static void expect_identity(const sph_transform* t) {
  assert_true(t->position.x == 0.0f && t->position.y == 0.0f && t->position.z == 0.0f);
  assert_true(t->rotation.x == 0.0f && t->rotation.y == 0.0f && t->rotation.z == 0.0f &&
              t->rotation.w == 1.0f);
}

static void test_collider_def_and_material(void** state) {
  sph_context* context = make_context();
  sph_world* world = make_world(context);
  sph_sdf* sdf = make_sphere(context, 0.1f);
  sph_collider_def def;
  sph_collider_id id = {0}, null_id = {0};
  sph_collider_material material, out, initialised;
  sph_transform t;
  (void)state;
  ZEROED(def); /* the SDF is required */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->sdf", sph_collider_create(world, &def, &id));
  assert_true(SPH_ID_IS_NULL(id)); /* not written on error */
  def.sdf = sdf;
  EXPECT_OK(sph_collider_create(world, &def, &id));
  assert_false(SPH_ID_IS_NULL(id));
  EXPECT_OK(sph_collider_get_transform(world, id, &t));
  expect_identity(&t); /* the all-zero quaternion is the identity */
  ZEROED(out);
  EXPECT_OK(sph_collider_get_material(world, id, &out));
  assert_true(out.restitution == 0.0f && out.friction == 0.0f && out.stickiness == 0.0f);
  /* The material's init is the zeroed struct. */
  sph_collider_material_init(&initialised);
  ZEROED(material);
  assert_memory_equal(&initialised, &material, sizeof material);

  /* Set whole, read back whole. */
  material.restitution = 0.25f;
  material.friction = 0.5f;
  material.stickiness = 2.0f;
  EXPECT_OK(sph_collider_set_material(world, id, &material));
  EXPECT_OK(sph_collider_get_material(world, id, &out));
  assert_true(out.struct_size == sizeof out && out.restitution == 0.25f && out.friction == 0.5f &&
              out.stickiness == 2.0f);
  /* A bad value names its field and changes nothing. */
  material.restitution = 1.5f;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "material->restitution",
               sph_collider_set_material(world, id, &material));
  material.restitution = 0.0f;
  material.friction = NAN;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "material->friction",
               sph_collider_set_material(world, id, &material));
  material.friction = 0.0f;
  material.stickiness = -1.0f;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "material->stickiness",
               sph_collider_set_material(world, id, &material));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "material", sph_collider_set_material(world, id, NULL));
  material.struct_size = 8;
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "struct_size", sph_collider_set_material(world, id, &material));
  EXPECT_OK(sph_collider_get_material(world, id, &out));
  assert_true(out.restitution == 0.25f && out.friction == 0.5f && out.stickiness == 2.0f);
  /* An older, smaller out struct gets only its bytes. */
  memset(&out, 0x7f, sizeof out);
  out.struct_size = 8;
  EXPECT_OK(sph_collider_get_material(world, id, &out));
  assert_true(out.restitution == 0.25f);
  {
    float untouched;
    memset(&untouched, 0x7f, sizeof untouched);
    assert_memory_equal(&out.friction, &untouched, sizeof untouched);
  }

  /* Null ids: refused by every call but destroy. */
  assert_true(SPH_ID_IS_NULL(null_id));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_get_material(world, null_id, &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_get_transform(world, null_id, &t));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_set_material(world, null_id, &initialised));
  EXPECT_OK(sph_collider_destroy(world, null_id));

  /* A zeroed transform teleports to the identity too. */
  t.position.x = 1.0f;
  t.rotation.w = 1.0f;
  EXPECT_OK(sph_collider_teleport(world, id, &t));
  memset(&t, 0, sizeof t);
  EXPECT_OK(sph_collider_teleport(world, id, &t));
  EXPECT_OK(sph_collider_get_transform(world, id, &t));
  expect_identity(&t);
  EXPECT_OK(sph_collider_destroy(world, id));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_get_material(world, id, &out));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* Particles after one step of a world with a source made from `def` (region set by the caller). */
static uint32_t emitted_after_one_step(sph_context* context, const sph_source_def* def) {
  sph_world* world = make_world(context);
  sph_source_id id = {0};
  uint32_t n;
  EXPECT_OK(sph_source_create(world, def, &id));
  assert_false(SPH_ID_IS_NULL(id));
  EXPECT_OK(sph_world_step(world, 1e-4f));
  n = count_of(world);
  EXPECT_OK(sph_world_destroy(world));
  return n;
}

static void test_source_sink_and_field_defs(void** state) {
  sph_context* context = make_context();
  sph_world* world = make_world(context);
  sph_sdf* sdf = make_sphere(context, 0.06f);
  sph_source_def source;
  sph_sink_def sink;
  sph_force_field_def field;
  sph_source_id source_id = {0};
  sph_sink_id sink_id = {0};
  sph_force_field_id field_id = {0};
  uint32_t zeroed_count, initialised_count;
  (void)state;
  ZEROED(source); /* the region is required */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->region", sph_source_create(world, &source, &source_id));
  assert_true(SPH_ID_IS_NULL(source_id));
  source.region = sdf;
  zeroed_count = emitted_after_one_step(context, &source);
  sph_source_def_init(&source);
  source.region = sdf;
  initialised_count = emitted_after_one_step(context, &source);
  /* A sphere of radius 3 spacings holds about (4/3) pi 27 sqrt 2 = 160 lattice points. */
  assert_true(zeroed_count > 100 && zeroed_count < 220);
  assert_int_equal(zeroed_count, initialised_count);

  ZEROED(sink); /* a REGION sink: the region is required */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->region", sph_sink_create(world, &sink, &sink_id));
  assert_true(SPH_ID_IS_NULL(sink_id));
  sink.region = sdf;
  EXPECT_OK(sph_sink_create(world, &sink, &sink_id));
  assert_false(SPH_ID_IS_NULL(sink_id));

  ZEROED(field); /* a uniform field of zero acceleration: valid */
  EXPECT_OK(sph_force_field_create(world, &field, &field_id));
  assert_false(SPH_ID_IS_NULL(field_id));
  field.kind = SPH_FORCE_FIELD_VORTEX; /* its axis is required */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->vector", sph_force_field_create(world, &field, &field_id));
  field.kind = SPH_FORCE_FIELD_GRID; /* its grid is required */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def->grid", sph_force_field_create(world, &field, &field_id));

  EXPECT_OK(sph_sink_destroy(world, sink_id));
  EXPECT_OK(sph_force_field_destroy(world, field_id));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* A zeroed force field changes nothing: a block falls the same with and without it. Compared
 * to 1e-6 m after 10 steps, not bit for bit: the CUDA backend runs a scene variant of its
 * kernels when a field exists, which may contract the arithmetic differently. */
static void test_zeroed_force_field_changes_nothing(void** state) {
  sph_context* context = make_context();
  sph_world *plain = make_world(context), *with_field = make_world(context);
  sph_fill_box_desc box;
  sph_force_field_def field;
  sph_force_field_id id;
  float a[3 * 512], b[3 * 512];
  uint32_t n = 0, i;
  (void)state;
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 0.12f;
  EXPECT_OK(sph_world_fill_box(plain, &box, &n));
  EXPECT_OK(sph_world_fill_box(with_field, &box, &n));
  assert_true(n > 50 && n <= 512);
  ZEROED(field);
  EXPECT_OK(sph_force_field_create(with_field, &field, &id));
  for (i = 0; i < 10; ++i) {
    EXPECT_OK(sph_world_step(plain, 1.0f / 240.0f));
    EXPECT_OK(sph_world_step(with_field, 1.0f / 240.0f));
  }
  EXPECT_OK(sph_world_copy_attribute(plain, SPH_ATTRIBUTE_POSITION, a, sizeof a, 0, 0, n, NULL));
  EXPECT_OK(sph_world_copy_attribute(with_field, SPH_ATTRIBUTE_POSITION, b, sizeof b, 0, 0, n, NULL));
  for (i = 0; i < 3 * n; ++i) assert_true(fabsf(a[i] - b[i]) < 1e-6f);
  EXPECT_OK(sph_world_destroy(plain));
  EXPECT_OK(sph_world_destroy(with_field));
  EXPECT_OK(sph_context_destroy(context));
}

/* A saved world keeps its colliders' materials and poses and its ids. */
static void test_material_survives_a_checkpoint(void** state) {
  sph_context* context = make_context();
  sph_world *world = make_world(context), *loaded = NULL;
  sph_sdf* sdf = make_sphere(context, 0.1f);
  sph_collider_def def;
  sph_collider_id id;
  sph_collider_material m, out;
  sph_transform t;
  uint64_t size = 0;
  void* bytes;
  (void)state;
  sph_collider_def_init(&def);
  def.sdf = sdf;
  def.transform.position.y = 0.5f;
  def.transform.rotation.z = 0.3f; /* normalised by the library */
  EXPECT_OK(sph_collider_create(world, &def, &id));
  sph_collider_material_init(&m);
  m.restitution = 0.75f;
  m.friction = 0.125f;
  m.stickiness = 4.0f;
  EXPECT_OK(sph_collider_set_material(world, id, &m));
  EXPECT_OK(sph_world_save(world, NULL, 0, &size));
  bytes = test_malloc((size_t)size);
  EXPECT_OK(sph_world_save(world, bytes, size, &size));
  EXPECT_OK(sph_world_load(context, bytes, size, &loaded));
  test_free(bytes);
  sph_collider_material_init(&out);
  EXPECT_OK(sph_collider_get_material(loaded, id, &out));
  assert_memory_equal(&out, &m, sizeof m);
  {
    sph_transform saved;
    EXPECT_OK(sph_collider_get_transform(world, id, &saved));
    EXPECT_OK(sph_collider_get_transform(loaded, id, &t));
    assert_memory_equal(&t, &saved, sizeof t); /* the stored unit quaternion, bit for bit */
  }
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_context_def),
      cmocka_unit_test(test_world_def),
      cmocka_unit_test(test_spawn_and_fill_descs),
      cmocka_unit_test(test_grid_and_sdf_descs),
      cmocka_unit_test(test_shape_desc),
      cmocka_unit_test(test_collider_def_and_material),
      cmocka_unit_test(test_source_sink_and_field_defs),
      cmocka_unit_test(test_zeroed_force_field_changes_nothing),
      cmocka_unit_test(test_material_survives_a_checkpoint),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
