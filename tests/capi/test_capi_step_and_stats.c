// SPDX-License-Identifier: MIT
/* Stepping and statistics through the C API: bad frame lengths, SPH_INCOMPLETE when the
 * substep budget runs out, SPH_ERROR_NON_FINITE with the world rolled back, and the values
 * sph_world_get_stats reports after a step. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

typedef struct {
  sph_stats stats;
  unsigned char extra[16];
} grown_stats;

static capi_snapshot before;

static sph_stats get_stats(const sph_world* world) {
  sph_stats s;
  sph_stats_init(&s);
  EXPECT_OK(sph_world_get_stats(world, &s));
  return s;
}

static void test_step_bad_frame_dt(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  const float bad[] = {0.0f, -0.0f, -0.01f, -FLT_MAX, NAN, INFINITY, -INFINITY};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    capi_snapshot_take(f->world, &before);
    EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step(f->world, bad[i]));
    EXPECT_UNCHANGED(f->world, &before);
  }
}

static void test_stats_errors(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  sph_stats s;
  grown_stats grown;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out", sph_world_get_stats(f->world, NULL));
  memset(&s, 0xab, sizeof s);
  s.struct_size = 4;
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "struct_size", sph_world_get_stats(f->world, &s));
  assert_int_equal(s.struct_size, 4);
  assert_int_equal(s.particle_count, 0xababababu);
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "stats", sph_stats_init_sized(NULL, sizeof s));
  /* Below the first released size (0.1.0: 104 bytes, before DFSPH's solve statistics). */
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "stats", sph_stats_init_sized(&s, 104 - 8));
  /* A 0.1.0 caller's size: accepted, its prefix written, nothing past it. */
  memset(&s, 0xab, sizeof s);
  EXPECT_OK(sph_stats_init_sized(&s, 104));
  assert_int_equal(s.struct_size, 104);
  assert_int_equal(s.pressure_iterations, 0xababababu);
  EXPECT_OK(sph_world_get_stats(f->world, &s));
  assert_int_equal(s.pressure_iterations, 0xababababu);
  /* An older caller's shorter struct: only its prefix is written. */
  memset(&s, 0xab, sizeof s);
  s.struct_size = (uint32_t)offsetof(sph_stats, simulated_time);
  EXPECT_OK(sph_world_get_stats(f->world, &s));
  assert_int_equal(s.particle_count, 108);
  {
    unsigned char tail[sizeof s - offsetof(sph_stats, simulated_time)];
    memset(tail, 0xab, sizeof tail);
    assert_memory_equal((unsigned char*)&s + offsetof(sph_stats, simulated_time), tail, sizeof tail);
  }
  /* A newer caller's longer struct: the unknown tail is left alone. */
  memset(&grown, 0xcd, sizeof grown);
  grown.stats.struct_size = sizeof grown;
  EXPECT_OK(sph_world_get_stats(f->world, &grown.stats));
  assert_int_equal(grown.stats.particle_count, 108);
  for (size_t i = 0; i < sizeof grown.extra; ++i) assert_int_equal(grown.extra[i], 0xcd);
}

/* max_substeps runs out before the frame ends: SPH_INCOMPLETE (not an error), and the stats
 * say how far the step got. */
static void test_step_incomplete(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  sph_world_params p = f->params;
  const double t0 = get_stats(f->world).simulated_time;
  sph_stats s;
  p.max_substeps = 3;
  p.dt_min = 1e-3f;
  p.dt_max = 1e-3f;
  EXPECT_OK(sph_world_set_params(f->world, &p));
  EXPECT_ERROR(SPH_INCOMPLETE, NULL, sph_world_step(f->world, 0.1f));
  s = get_stats(f->world);
  assert_int_equal(s.substeps, 3);
  /* 3 substeps of dt_max; float dt, hence the 1e-9 s slack. */
  assert_true(fabs(s.frame_time - 3e-3) < 1e-9 + 3e-3 * 1e-6);
  assert_true(fabs(s.simulated_time - t0 - 3e-3) < 1e-9);
  /* With enough substeps the same frame completes. */
  p.max_substeps = 100;
  EXPECT_OK(sph_world_set_params(f->world, &p));
  EXPECT_OK(sph_world_step(f->world, 0.1f));
  s = get_stats(f->world);
  assert_int_equal(s.substeps, 100);
  assert_true(fabs(s.frame_time - 0.1) < 1e-7);
}

/* A step that produces Inf/NaN returns SPH_ERROR_NON_FINITE and restores the world. */
static void test_step_non_finite_rolls_back(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  /* Nine particles within 1 mm of each other: their summed density is far above rest
   * density, and with k = 3e38 the pressure overflows to Inf in the first substep. */
  float positions[9 * 3];
  sph_spawn_desc d;
  sph_world_params p = f->params;
  for (int i = 0; i < 9; ++i) {
    positions[3 * i + 0] = 1.0f + 1e-4f * (float)(i % 3);
    positions[3 * i + 1] = 1.0f + 1e-4f * (float)(i / 3);
    positions[3 * i + 2] = 1.0f + 1e-4f * (float)i;
  }
  sph_spawn_desc_init(&d);
  d.count = 9;
  d.positions = positions;
  EXPECT_OK(sph_world_spawn(f->world, &d, NULL));
  p.stiffness = 3e38f;
  EXPECT_OK(sph_world_set_params(f->world, &p));
  capi_snapshot_take(f->world, &before);
  EXPECT_ERROR(SPH_ERROR_NON_FINITE, "non-finite", sph_world_step(f->world, 0.01f));
  EXPECT_UNCHANGED(f->world, &before);
  /* The world is still usable. */
  EXPECT_OK(sph_world_set_params(f->world, &f->params));
  EXPECT_OK(sph_world_step(f->world, 0.001f));
  assert_int_equal(get_stats(f->world).particle_count, 117);
}

static void test_stats_before_first_step(void** state) {
  sph_context* context = NULL;
  sph_world_def def;
  sph_world* world = NULL;
  sph_stats s;
  (void)state;
  EXPECT_OK(sph_test_context_create(&context));
  sph_world_def_init(&def);
  def.capacity = 100;
  EXPECT_OK(sph_world_create(context, &def, &world));
  s = get_stats(world);
  assert_int_equal(s.struct_size, sizeof s);
  assert_int_equal(s.particle_count, 0);
  assert_int_equal(s.substeps, 0);
  assert_true(s.simulated_time == 0.0);
  assert_true(s.frame_time == 0.0f);
  assert_true(s.dt_min == 0.0f && s.dt_max == 0.0f && s.max_speed == 0.0f);
  /* Stepping an empty world is fine. */
  EXPECT_OK(sph_world_step(world, 0.01f));
  s = get_stats(world);
  assert_int_equal(s.particle_count, 0);
  assert_true(fabs(s.simulated_time - 0.01) < 1e-7);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* After a step every statistic agrees with the particle data and the parameters. */
static void test_stats_after_step(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  static float density[CAPI_SNAPSHOT_MAX], velocity[3 * CAPI_SNAPSHOT_MAX];
  const double t0 = get_stats(f->world).simulated_time;
  const float frame = 1.0f / 60.0f;
  sph_stats s;
  uint32_t n = 0;
  double dmin = INFINITY, dmax = -INFINITY, dsum = 0.0, vmax = 0.0, stage_sum = 0.0;
  EXPECT_OK(sph_world_step(f->world, frame));
  s = get_stats(f->world);
  EXPECT_OK(sph_world_get_particle_count(f->world, &n));
  assert_int_equal(s.particle_count, n);
  assert_int_equal(s.pressure_solves_guarded, 0); /* a weakly compressible world: no DFSPH solve */
  /* Time: the substeps add up to the frame exactly (float frame_dt, double bookkeeping). */
  assert_true(fabs(s.frame_time - frame) <= 1e-6f * frame);
  assert_true(fabs(s.simulated_time - t0 - (double)frame) < 1e-9);
  assert_true(s.substeps >= 1 && s.substeps <= f->params.max_substeps);
  assert_true(s.dt_min > 0.0f && s.dt_min <= s.dt_max && s.dt_max <= f->params.dt_max);
  assert_true((double)s.dt_max * s.substeps >= frame * (1.0 - 1e-6));
  /* dt_max 5e-4 s over 1/60 s: at least 34 substeps. */
  assert_true(s.substeps >= 34);
  /* Densities of the last evaluation and speeds at the end: min/max exact, mean to float
   * summation accuracy. */
  EXPECT_OK(
      sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_DENSITY, density, sizeof density, 0, 0, n, NULL));
  EXPECT_OK(
      sph_world_copy_attribute(f->world, SPH_ATTRIBUTE_VELOCITY, velocity, sizeof velocity, 0, 0, n, NULL));
  for (uint32_t i = 0; i < n; ++i) {
    const double v =
        sqrt((double)velocity[3 * i] * velocity[3 * i] + (double)velocity[3 * i + 1] * velocity[3 * i + 1] +
             (double)velocity[3 * i + 2] * velocity[3 * i + 2]);
    dmin = fmin(dmin, density[i]);
    dmax = fmax(dmax, density[i]);
    dsum += density[i];
    vmax = fmax(vmax, v);
  }
  assert_true(s.density_min > 0.0f && s.density_min <= s.density_mean && s.density_mean <= s.density_max);
  assert_true(s.density_min == (float)dmin);
  assert_true(s.density_max == (float)dmax);
  assert_true(fabs(s.density_mean - dsum / n) <= 1e-5 * dsum / n);
  assert_true(fabs(s.max_speed - vmax) <= 1e-5 * vmax + 1e-12);
  assert_true(s.max_speed > 0.0f); /* gravity acted */
  /* Neighbours: a 6 x 6 x 6 FCC block at h = 1.8 spacing has interior particles with 42. */
  assert_true(s.neighbors_mean > 0.0f && s.neighbors_mean <= (float)s.neighbors_max);
  assert_true(s.neighbors_max >= 20 && s.neighbors_max < n);
  /* Timings and memory. */
  for (int i = 0; i < SPH_STAGE_COUNT; ++i) {
    assert_true(isfinite(s.stage_ms[i]) && s.stage_ms[i] >= 0.0f);
    stage_sum += s.stage_ms[i];
  }
  assert_true(isfinite(s.step_ms) && s.step_ms > 0.0f);
  assert_true(stage_sum > 0.0);
  assert_true(s.memory_bytes >= (uint64_t)n * 32u); /* at least position + velocity as float4 */
}

/* Water in a box collider whose walls count in the density, on the test backend. */
static void open_walled_water(support_world* w, sph_sdf** sdf) {
  sph_world_def def;
  sph_shape_desc box;
  sph_collider_def cdef;
  sph_collider_id id;
  sph_fill_box_desc fill;
  uint32_t filled = 0;
  sph_world_def_init(&def);
  def.capacity = 4096;
  def.particle_spacing = 0.02f;
  def.features = SPH_FEATURE_BOUNDARY_DENSITY;
  EXPECT_OK(support_world_open(w, sph_test_backend(), &def, NULL));
  sph_shape_desc_init(&box);
  box.shape = SPH_SHAPE_BOX;
  box.half_extents = (sph_vec3){0.1f, 0.1f, 0.1f};
  box.voxel_size = 0.01f;
  EXPECT_OK(sph_sdf_create_shape(w->context, &box, sdf));
  sph_collider_def_init(&cdef);
  cdef.sdf = *sdf;
  cdef.flags = SPH_COLLIDER_FLAG_INVERTED;
  EXPECT_OK(sph_collider_create(w->world, &cdef, &id));
  sph_fill_box_desc_init(&fill);
  fill.min = (sph_vec3){-0.09f, -0.09f, -0.09f};
  fill.max = (sph_vec3){0.09f, 0.0f, 0.09f};
  EXPECT_OK(sph_world_fill_box(w->world, &fill, &filled));
  assert_true(filled > 100);
}

/* sph_world_prepare (0.2.0) builds what a first step would build before its first substep (here
 * the box's boundary-density map: the world then holds it, 16 bytes a voxel, as memory_bytes
 * shows), changes nothing a checkpoint holds, and the step after it gives the same particles, bit
 * for bit, as a step without it (the checkpoints then differ in the steps' wall-clock timings).
 * Its errors: a NULL or destroyed world, a world in an asynchronous step. */
static void test_prepare_builds_what_a_step_would(void** state) {
  support_world a, b;
  sph_sdf *sdf_a = NULL, *sdf_b = NULL;
  unsigned char *before_bytes, *after_bytes;
  uint64_t before_size, after_size;
  uint64_t memory_before;
  sph_world* gone;
  (void)state;
  memset(&a, 0, sizeof a);
  memset(&b, 0, sizeof b);
  open_walled_water(&a, &sdf_a);
  open_walled_water(&b, &sdf_b);
  memory_before = get_stats(a.world).memory_bytes;
  before_bytes = capi_save(a.world, &before_size);
  EXPECT_OK(sph_world_prepare(a.world));
  /* The map covers the box's grid (21^3 voxels at least, with its padding more) at 16 bytes. */
  assert_true(get_stats(a.world).memory_bytes >= memory_before + 16u * 21u * 21u * 21u);
  EXPECT_OK(sph_world_prepare(a.world)); /* again: nothing stale, nothing to do */
  after_bytes = capi_save(a.world, &after_size);
  assert_true(before_size == after_size && memcmp(before_bytes, after_bytes, (size_t)before_size) == 0);
  /* b is stepped without it: the same bits. */
  EXPECT_OK(sph_world_step(a.world, 0.01f));
  EXPECT_OK(sph_world_step(b.world, 0.01f));
  capi_expect_same_particles(a.world, b.world);
  /* Errors. */
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_prepare(NULL));
  EXPECT_OK(sph_world_step_begin(b.world, 0.01f));
  EXPECT_ERROR(SPH_ERROR_WORLD_LOCKED, "world", sph_world_prepare(b.world));
  EXPECT_OK(sph_world_step_wait(b.world));
  free(before_bytes);
  free(after_bytes);
  gone = b.world;
  EXPECT_OK(sph_world_destroy(b.world));
  b.world = NULL;
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_prepare(gone));
  EXPECT_OK(sph_sdf_destroy(sdf_a));
  EXPECT_OK(sph_sdf_destroy(sdf_b));
  EXPECT_OK(support_world_close(&a));
  EXPECT_OK(support_world_close(&b));
}

/* sph_world_restore keeps what the world computed from assets the checkpoint holds unchanged: on
 * the CPU the restored world still holds the box's boundary-density map (a world loaded from the
 * same checkpoint holds none until it steps), and the next step gives the same particles, bit for
 * bit, as the loaded world's step, which computes the map again. (Before, every restore dropped
 * the maps: the step after it paid for them again, 0.38 s for a 90,601-voxel tank.) The CUDA
 * backend computes its maps again after a restore. */
static void test_restore_keeps_the_maps_of_unchanged_assets(void** state) {
  support_world a;
  sph_sdf* sdf = NULL;
  sph_world* loaded = NULL;
  unsigned char* saved;
  uint64_t size = 0;
  (void)state;
  memset(&a, 0, sizeof a);
  open_walled_water(&a, &sdf);
  EXPECT_OK(sph_world_step(a.world, 0.01f));
  saved = capi_save(a.world, &size);
  EXPECT_OK(sph_world_step(a.world, 0.01f));
  EXPECT_OK(sph_world_restore(a.world, saved, size));
  EXPECT_OK(sph_world_load(a.context, saved, size, &loaded));
  if (sph_test_backend() == SPH_BACKEND_CPU)
    assert_true(get_stats(a.world).memory_bytes >= get_stats(loaded).memory_bytes + 16u * 21u * 21u * 21u);
  EXPECT_OK(sph_world_step(a.world, 0.01f));
  EXPECT_OK(sph_world_step(loaded, 0.01f));
  capi_expect_same_particles(a.world, loaded);
  free(saved);
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(support_world_close(&a));
}

int main(void) {
#define FIXTURE(test) cmocka_unit_test_setup_teardown(test, capi_fixture_setup, capi_fixture_teardown)
  const struct CMUnitTest tests[] = {
      FIXTURE(test_step_bad_frame_dt),
      FIXTURE(test_stats_errors),
      FIXTURE(test_step_incomplete),
      FIXTURE(test_step_non_finite_rolls_back),
      cmocka_unit_test(test_stats_before_first_step),
      cmocka_unit_test(test_prepare_builds_what_a_step_would),
      cmocka_unit_test(test_restore_keeps_the_maps_of_unchanged_assets),
      FIXTURE(test_stats_after_step),
  };
  return cmocka_run_group_tests_name("capi_step_and_stats", tests, NULL, NULL);
}
