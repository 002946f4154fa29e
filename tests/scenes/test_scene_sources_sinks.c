// SPDX-License-Identifier: MIT
/* Sources and sinks (issue 4, items 3, 4 and 6): a source's count and spacing match its FCC
 * lattice, it never emits on top of fluid, it stops cleanly at capacity with an event; a sink
 * removes exactly the particles inside it and reports their ids. Zero gravity and tiny steps
 * keep particles where they were placed, so the expectations are exact. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene_test.h"

static sph_sdf* sphere_asset(scene* s, float radius, float voxel) {
  sph_shape_desc d;
  sph_shape_desc_init(&d);
  d.shape = SPH_SHAPE_SPHERE;
  d.radius = radius;
  d.voxel_size = voxel;
  return scene_shape(s, &d);
}

static sph_source_id add_source(scene* s, sph_sdf* region, sph_source_mode mode, float rate) {
  sph_source_def def;
  sph_source_id id;
  sph_source_def_init(&def);
  def.region = region;
  def.mode = mode;
  def.rate = rate;
  SCENE_OK(sph_source_create(s->world, &def, &id));
  return id;
}

static uint32_t count_of(scene* s) {
  uint32_t n = 0;
  SCENE_OK(sph_world_get_particle_count(s->world, &n));
  return n;
}

/* A sphere of radius 12 spacings: the emitted count is within 2 % of the lattice's density
 * times the volume (sqrt(2) / s^3 per m^3; the boundary layer of a sphere this size moves the
 * count by about 1 %), every particle's nearest neighbour sits at exactly the spacing (to
 * float rounding), and every particle is inside the sphere. */
static void test_source_fills_fcc_lattice(void** state) {
  const float spacing = 0.01f, radius = 0.12f;
  scene s;
  sph_sdf* ball;
  uint32_t n, i, j;
  float *x, expected;
  (void)state;
  scene_open(&s, 40000, spacing, 0.0f, 1e-3f);
  ball = sphere_asset(&s, radius, 0.005f);
  add_source(&s, ball, SPH_SOURCE_FILL_ONCE, 0.0f);
  assert_int_equal(count_of(&s), 0);
  SCENE_OK(sph_world_step(s.world, 1e-6f));
  n = count_of(&s);
  expected =
      4.0f / 3.0f * 3.14159265f * radius * radius * radius * sqrtf(2.0f) / (spacing * spacing * spacing);
  assert_true(fabsf((float)n - expected) <= 0.02f * expected);
  x = malloc(12 * (size_t)n);
  assert_non_null(x);
  scene_positions(&s, x, n);
  for (i = 0; i < n; i += 7) { /* a sample of particles keeps the O(n^2) check quick */
    float nearest = 1e30f;
    for (j = 0; j < n; ++j) {
      float dx, dy, dz, d;
      if (j == i) continue;
      dx = x[3 * i] - x[3 * j];
      dy = x[3 * i + 1] - x[3 * j + 1];
      dz = x[3 * i + 2] - x[3 * j + 2];
      d = sqrtf(dx * dx + dy * dy + dz * dz);
      if (d < nearest) nearest = d;
    }
    assert_true(fabsf(nearest - spacing) <= 1e-4f * spacing + 1e-6f);
    assert_true(sqrtf(x[3 * i] * x[3 * i] + x[3 * i + 1] * x[3 * i + 1] + x[3 * i + 2] * x[3 * i + 2]) <=
                radius + 0.005f);
  }
  /* FILL_ONCE: the next step emits nothing. */
  SCENE_OK(sph_world_step(s.world, 1e-6f));
  assert_int_equal(count_of(&s), n);
  free(x);
  SCENE_OK(sph_sdf_destroy(ball));
  scene_close(&s);
}

/* A source whose lattice is coarser than 2 world spacings with min_distance left at its default:
 * 0.9 x its spacing would pass the kernel radius (1.8 spacings), which the emission's search cannot
 * reach, so the default takes the kernel radius instead of refusing a field the caller never set.
 * The lattice is filled once (its count within 5 % of sqrt(2) / s^3 per m^3: a coarse lattice's
 * boundary moves the count more) and an explicit min_distance beyond the kernel radius is still
 * refused, naming it. */
static void test_default_min_distance_within_kernel(void** state) {
  const float spacing = 0.02f, source_spacing = 0.05f, radius = 0.3f;
  scene s;
  sph_sdf* ball;
  sph_source_def def;
  sph_source_id id;
  float expected;
  uint32_t n;
  (void)state;
  scene_open(&s, 4000, spacing, 0.0f, 1e-3f);
  ball = sphere_asset(&s, radius, 0.01f);
  sph_source_def_init(&def);
  def.region = ball;
  def.spacing = source_spacing;
  SCENE_OK(sph_source_create(s.world, &def, &id));
  SCENE_OK(sph_world_step(s.world, 1e-6f));
  n = count_of(&s);
  expected = 4.0f / 3.0f * 3.14159265f * radius * radius * radius * sqrtf(2.0f) /
             (source_spacing * source_spacing * source_spacing);
  print_message("  %u particles from the 5 cm lattice (%.0f expected)\n", n, (double)expected);
  assert_true(fabsf((float)n - expected) <= 0.05f * expected);
  def.min_distance = 0.045f;
  assert_int_equal(sph_source_create(s.world, &def, &id), SPH_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(sph_get_last_error(), "min_distance"));
  SCENE_OK(sph_sdf_destroy(ball));
  scene_close(&s);
}

/* "At most rate particles per second" of simulated time when frames stop early: a continuous
 * source of 600 particles/s emits at each frame's start as if the frame would run whole, and a
 * frame cut short by max_substeps (1 substep of 1 ms out of 1/60 s) gives back the credit of the
 * time it did not simulate, a debt later frames pay first. Over 60 such frames (59 ms simulated)
 * the count is within one frame's credit (10 particles) of rate x time; before the debt it was
 * 600, a second's worth. A checkpoint carries the debt (format version 14), and the loaded world
 * emits what the original does. */
static void test_rate_holds_when_frames_stop_early(void** state) {
  const float rate = 600.0f, frame = 1.0f / 60.0f;
  scene s;
  sph_sdf* ball;
  sph_source_def def;
  sph_source_id id;
  sph_stats stats;
  sph_world* loaded = NULL;
  double simulated = 0.0;
  uint32_t n, n_loaded = 0;
  uint64_t size = 0;
  void* buffer;
  int f;
  (void)state;
  scene_open(&s, 20000, 0.02f, 0.0f, 1e-3f);
  s.params.max_substeps = 1;
  scene_set_params(&s);
  ball = sphere_asset(&s, 0.3f, 0.01f);
  sph_source_def_init(&def);
  def.region = ball;
  def.mode = SPH_SOURCE_CONTINUOUS;
  def.rate = rate;
  SCENE_OK(sph_source_create(s.world, &def, &id));
  for (f = 0; f < 60; ++f) {
    assert_int_equal(sph_world_step(s.world, frame), SPH_INCOMPLETE);
    sph_stats_init(&stats);
    SCENE_OK(sph_world_get_stats(s.world, &stats));
    simulated += stats.frame_time;
  }
  n = count_of(&s);
  print_message("  %u particles over %.4f s simulated (rate x time %.1f)\n", n, simulated, rate * simulated);
  assert_true((double)n <= rate * simulated + rate * frame + 1.0);
  assert_true((double)n >= rate * simulated - rate * frame - 1.0);

  SCENE_OK(sph_world_save(s.world, NULL, 0, &size));
  buffer = malloc((size_t)size);
  assert_non_null(buffer);
  SCENE_OK(sph_world_save(s.world, buffer, size, &size));
  assert_true(((const uint8_t*)buffer)[8] >= 14); /* the format version (14: the debt), little-endian */
  SCENE_OK(sph_world_load(s.context, buffer, size, &loaded));
  for (f = 0; f < 5; ++f) {
    assert_int_equal(sph_world_step(s.world, frame), SPH_INCOMPLETE);
    assert_int_equal(sph_world_step(loaded, frame), SPH_INCOMPLETE);
  }
  SCENE_OK(sph_world_get_particle_count(loaded, &n_loaded));
  assert_int_equal(n_loaded, count_of(&s));
  assert_true(count_of(&s) > n); /* the debt was paid and emission went on */
  sph_world_destroy(loaded);
  free(buffer);
  SCENE_OK(sph_sdf_destroy(ball));
  scene_close(&s);
}

/* A continuous source refills only where fluid left: with nothing moving it adds nothing on the
 * second step; its rate limit caps what one step emits. */
static void test_continuous_source_respects_existing_fluid_and_rate(void** state) {
  scene s;
  sph_sdf* ball;
  uint32_t first;
  (void)state;
  scene_open(&s, 40000, 0.01f, 0.0f, 1e-3f);
  ball = sphere_asset(&s, 0.05f, 0.005f);
  add_source(&s, ball, SPH_SOURCE_CONTINUOUS, 0.0f);
  SCENE_OK(sph_world_step(s.world, 1e-6f));
  first = count_of(&s);
  assert_true(first > 500);
  SCENE_OK(sph_world_step(s.world, 1e-6f));
  assert_int_equal(count_of(&s), first);
  SCENE_OK(sph_sdf_destroy(ball));
  scene_close(&s);

  /* 1000 particles per second over 0.1 s: at most 100. */
  scene_open(&s, 40000, 0.01f, 0.0f, 1e-3f);
  ball = sphere_asset(&s, 0.05f, 0.005f);
  add_source(&s, ball, SPH_SOURCE_CONTINUOUS, 1000.0f);
  SCENE_OK(sph_world_step(s.world, 0.1f));
  assert_int_equal(count_of(&s), 100);
  SCENE_OK(sph_sdf_destroy(ball));
  scene_close(&s);
}

/* At capacity a source emits what fits, the step succeeds, and an event says how many did
 * not fit. */
static void test_source_at_capacity_reports_event(void** state) {
  scene s;
  sph_sdf* ball;
  sph_source_id source;
  sph_event events[4];
  uint32_t count = 0;
  (void)state;
  scene_open(&s, 100, 0.01f, 0.0f, 1e-3f);
  ball = sphere_asset(&s, 0.05f, 0.005f);
  source = add_source(&s, ball, SPH_SOURCE_FILL_ONCE, 0.0f);
  SCENE_OK(sph_world_step(s.world, 1e-6f));
  assert_int_equal(count_of(&s), 100);
  SCENE_OK(sph_world_get_events(s.world, events, 4, &count));
  assert_int_equal(count, 1);
  assert_int_equal(events[0].type, SPH_EVENT_SOURCE_CAPACITY_REACHED);
  assert_true(events[0].object_bits == source.bits);
  assert_true(events[0].count > 300); /* the ~530-point lattice minus the 100 that fit */
  /* Two-call pattern: capacity 0 asks for the count. */
  assert_int_equal(sph_world_get_events(s.world, NULL, 0, &count), SPH_INCOMPLETE);
  assert_int_equal(count, 1);
  SCENE_OK(sph_sdf_destroy(ball));
  scene_close(&s);
}

/* A sink sphere inside a filled box removes exactly the particles whose centres are inside it
 * (by the asset's own distance, the sink's test) and reports their ids; nothing else changes. */
static void test_sink_removes_exactly_particles_inside(void** state) {
  scene s;
  sph_sdf* ball;
  sph_sink_def def;
  sph_sink_id sink;
  sph_fill_box_desc fill;
  uint32_t n = 0, i, removed_count = 0, expected_count = 0, after;
  float* x;
  uint32_t *ids, *removed, *expected;
  sph_event event;
  uint32_t events = 0;
  (void)state;
  scene_open(&s, 20000, 0.01f, 0.0f, 1e-3f);
  ball = sphere_asset(&s, 0.05f, 0.005f);
  sph_fill_box_desc_init(&fill);
  fill.min.x = fill.min.y = fill.min.z = -0.1f;
  fill.max.x = fill.max.y = fill.max.z = 0.1f;
  SCENE_OK(sph_world_fill_box(s.world, &fill, &n));
  x = malloc(12 * (size_t)n);
  ids = malloc(4 * (size_t)n);
  removed = malloc(4 * (size_t)n);
  expected = malloc(4 * (size_t)n);
  assert_true(x && ids && removed && expected);
  scene_positions(&s, x, n);
  scene_ids(&s, ids, n);
  for (i = 0; i < n; ++i) {
    float d;
    sph_vec3 p;
    p.x = x[3 * i] - 0.0031f; /* the sink sits off the lattice's symmetry */
    p.y = x[3 * i + 1] - 0.0213f;
    p.z = x[3 * i + 2] - 0.0017f;
    SCENE_OK(sph_sdf_sample(ball, p, &d));
    assert_true(fabsf(d) > 1e-5f); /* no particle on the boundary: the expectation is sharp */
    if (d < 0.0f) expected[expected_count++] = ids[i];
  }
  assert_true(expected_count > 200);
  sph_sink_def_init(&def);
  def.region = ball;
  def.transform = scene_at(0.0031f, 0.0213f, 0.0017f);
  SCENE_OK(sph_sink_create(s.world, &def, &sink));
  SCENE_OK(sph_world_step(s.world, 1e-6f));
  after = count_of(&s);
  assert_int_equal(after, n - expected_count);
  SCENE_OK(sph_world_get_removed_ids(s.world, removed, n, &removed_count));
  assert_int_equal(removed_count, expected_count);
  for (i = 0; i < expected_count; ++i) {
    uint32_t j, found = 0;
    for (j = 0; j < removed_count; ++j) found |= removed[j] == expected[i];
    assert_true(found);
  }
  SCENE_OK(sph_world_get_events(s.world, &event, 1, &events));
  assert_int_equal(events, 1);
  assert_int_equal(event.type, SPH_EVENT_SINK_REMOVED);
  assert_int_equal(event.count, expected_count);
  assert_true(event.object_bits == sink.bits);
  /* The survivors are all outside the sphere. */
  scene_positions(&s, x, after);
  for (i = 0; i < after; ++i) {
    float d;
    sph_vec3 p;
    p.x = x[3 * i] - 0.0031f;
    p.y = x[3 * i + 1] - 0.0213f;
    p.z = x[3 * i + 2] - 0.0017f;
    SCENE_OK(sph_sdf_sample(ball, p, &d));
    assert_true(d > 0.0f);
  }
  free(x);
  free(ids);
  free(removed);
  free(expected);
  SCENE_OK(sph_sdf_destroy(ball));
  scene_close(&s);
}

/* An OUTSIDE_BOUNDS sink removes what leaves the box: particles shot in +x leave it. */
static void test_bounds_sink_removes_escapees(void** state) {
  scene s;
  sph_sink_def def;
  sph_sink_id sink;
  uint32_t fast, slow, removed[4], count = 0;
  (void)state;
  scene_open(&s, 16, 0.02f, 0.0f, 1e-3f);
  sph_sink_def_init(&def);
  def.mode = SPH_SINK_OUTSIDE_BOUNDS;
  def.bounds_min.x = def.bounds_min.y = def.bounds_min.z = -1.0f;
  def.bounds_max.x = def.bounds_max.y = def.bounds_max.z = 1.0f;
  SCENE_OK(sph_sink_create(s.world, &def, &sink));
  fast = scene_spawn_one(&s, 0.5f, 0.0f, 0.0f, 10.0f, 0.0f, 0.0f);
  slow = scene_spawn_one(&s, -0.5f, 0.0f, 0.0f, 0.1f, 0.0f, 0.0f);
  SCENE_OK(sph_world_step(s.world, 0.1f));
  assert_int_equal(count_of(&s), 1);
  SCENE_OK(sph_world_get_removed_ids(s.world, removed, 4, &count));
  assert_int_equal(count, 1);
  assert_int_equal(removed[0], fast);
  {
    float p[3], v[3];
    scene_particle(&s, slow, p, v);
    assert_true(fabsf(p[0] - (-0.49f)) < 1e-4f);
  }
  scene_close(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_source_fills_fcc_lattice),
      cmocka_unit_test(test_default_min_distance_within_kernel),
      cmocka_unit_test(test_continuous_source_respects_existing_fluid_and_rate),
      cmocka_unit_test(test_rate_holds_when_frames_stop_early),
      cmocka_unit_test(test_source_at_capacity_reports_event),
      cmocka_unit_test(test_sink_removes_exactly_particles_inside),
      cmocka_unit_test(test_bounds_sink_removes_escapees),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
