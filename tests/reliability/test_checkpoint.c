// SPDX-License-Identifier: MIT
/* Checkpoints (issue 9, item 4): a world saved and loaded continues bit for bit as the saved
 * one does (same backend); ids of scene objects stay valid; every truncation and corruption is
 * refused with a clear error and creates nothing; a file is replaced only by a complete one.
 *
 * Bitwise equality is the honest tolerance here, not a strict one: the same library on the
 * same backend runs the same instructions on the same bits in the same order (the particles
 * are saved in storage order, which fixes every neighbour sum's order), so any difference is a
 * state the checkpoint failed to carry. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "capi_test.h"

#define FRAME_DT (1.0f / 60.0f)

/* ---- a scene with every kind of object ------------------------------------------------------ */
typedef struct scene_ids {
  sph_collider_id tank, paddle;
  sph_source_id source;
  sph_sink_id region_sink, bounds_sink;
  sph_force_field_id vortex, grid;
} scene_ids;

static sph_sdf* make_shape(sph_context* context, sph_shape shape, float radius, float voxel, float half,
                           float wall, uint32_t flags) {
  sph_shape_desc d;
  sph_sdf* sdf = NULL;
  sph_shape_desc_init(&d);
  d.shape = shape;
  d.radius = radius;
  d.half_extents.x = half;
  d.half_extents.y = half;
  d.half_extents.z = 0.75f * half;
  d.wall_thickness = wall;
  d.voxel_size = voxel;
  d.flags = flags;
  EXPECT_OK(sph_sdf_create_shape(context, &d, &sdf));
  return sdf;
}

static sph_transform at(float x, float y, float z) {
  sph_transform t = sph_transform_identity();
  t.position.x = x;
  t.position.y = y;
  t.position.z = z;
  return t;
}

/* A tank with water, a moving paddle, a continuous source, two sinks (a third was created and
 * destroyed, so the free list is not empty), a vortex and a grid force field. */
static sph_world* build_scene(sph_context* context, scene_ids* ids) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_world_params params;
  sph_fill_box_desc box;
  sph_collider_def collider;
  sph_source_def source;
  sph_sink_def sink;
  sph_sink_id dropped;
  sph_force_field_def field;
  sph_grid_desc grid;
  float accelerations[3 * 27];
  sph_sdf *tank, *ball, *emitter, *drain;
  uint32_t added = 0;
  int i;

  sph_world_def_init(&def);
  def.capacity = 3000;
  def.particle_spacing = 0.04f;
  EXPECT_OK(sph_world_create(context, &def, &world));
  sph_world_params_init(&params);
  /* A small step factor, so that the step size follows the fastest particle or collider and
   * the largest acceleration (the state a backend carries between frames), not dt_max. */
  params.dt_max = 2.5e-3f;
  params.step_factor = 0.05f;
  params.step_limits = SPH_STEP_LIMIT_FORCE;
  EXPECT_OK(sph_world_set_params(world, &params));
  sph_fill_box_desc_init(&box);
  box.min.x = -0.3f;
  box.min.y = 0.03f;
  box.min.z = -0.2f;
  box.max.x = 0.0f;
  box.max.y = 0.3f;
  box.max.z = 0.2f;
  EXPECT_OK(sph_world_fill_box(world, &box, &added));
  assert_true(added > 300);

  tank = make_shape(context, SPH_SHAPE_BOX, 0.0f, 0.05f, 0.4f, 0.05f, SPH_SHAPE_FLAG_OPEN_TOP);
  ball = make_shape(context, SPH_SHAPE_SPHERE, 0.08f, 0.04f, 0.5f, 0.0f, 0);
  emitter = make_shape(context, SPH_SHAPE_SPHERE, 0.06f, 0.03f, 0.5f, 0.0f, 0);
  drain = make_shape(context, SPH_SHAPE_SPHERE, 0.07f, 0.035f, 0.5f, 0.0f, 0);

  sph_collider_def_init(&collider);
  collider.sdf = tank;
  collider.transform = at(0.0f, 0.4f, 0.0f);
  collider.restitution = 0.1f;
  collider.friction = 0.2f;
  EXPECT_OK(sph_collider_create(world, &collider, &ids->tank));
  collider.sdf = ball;
  collider.transform = at(0.15f, 0.1f, 0.0f);
  collider.restitution = 0.0f;
  collider.stickiness = 0.5f;
  EXPECT_OK(sph_collider_create(world, &collider, &ids->paddle));

  sph_source_def_init(&source);
  source.mode = SPH_SOURCE_CONTINUOUS;
  source.region = emitter;
  source.transform = at(0.2f, 0.45f, 0.0f);
  source.velocity.y = -1.0f;
  source.rate = 700.0f; /* about 11.7 per frame: the fractional budget carries over */
  EXPECT_OK(sph_source_create(world, &source, &ids->source));

  sph_sink_def_init(&sink);
  sink.region = drain;
  sink.transform = at(-0.3f, 0.0f, 0.0f);
  EXPECT_OK(sph_sink_create(world, &sink, &dropped));
  sink.transform = at(0.2f, 0.3f, 0.0f); /* under the source: it drains what the source emits */
  EXPECT_OK(sph_sink_create(world, &sink, &ids->region_sink));
  EXPECT_OK(sph_sink_destroy(world, dropped));
  sph_sink_def_init(&sink);
  sink.mode = SPH_SINK_OUTSIDE_BOUNDS;
  sink.bounds_min.x = sink.bounds_min.y = sink.bounds_min.z = -1.0f;
  sink.bounds_max.x = sink.bounds_max.z = 1.0f;
  sink.bounds_max.y = 2.0f;
  EXPECT_OK(sph_sink_create(world, &sink, &ids->bounds_sink));

  sph_force_field_def_init(&field);
  field.kind = SPH_FORCE_FIELD_VORTEX;
  field.vector.y = 1.0f;
  field.strength = 2.0f;
  field.falloff_radius = 0.5f;
  EXPECT_OK(sph_force_field_create(world, &field, &ids->vortex));
  sph_force_field_def_init(&field);
  field.kind = SPH_FORCE_FIELD_GRID;
  sph_grid_desc_init(&grid);
  grid.dims[0] = grid.dims[1] = grid.dims[2] = 3;
  grid.components = 3;
  grid.index_to_local[0] = grid.index_to_local[5] = grid.index_to_local[10] = 0.5f;
  grid.index_to_local[3] = grid.index_to_local[7] = grid.index_to_local[11] = -0.5f;
  for (i = 0; i < 27; ++i) {
    accelerations[3 * i] = 40.0f * (float)(i % 3); /* strong enough for the force step limit */
    accelerations[3 * i + 1] = 0.0f;
    accelerations[3 * i + 2] = -0.2f * (float)(i / 9);
  }
  grid.data = accelerations;
  field.grid = &grid;
  field.region = ball; /* the paddle's asset too: saved once, used twice */
  EXPECT_OK(sph_force_field_create(world, &field, &ids->grid));

  /* The world keeps the assets; the handles can go. */
  EXPECT_OK(sph_sdf_destroy(tank));
  EXPECT_OK(sph_sdf_destroy(ball));
  EXPECT_OK(sph_sdf_destroy(emitter));
  EXPECT_OK(sph_sdf_destroy(drain));
  return world;
}

/* One frame of the script every copy of the scene follows: the paddle moves (through object
 * ids, which must stay valid in a loaded world), then the world steps. */
static void drive(sph_world* world, const scene_ids* ids, int frame) {
  sph_transform target = at(0.15f - 0.005f * (float)frame, 0.1f, 0.004f * (float)frame);
  sph_result r;
  EXPECT_OK(sph_collider_set_target_transform(world, ids->paddle, &target));
  r = sph_world_step(world, FRAME_DT);
  if (r != SPH_OK) fail_msg("frame %d: sph_world_step returned %d: %s", frame, (int)r, sph_get_last_error());
}

/* ---- the observable state of a world, compared bit for bit ---------------------------------- */
typedef struct world_state {
  uint32_t count;
  float* positions;
  float* velocities;
  float* densities;
  float* pressures;
  uint32_t* ids;
  sph_stats stats;
  uint32_t event_count;
  sph_event events[16];
  uint32_t removed_count;
  uint32_t removed[4096];
} world_state;

static void copy_out(const sph_world* world, sph_attribute attribute, void* dst, uint32_t count,
                     uint32_t components) {
  uint32_t written = 0;
  if (count == 0) return;
  EXPECT_OK(sph_world_copy_attribute(world, attribute, dst, (uint64_t)count * components * 4u, 0, 0, count,
                                     &written));
  assert_int_equal(written, count);
}

static void state_take(const sph_world* world, world_state* s) {
  uint32_t n = 0;
  EXPECT_OK(sph_world_get_particle_count(world, &n));
  s->count = n;
  s->positions = (float*)malloc(12u * (n + 1u));
  s->velocities = (float*)malloc(12u * (n + 1u));
  s->densities = (float*)malloc(4u * (n + 1u));
  s->pressures = (float*)malloc(4u * (n + 1u));
  s->ids = (uint32_t*)malloc(4u * (n + 1u));
  assert_non_null(s->positions);
  assert_non_null(s->velocities);
  assert_non_null(s->densities);
  assert_non_null(s->pressures);
  assert_non_null(s->ids);
  copy_out(world, SPH_ATTRIBUTE_POSITION, s->positions, n, 3);
  copy_out(world, SPH_ATTRIBUTE_VELOCITY, s->velocities, n, 3);
  copy_out(world, SPH_ATTRIBUTE_DENSITY, s->densities, n, 1);
  copy_out(world, SPH_ATTRIBUTE_PRESSURE, s->pressures, n, 1);
  copy_out(world, SPH_ATTRIBUTE_ID, s->ids, n, 1);
  sph_stats_init(&s->stats);
  EXPECT_OK(sph_world_get_stats(world, &s->stats));
  assert_true(sph_world_get_events(world, s->events, 16, &s->event_count) == SPH_OK);
  assert_true(sph_world_get_removed_ids(world, s->removed, 4096, &s->removed_count) == SPH_OK);
}

static void state_free(world_state* s) {
  free(s->positions);
  free(s->velocities);
  free(s->densities);
  free(s->pressures);
  free(s->ids);
}

#define SAME_BITS(a, b, n, what)                                                                           \
  do {                                                                                                     \
    if ((n) > 0 && memcmp((a), (b), (n)) != 0) fail_msg("%s: %s differ (not bitwise equal)", label, what); \
  } while (0)

/* Everything a caller can read, bit for bit; with_step_report also compares the last step's
 * statistics and events (timings excepted: they are wall-clock). */
static void state_expect_equal(const world_state* a, const world_state* b, int with_step_report,
                               const char* label) {
  if (a->count != b->count) fail_msg("%s: %u particles vs %u", label, a->count, b->count);
  SAME_BITS(a->positions, b->positions, 12u * a->count, "positions");
  SAME_BITS(a->velocities, b->velocities, 12u * a->count, "velocities");
  SAME_BITS(a->densities, b->densities, 4u * a->count, "densities");
  SAME_BITS(a->pressures, b->pressures, 4u * a->count, "pressures");
  SAME_BITS(a->ids, b->ids, 4u * a->count, "ids");
  SAME_BITS(&a->stats.simulated_time, &b->stats.simulated_time, sizeof(double), "simulated times");
  if (!with_step_report) return;
  assert_int_equal(a->stats.particle_count, b->stats.particle_count);
  assert_int_equal(a->stats.substeps, b->stats.substeps);
  assert_int_equal(a->stats.neighbors_max, b->stats.neighbors_max);
  SAME_BITS(&a->stats.frame_time, &b->stats.frame_time, 4, "frame times");
  SAME_BITS(&a->stats.dt_min, &b->stats.dt_min, 4, "dt_min");
  SAME_BITS(&a->stats.dt_max, &b->stats.dt_max, 4, "dt_max");
  SAME_BITS(&a->stats.max_speed, &b->stats.max_speed, 4, "max speeds");
  SAME_BITS(&a->stats.density_min, &b->stats.density_min, 4, "density minima");
  SAME_BITS(&a->stats.density_mean, &b->stats.density_mean, 4, "density means");
  SAME_BITS(&a->stats.density_max, &b->stats.density_max, 4, "density maxima");
  SAME_BITS(&a->stats.neighbors_mean, &b->stats.neighbors_mean, 4, "neighbour means");
  assert_int_equal(a->event_count, b->event_count);
  SAME_BITS(a->events, b->events, sizeof(sph_event) * a->event_count, "events");
  assert_int_equal(a->removed_count, b->removed_count);
  SAME_BITS(a->removed, b->removed, 4u * a->removed_count, "removed ids");
}

static uint8_t* save_to_memory(const sph_world* world, uint64_t* size) {
  uint8_t* buffer;
  uint64_t needed = 0, written = 0;
  EXPECT_OK(sph_world_save(world, NULL, 0, &needed));
  assert_true(needed > 48);
  buffer = (uint8_t*)malloc((size_t)needed);
  assert_non_null(buffer);
  EXPECT_OK(sph_world_save(world, buffer, needed, &written));
  assert_true(written == needed);
  *size = written;
  return buffer;
}

static uint32_t live_objects(void) {
  uint32_t n = 0;
  EXPECT_OK(sph_get_live_object_count(&n));
  return n;
}

/* A private directory for this test's files. */
static char g_dir[256];

static void make_dir(void) {
  const char* tmp = getenv("TMPDIR");
  snprintf(g_dir, sizeof g_dir, "%s/sph_checkpoint_XXXXXX", tmp && *tmp ? tmp : "/tmp");
  assert_non_null(mkdtemp(g_dir));
}

static void path_in_dir(char* out, size_t size, const char* name) {
  snprintf(out, size, "%s/%s", g_dir, name);
}

/* Removes the directory's files (and the directory). */
static void remove_dir(void) {
  DIR* d = opendir(g_dir);
  struct dirent* e;
  char path[512];
  if (!d) return;
  while ((e = readdir(d)) != NULL) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    snprintf(path, sizeof path, "%s/%s", g_dir, e->d_name);
    if (remove(path) != 0) rmdir(path);
  }
  closedir(d);
  rmdir(g_dir);
}

/* Number of temporary files (".tmp-") left in the directory. */
static int temporaries_left(void) {
  DIR* d = opendir(g_dir);
  struct dirent* e;
  int n = 0;
  assert_non_null(d);
  while ((e = readdir(d)) != NULL)
    if (strstr(e->d_name, ".tmp-") != NULL) ++n;
  closedir(d);
  return n;
}

/* ---- (a) continuation ----------------------------------------------------------------------- */
enum { FRAMES_BEFORE = 3, FRAMES_AFTER = 4 };

static void test_scene_continues_bitwise_from_memory_and_file(void** state) {
  sph_context* context = NULL;
  sph_world *original, *from_memory = NULL, *from_file = NULL, *restored = NULL;
  scene_ids ids;
  world_state expected[FRAMES_AFTER], at_save, got;
  uint8_t *checkpoint, *again;
  uint64_t size, size_again;
  char path[512];
  sph_transform pose_a, pose_b;
  sph_sink_def sink;
  sph_sink_id new_a, new_b, foreign;
  int f, k;
  const uint32_t live_before = live_objects();
  (void)state;

  EXPECT_OK(sph_test_context_create(&context));
  original = build_scene(context, &ids);
  for (f = 0; f < FRAMES_BEFORE; ++f) drive(original, &ids, f);

  /* Save mid-run, to memory and to a file; the saved state is what the caller saw then. */
  checkpoint = save_to_memory(original, &size);
  make_dir();
  path_in_dir(path, sizeof path, "scene.sphckpt");
  EXPECT_OK(sph_world_save_file(original, path));
  assert_int_equal(temporaries_left(), 0);
  state_take(original, &at_save);

  for (f = 0; f < FRAMES_AFTER; ++f) {
    drive(original, &ids, FRAMES_BEFORE + f);
    state_take(original, &expected[f]);
    print_message("frame %d: %u substeps, dt %g..%g, max speed %g, %u particles, %u removed\n",
                  FRAMES_BEFORE + f + 1, expected[f].stats.substeps, expected[f].stats.dt_min,
                  expected[f].stats.dt_max, expected[f].stats.max_speed, expected[f].count,
                  expected[f].removed_count);
  }
  assert_true(expected[FRAMES_AFTER - 1].stats.simulated_time > 0.1); /* 7 frames of 1/60 s */

  EXPECT_OK(sph_world_load(context, checkpoint, size, &from_memory));
  EXPECT_OK(sph_world_load_file(context, path, &from_file));
  assert_non_null(from_memory);
  assert_non_null(from_file);

  /* Right after loading: the saved state, and saving it again gives the same bytes. */
  state_take(from_memory, &got);
  state_expect_equal(&at_save, &got, 1, "loaded, before stepping");
  state_free(&got);

  /* Ids of the saved world's objects work in the loaded ones. */
  EXPECT_OK(sph_collider_get_transform(original, ids.tank, &pose_a));
  EXPECT_OK(sph_collider_get_transform(from_memory, ids.tank, &pose_b));
  assert_memory_equal(&pose_a, &pose_b, sizeof pose_a);
  pose_b = at(0.2f, 0.45f, 0.0f); /* where build_scene put it: a no-op that needs a valid id */
  EXPECT_OK(sph_source_set_transform(from_memory, ids.source, &pose_b));
  foreign.bits = ids.tank.bits; /* a collider's id is no sink's, there as here */
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_sink_destroy(from_memory, foreign));

  for (k = 0; k < 2; ++k) {
    sph_world* w = k == 0 ? from_memory : from_file;
    for (f = 0; f < FRAMES_AFTER; ++f) {
      char label[64];
      drive(w, &ids, FRAMES_BEFORE + f);
      state_take(w, &got);
      snprintf(label, sizeof label, "%s, frame %d after the save", k == 0 ? "memory" : "file", f + 1);
      state_expect_equal(&expected[f], &got, 1, label);
      state_free(&got);
    }
  }

  /* Restore in place: a world that went its own way comes back to the checkpoint, keeps its
   * handle, and continues as the others did. */
  EXPECT_OK(sph_world_load(context, checkpoint, size, &restored));
  drive(restored, &ids, 40);
  EXPECT_OK(sph_world_restore(restored, checkpoint, size));
  for (f = 0; f < FRAMES_AFTER; ++f) {
    drive(restored, &ids, FRAMES_BEFORE + f);
    state_take(restored, &got);
    state_expect_equal(&expected[f], &got, 1, "restored in place");
    state_free(&got);
  }

  /* Saving a loaded world gives the same bytes (checked last: the continuation above is the
   * test that matters; this one names the state that was lost if it fails). */
  EXPECT_OK(sph_world_restore(restored, checkpoint, size));
  again = save_to_memory(restored, &size_again);
  assert_true(size_again == size);
  assert_memory_equal(again, checkpoint, (size_t)size);
  free(again);

  /* The free lists came along: the next object gets the same id in both worlds. */
  sph_sink_def_init(&sink);
  sink.mode = SPH_SINK_OUTSIDE_BOUNDS;
  sink.bounds_min.x = sink.bounds_min.y = sink.bounds_min.z = -5.0f;
  sink.bounds_max.x = sink.bounds_max.y = sink.bounds_max.z = 5.0f;
  EXPECT_OK(sph_sink_create(original, &sink, &new_a));
  EXPECT_OK(sph_sink_create(from_file, &sink, &new_b));
  assert_true(new_a.bits == new_b.bits);

  for (f = 0; f < FRAMES_AFTER; ++f) state_free(&expected[f]);
  state_free(&at_save);
  free(checkpoint);
  EXPECT_OK(sph_world_destroy(restored));
  EXPECT_OK(sph_world_destroy(from_file));
  EXPECT_OK(sph_world_destroy(from_memory));
  EXPECT_OK(sph_world_destroy(original));
  EXPECT_OK(sph_context_destroy(context));
  remove_dir();
  assert_int_equal(live_objects(), live_before);
}

/* The options' state and parameters come along too: RK4, surface tension, normalised density,
 * Clavet viscosity and the Tait equation of state, each with non-default parameters. No source
 * appends particles here, so the speed and acceleration the backend carries from frame to
 * frame decide the first step after the load: with the force limit on (and a slow drop) the
 * largest acceleration sets the steps; with it off (and a fast drop) the largest speed does. */
static void options_case(uint32_t step_limits, float speed) {
  sph_context* context = NULL;
  sph_world_def def;
  sph_world *original = NULL, *loaded = NULL;
  sph_world_params params;
  sph_surface_tension_params tension, tension_loaded;
  sph_clavet_viscosity_params clavet;
  sph_tait_params tait, tait_loaded;
  sph_fill_sphere_desc ball;
  world_state expected, got;
  uint8_t* checkpoint;
  uint64_t size;
  uint32_t added;

  EXPECT_OK(sph_test_context_create(&context));
  sph_world_def_init(&def);
  def.capacity = 1200;
  def.particle_spacing = 0.02f;
  def.integrator = SPH_INTEGRATOR_RK4;
  def.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY;
  def.viscosity_method = SPH_VISCOSITY_CLAVET;
  def.equation_of_state = SPH_EOS_TAIT;
  EXPECT_OK(sph_world_create(context, &def, &original));
  sph_world_params_init(&params);
  params.dt_max = 2e-3f;
  params.step_factor = 0.01f;
  params.step_limits = step_limits;
  EXPECT_OK(sph_world_set_params(original, &params));
  sph_surface_tension_params_init(&tension);
  tension.coefficient = 0.5f;
  EXPECT_OK(sph_world_set_surface_tension_params(original, &tension));
  sph_clavet_viscosity_params_init(&clavet);
  clavet.linear = 4.0f;
  clavet.quadratic = 0.5f;
  EXPECT_OK(sph_world_set_clavet_viscosity_params(original, &clavet));
  sph_tait_params_init(&tait);
  tait.speed_of_sound = 12.0f;
  EXPECT_OK(sph_world_set_tait_params(original, &tait));
  sph_fill_sphere_desc_init(&ball);
  ball.center.y = 0.2f;
  ball.radius = 0.1f;
  ball.velocity.x = speed;
  EXPECT_OK(sph_world_fill_sphere(original, &ball, &added));
  assert_true(added > 400);

  EXPECT_OK(sph_world_step(original, 0.004f));
  checkpoint = save_to_memory(original, &size);
  EXPECT_OK(sph_world_step(original, 0.004f));
  state_take(original, &expected);

  EXPECT_OK(sph_world_load(context, checkpoint, size, &loaded));
  sph_surface_tension_params_init(&tension_loaded);
  EXPECT_OK(sph_world_get_surface_tension_params(loaded, &tension_loaded));
  assert_memory_equal(&tension, &tension_loaded, sizeof tension);
  sph_tait_params_init(&tait_loaded);
  EXPECT_OK(sph_world_get_tait_params(loaded, &tait_loaded));
  assert_memory_equal(&tait, &tait_loaded, sizeof tait);
  EXPECT_OK(sph_world_step(loaded, 0.004f));
  state_take(loaded, &got);
  print_message("options: %u substeps, dt %g..%g\n", got.stats.substeps, got.stats.dt_min, got.stats.dt_max);
  state_expect_equal(&expected, &got, 1, "RK4 with every option");
  state_free(&got);
  state_free(&expected);

  free(checkpoint);
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_world_destroy(original));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_options_continue_bitwise(void** state) {
  (void)state;
  options_case(SPH_STEP_LIMIT_FORCE, 0.3f);
  options_case(0, 3.0f);
}

/* ---- (b) damaged checkpoints ---------------------------------------------------------------- */

/* FNV-1a 64 as docs/checkpoint.md defines it, to forge a checkpoint whose checksum is right
 * but whose contents are not (a hostile file rather than a damaged one). */
static uint64_t fnv1a(const uint8_t* p, size_t n, uint64_t h) {
  size_t i;
  for (i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

static void put_u64(uint8_t* p, uint64_t v) {
  int k;
  for (k = 0; k < 8; ++k) p[k] = (uint8_t)(v >> (8 * k));
}

/* Rewrites the payload size and the checksum of a header to match the bytes. */
static void reseal(uint8_t* data, size_t size) {
  uint64_t h = fnv1a(data, 32, 0xcbf29ce484222325ull);
  put_u64(data + 24, (uint64_t)(size - 48));
  h = fnv1a(data, 32, 0xcbf29ce484222325ull);
  h = fnv1a(data + 40, size - 40, h);
  put_u64(data + 32, h);
}

/* Forges a checkpoint: the one float of the payload (after the 48-byte header) whose bits are
 * `marker` becomes `value`, and the checksum is made right again. The marker must occur once. */
static void forge_float(uint8_t* data, uint64_t size, float marker, float value) {
  uint64_t at;
  int found = 0;
  for (at = 48; at + 4 <= size; ++at)
    if (memcmp(data + at, &marker, 4) == 0) {
      memcpy(data + at, &value, 4);
      ++found;
    }
  assert_int_equal(found, 1);
  reseal(data, (size_t)size);
}

typedef struct damaged_fixture {
  sph_context* context;
  uint8_t* checkpoint;
  uint64_t size;
  uint8_t* scratch;
} damaged_fixture;

static int damaged_setup(void** state) {
  damaged_fixture* d = (damaged_fixture*)calloc(1, sizeof *d);
  scene_ids ids;
  sph_world* world;
  *state = d;
  if (!d || sph_test_context_create(&d->context) != SPH_OK) return -1;
  world = build_scene(d->context, &ids);
  drive(world, &ids, 0);
  d->checkpoint = save_to_memory(world, &d->size);
  d->scratch = (uint8_t*)malloc((size_t)d->size + 16);
  sph_world_destroy(world);
  return d->scratch ? 0 : -1;
}

static int damaged_teardown(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  free(d->checkpoint);
  free(d->scratch);
  sph_context_destroy(d->context);
  free(d);
  return 0;
}

/* The format version the writer writes: the fixture's checkpoint's (its u32 at byte 8). */
static uint32_t current_version(const damaged_fixture* d) {
  return (uint32_t)d->checkpoint[8] | (uint32_t)d->checkpoint[9] << 8 | (uint32_t)d->checkpoint[10] << 16 |
         (uint32_t)d->checkpoint[11] << 24;
}

/* The message of the last refused load (expect_refused's own calls clear the thread's). */
static char g_message[1024];

/* Loads data and expects `expected` (or one of the refusals when expected is SPH_OK: a forged
 * checkpoint may also be valid), no world unless it succeeded, and a message. */
static void expect_refused(damaged_fixture* d, const uint8_t* data, uint64_t size, sph_result expected,
                           const char* what, uint64_t where) {
  sph_world* out = (sph_world*)(uintptr_t)0x1;
  const uint32_t live = live_objects();
  const sph_result r = sph_world_load(d->context, data, size, &out);
  snprintf(g_message, sizeof g_message, "%s", sph_get_last_error());
  if (r != expected)
    fail_msg("%s at %llu: sph_world_load returned %d (%s), expected %d; %s", what, (unsigned long long)where,
             (int)r, sph_result_string(r), (int)expected, g_message);
  if (out != (sph_world*)(uintptr_t)0x1)
    fail_msg("%s at %llu: *out was written on failure", what, (unsigned long long)where);
  if (strncmp(g_message, "sph_world_load: checkpoint: ", 28) != 0)
    fail_msg("%s at %llu: unclear message \"%s\"", what, (unsigned long long)where, g_message);
  if (live_objects() != live)
    fail_msg("%s at %llu: a world was left behind", what, (unsigned long long)where);
}

/* Every truncation: each length of the header and payload is refused as truncated. */
static void test_every_truncation_is_refused(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  uint64_t n;
  for (n = 0; n < d->size; ++n) expect_refused(d, d->checkpoint, n, SPH_ERROR_CORRUPT_DATA, "truncation", n);
  /* A message names what is missing. */
  sph_world* out = NULL;
  assert_int_equal(sph_world_load(d->context, d->checkpoint, d->size - 1, &out), SPH_ERROR_CORRUPT_DATA);
  assert_non_null(strstr(sph_get_last_error(), "truncated"));
}

/* Truncations whose header was resealed (size and checksum made to match): the sections' own
 * bounds checks must refuse them, at every cut in the first 4 KiB and a dense sample after. */
static void test_resealed_truncations_are_refused(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  uint64_t n;
  int found_section_message = 0;
  for (n = 48; n < d->size; n += (n < 4096 ? 1 : 97)) {
    memcpy(d->scratch, d->checkpoint, (size_t)n);
    reseal(d->scratch, (size_t)n);
    expect_refused(d, d->scratch, n, SPH_ERROR_CORRUPT_DATA, "resealed truncation", n);
    if (strstr(g_message, "section '") != NULL) found_section_message = 1;
  }
  assert_true(found_section_message);
}

/* Single-byte corruption anywhere is caught by the checksum (or, in the magic and version, by
 * their own checks): every offset of the first 4 KiB, then every 13th, two patterns each. */
static void test_every_byte_flip_is_refused(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  uint64_t at;
  int pattern;
  for (at = 0; at < d->size; at += (at < 4096 ? 1 : 13)) {
    for (pattern = 0; pattern < 2; ++pattern) {
      const uint8_t mask = pattern == 0 ? 0x01 : 0xff;
      sph_result expected = SPH_ERROR_CORRUPT_DATA;
      memcpy(d->scratch, d->checkpoint, (size_t)d->size);
      d->scratch[at] ^= mask;
      /* The format version: one this library does not read is a version mismatch; an older one
       * it reads (4 -> 5 is newer, 4 -> 3 older) fails on the checksum like any other damage. */
      if (at >= 8 && at < 12) {
        const uint32_t version = (uint32_t)d->scratch[8] | (uint32_t)d->scratch[9] << 8 |
                                 (uint32_t)d->scratch[10] << 16 | (uint32_t)d->scratch[11] << 24;
        if (version < 1 || version > current_version(d)) expected = SPH_ERROR_VERSION_MISMATCH;
      }
      expect_refused(d, d->scratch, d->size, expected, "byte flip", at);
    }
  }
}

/* Forged corruption (checksum recomputed) at many offsets: the loader validates every field,
 * so each load either succeeds with a world that works or is refused; nothing crashes or
 * leaks (sanitizer builds check the memory side). */
static void test_forged_corruption_never_crashes(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  uint64_t at;
  uint32_t loaded = 0, refused = 0;
  const uint32_t live = live_objects();
  for (at = 48; at < d->size; at += (at < 2048 ? 1 : 211)) {
    sph_world* out = NULL;
    sph_result r;
    memcpy(d->scratch, d->checkpoint, (size_t)d->size);
    d->scratch[at] ^= (uint8_t)(0x5a + at);
    reseal(d->scratch, (size_t)d->size);
    r = sph_world_load(d->context, d->scratch, d->size, &out);
    if (r == SPH_OK) {
      ++loaded;
      sph_world_destroy(out);
    } else {
      ++refused;
      /* A forged capacity may be valid but more than the device holds (CUDA allocates the
       * capacity up front): that is the honest answer too. */
      if (r != SPH_ERROR_CORRUPT_DATA && r != SPH_ERROR_OUT_OF_DEVICE_MEMORY &&
          r != SPH_ERROR_OUT_OF_HOST_MEMORY)
        fail_msg("forged byte at %llu: %d (%s)", (unsigned long long)at, (int)r, sph_get_last_error());
      assert_null(out);
    }
  }
  assert_true(refused > 0);
  assert_int_equal(live_objects(), live);
  print_message("forged corruption: %u loaded, %u refused\n", loaded, refused);
}

/* Offset of the body of section `index` (0-based) of a checkpoint. */
static size_t section_body(const uint8_t* data, int index) {
  size_t at = 48;
  int k;
  for (k = 0; k < index; ++k) {
    uint64_t length = 0;
    int b;
    for (b = 0; b < 8; ++b) length |= (uint64_t)data[at + 8 + (size_t)b] << (8 * b);
    at += 16 + (size_t)length;
  }
  return at + 16;
}

/* Forged checkpoints that are valid but extreme: a small world whose one sphere asset is a
 * collider, a source region and a sink region, with one particle's position or velocity at a
 * time scaled by 2^128 on one axis (still finite, so the loader takes it). Each loads and steps: the SDF
 * lookups meet inf - inf = NaN query points, which must still index inside the grids (the first fuzzing of
 * the loader found an out-of-bounds read here); the step then completes or reports a
 * non-finite state. */
static void test_extreme_forged_values_step_without_crashing(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  sph_world_def def;
  sph_world *world = NULL, *loaded = NULL;
  sph_fill_box_desc box;
  sph_shape_desc shape;
  sph_sdf* ball = NULL;
  sph_collider_def collider;
  sph_source_def source;
  sph_sink_def sink;
  sph_collider_id collider_id;
  sph_source_id source_id;
  sph_sink_id sink_id;
  uint8_t *data, *forged;
  uint64_t size;
  size_t positions;
  uint32_t count, i;
  int axis, outcome[2] = {0, 0};

  sph_world_def_init(&def);
  def.capacity = 300;
  EXPECT_OK(sph_world_create(d->context, &def, &world));
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 0.08f;
  EXPECT_OK(sph_world_fill_box(world, &box, NULL));
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.05f;
  shape.voxel_size = 0.02f;
  EXPECT_OK(sph_sdf_create_shape(d->context, &shape, &ball));
  sph_collider_def_init(&collider);
  collider.sdf = ball;
  EXPECT_OK(sph_collider_create(world, &collider, &collider_id));
  sph_source_def_init(&source);
  source.region = ball;
  source.mode = SPH_SOURCE_CONTINUOUS;
  source.rate = 100.0f;
  EXPECT_OK(sph_source_create(world, &source, &source_id));
  sph_sink_def_init(&sink);
  sink.region = ball;
  EXPECT_OK(sph_sink_create(world, &sink, &sink_id));
  EXPECT_OK(sph_world_step(world, 0.01f));
  data = save_to_memory(world, &size);
  forged = (uint8_t*)malloc((size_t)size);
  assert_non_null(forged);
  memcpy(&count, data + section_body(data, 3), 4);
  positions = section_body(data, 3) + 16; /* count, 0, max speed, max acceleration */
  for (i = 0; i < 2 * count; ++i) {       /* positions, then velocities */
    for (axis = 0; axis < 3; ++axis) {
      const size_t at = positions + 16u * i + 4u * (uint32_t)axis;
      float v;
      sph_result r;
      memcpy(forged, data, (size_t)size);
      forged[at + 3] |= 0x40; /* the exponent + 128: x 2^128 for |v| < 2 */
      memcpy(&v, forged + at, 4);
      if (!isfinite(v)) continue;
      reseal(forged, (size_t)size);
      EXPECT_OK(sph_world_load(d->context, forged, size, &loaded));
      r = sph_world_step(loaded, 0.005f);
      if (r != SPH_ERROR_NON_FINITE && r != SPH_OK && r != SPH_INCOMPLETE)
        fail_msg("%s %u axis %d at %g: stepping returned %d: %s", i < count ? "position" : "velocity",
                 i % count, axis, (double)v, (int)r, sph_get_last_error());
      ++outcome[r == SPH_ERROR_NON_FINITE ? 0 : 1];
      EXPECT_OK(sph_world_destroy(loaded));
    }
  }
  print_message("extreme forged worlds: %d non-finite steps, %d completed\n", outcome[0], outcome[1]);
  free(forged);
  free(data);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(ball));
}

/* When a world's 2^32 particle ids run out (they are never reused), a source emits what ids are
 * left and reports the rest as SPH_EVENT_SOURCE_CAPACITY_REACHED, and the step succeeds, as at a
 * full capacity; before, every step failed with CAPACITY until the source was removed. Reached
 * here by a forged checkpoint (TIME's next id 2^32 - 7, the checksum resealed) rather than by
 * 2^32 emissions. */
static void test_source_at_the_end_of_the_ids(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  sph_world_def def;
  sph_world *world = NULL, *loaded = NULL;
  sph_shape_desc shape;
  sph_sdf* ball = NULL;
  sph_source_def source;
  sph_source_id source_id;
  uint8_t* data;
  uint64_t size;
  size_t at = 48;
  uint32_t next_id = 0xFFFFFFFFu - 6u, count = 0, events = 0, ids[8], i;
  sph_event event[4];
  int found = 0;

  sph_world_def_init(&def);
  def.capacity = 300;
  EXPECT_OK(sph_world_create(d->context, &def, &world));
  data = save_to_memory(world, &size);
  while (at + 16 <= size) { /* the TIME section: u32 next particle id first */
    uint64_t length = 0;
    int b;
    for (b = 0; b < 8; ++b) length |= (uint64_t)data[at + 8 + (size_t)b] << (8 * b);
    if (memcmp(data + at, "TIME", 4) == 0) {
      memcpy(data + at + 16, &next_id, 4);
      found = 1;
      break;
    }
    at += 16 + (size_t)length;
  }
  assert_true(found);
  reseal(data, (size_t)size);
  EXPECT_OK(sph_world_load(d->context, data, size, &loaded));
  free(data);
  EXPECT_OK(sph_world_destroy(world));
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.05f;
  shape.voxel_size = 0.02f;
  EXPECT_OK(sph_sdf_create_shape(d->context, &shape, &ball));
  sph_source_def_init(&source);
  source.region = ball;
  source.mode = SPH_SOURCE_CONTINUOUS;
  EXPECT_OK(sph_source_create(loaded, &source, &source_id));
  EXPECT_OK(sph_world_step(loaded, 0.005f));
  EXPECT_OK(sph_world_get_particle_count(loaded, &count));
  assert_int_equal(count, 6); /* ids 2^32 - 7 ... 2^32 - 2 */
  EXPECT_OK(sph_world_copy_attribute(loaded, SPH_ATTRIBUTE_ID, ids, sizeof ids, 0, 0, count, NULL));
  for (i = 0; i < count; ++i) assert_true(ids[i] >= next_id);
  EXPECT_OK(sph_world_get_events(loaded, event, 4, &events));
  assert_true(events >= 1 && event[0].type == SPH_EVENT_SOURCE_CAPACITY_REACHED && event[0].count > 0);
  EXPECT_OK(sph_world_step(loaded, 0.005f)); /* none left: nothing emitted, the step goes on */
  EXPECT_OK(sph_world_get_particle_count(loaded, &count));
  assert_int_equal(count, 6);
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_sdf_destroy(ball));
}

/* A failed step restores the world: with springs on, an emission lowers the springs' "lowest id
 * waiting" word to the emitted particles' first id, and a step that emitted and then failed
 * (NON_FINITE, rolled back) left it there, so the world saved other bytes than before the step
 * (its continuation was the same). Now the save after the failed step equals the one before it. */
static void test_failed_step_keeps_the_springs_state(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  sph_world_def def;
  sph_world* world = NULL;
  sph_fill_box_desc box;
  sph_shape_desc shape;
  sph_sdf* ball = NULL;
  sph_source_def source;
  sph_source_id source_id;
  sph_world_params good, bad;
  uint8_t *before, *after;
  uint64_t size_before, size_after;
  int k;

  sph_world_def_init(&def);
  def.capacity = 3000;
  def.features = SPH_FEATURE_SPRINGS;
  EXPECT_OK(sph_world_create(d->context, &def, &world));
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 0.08f;
  EXPECT_OK(sph_world_fill_box(world, &box, NULL));
  for (k = 0; k < 3; ++k) EXPECT_OK(sph_world_step(world, 0.005f)); /* every particle has its springs */
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_SPHERE;
  shape.radius = 0.04f;
  shape.voxel_size = 0.02f;
  EXPECT_OK(sph_sdf_create_shape(d->context, &shape, &ball));
  sph_source_def_init(&source);
  source.region = ball;
  source.transform = at(0.0f, 0.3f, 0.0f); /* clear of the block: it emits in the next step */
  EXPECT_OK(sph_source_create(world, &source, &source_id));
  before = save_to_memory(world, &size_before);
  sph_world_params_init(&good);
  EXPECT_OK(sph_world_get_params(world, &good));
  bad = good;
  bad.gravity.y = -3e38f; /* overflows in the first substep, after the emission */
  EXPECT_OK(sph_world_set_params(world, &bad));
  EXPECT_ERROR(SPH_ERROR_NON_FINITE, NULL, sph_world_step(world, 0.005f));
  EXPECT_OK(sph_world_set_params(world, &good));
  after = save_to_memory(world, &size_after);
  assert_true(size_after == size_before);
  assert_memory_equal(after, before, (size_t)size_before);
  free(before);
  free(after);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(ball));
}

/* The rule of sph_sdf_create on a velocity channel (speeds below 1.8e19 m/s), for a source that
 * gives its particles the channel's velocities, holds for a checkpoint too: a forged one whose
 * region holds 3e19 m/s is CORRUPT_DATA naming the source (the same channel in a force field's
 * grid, which holds accelerations, is no error: bdecb11). */
static void test_forged_fast_source_region_is_refused(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  sph_world_def def;
  sph_world *world = NULL, *loaded = NULL;
  sph_sdf_desc desc;
  sph_grid_desc velocity;
  sph_sdf* region = NULL;
  sph_source_def source;
  sph_source_id source_id;
  float distance[8] = {-1, -1, -1, -1, -1, -1, -1, -1}, speeds[24] = {0};
  const float marker = 1234.5f, fast = 3e19f;
  uint8_t* data;
  uint64_t size;

  sph_world_def_init(&def);
  def.capacity = 300;
  EXPECT_OK(sph_world_create(d->context, &def, &world));
  sph_sdf_desc_init(&desc);
  desc.distance.dims[0] = desc.distance.dims[1] = desc.distance.dims[2] = 2;
  desc.distance.index_to_local[0] = desc.distance.index_to_local[5] = desc.distance.index_to_local[10] =
      0.05f;
  desc.distance.data = distance;
  sph_grid_desc_init(&velocity);
  velocity.dims[0] = velocity.dims[1] = velocity.dims[2] = 2;
  speeds[21] = marker; /* voxel 7's x: a value to find in the bytes */
  velocity.data = speeds;
  desc.velocity = &velocity;
  EXPECT_OK(sph_sdf_create(d->context, &desc, &region));
  sph_source_def_init(&source);
  source.region = region;
  source.flags = SPH_SOURCE_FLAG_VELOCITY_FROM_FIELD;
  EXPECT_OK(sph_source_create(world, &source, &source_id));
  data = save_to_memory(world, &size);
  forge_float(data, size, marker, fast);
  EXPECT_ERROR(SPH_ERROR_CORRUPT_DATA, "region has a speed above 1.8e19",
               sph_world_load(d->context, data, size, &loaded));
  assert_null(loaded);
  free(data);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(region));
}

static void test_wrong_magic_future_version_and_trailing_bytes(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  char future[32];
  memcpy(d->scratch, d->checkpoint, (size_t)d->size);
  d->scratch[0] = 'X';
  expect_refused(d, d->scratch, d->size, SPH_ERROR_CORRUPT_DATA, "magic", 0);
  assert_non_null(strstr(g_message, "magic"));

  memcpy(d->scratch, d->checkpoint, (size_t)d->size);
  d->scratch[8] = (uint8_t)(current_version(d) + 1); /* resealed: a file from a later library */
  reseal(d->scratch, (size_t)d->size);
  expect_refused(d, d->scratch, d->size, SPH_ERROR_VERSION_MISMATCH, "future version", 8);
  snprintf(future, sizeof future, "version %u", (unsigned)(current_version(d) + 1));
  assert_non_null(strstr(g_message, future));

  memcpy(d->scratch, d->checkpoint, (size_t)d->size);
  d->scratch[d->size] = 0;
  expect_refused(d, d->scratch, d->size + 1, SPH_ERROR_CORRUPT_DATA, "trailing byte", d->size);
  reseal(d->scratch, (size_t)d->size + 1); /* a payload one byte longer than its sections */
  expect_refused(d, d->scratch, d->size + 1, SPH_ERROR_CORRUPT_DATA, "trailing payload byte", d->size);
  assert_non_null(strstr(g_message, "trailing"));
}

/* A failed restore leaves the world exactly as it was. */
static void test_failed_restore_changes_nothing(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  scene_ids ids;
  sph_world* world = build_scene(d->context, &ids);
  world_state before, after;
  drive(world, &ids, 0);
  state_take(world, &before);
  memcpy(d->scratch, d->checkpoint, (size_t)d->size);
  d->scratch[d->size / 2] ^= 0x10;
  EXPECT_ERROR(SPH_ERROR_CORRUPT_DATA, "checksum", sph_world_restore(world, d->scratch, d->size));
  EXPECT_ERROR(SPH_ERROR_CORRUPT_DATA, "truncated", sph_world_restore(world, d->checkpoint, 100));
  state_take(world, &after);
  state_expect_equal(&before, &after, 1, "after a failed restore");
  state_free(&before);
  state_free(&after);
  EXPECT_OK(sph_world_destroy(world));
}

/* A pending sph_world_cancel_step belongs to the handle, as the step budget does: a restore
 * keeps it, so the first step after the restore stops before its first substep. */
/* An undo of a deletion: colliders a and b share the caller's asset; save; destroy a; restore.
 * a comes back holding the caller's asset again (b still uses it), so the restored world saves
 * the same bytes as before (one asset; with a private copy for a, two: 120,147 -> 239,375 bytes
 * in an editor developer's review), and an update of the asset reaches both colliders (the save
 * after it still holds one asset, of the same size). */
static void test_undone_deletion_shares_the_asset(void** state) {
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_world_def def;
  sph_shape_desc shape;
  sph_sdf* box = NULL;
  sph_collider_def cdef;
  sph_collider_id a, b;
  uint64_t size = 0, size_after = 0, size_updated = 0;
  uint8_t *saved, *after, *updated;
  (void)state;

  EXPECT_OK(sph_test_context_create(&context));
  sph_world_def_init(&def);
  def.capacity = 64;
  EXPECT_OK(sph_world_create(context, &def, &world));
  sph_shape_desc_init(&shape);
  shape.shape = SPH_SHAPE_BOX;
  shape.half_extents.x = shape.half_extents.y = shape.half_extents.z = 0.1f;
  shape.voxel_size = 0.01f;
  EXPECT_OK(sph_sdf_create_shape(context, &shape, &box));
  sph_collider_def_init(&cdef);
  cdef.sdf = box;
  EXPECT_OK(sph_collider_create(world, &cdef, &a));
  EXPECT_OK(sph_collider_create(world, &cdef, &b));
  saved = save_to_memory(world, &size);
  EXPECT_OK(sph_collider_destroy(world, a));
  EXPECT_OK(sph_world_restore(world, saved, size));
  after = save_to_memory(world, &size_after);
  assert_int_equal(size_after, size);
  assert_int_equal(memcmp(after, saved, (size_t)size), 0);
  {
    const uint32_t origin[3] = {0, 0, 0}, one[3] = {1, 1, 1};
    const float far = 1.0f;
    EXPECT_OK(sph_sdf_update(box, SPH_SDF_CHANNEL_DISTANCE, origin, one, &far, SPH_MEMORY_HOST));
  }
  updated = save_to_memory(world, &size_updated);
  assert_int_equal(size_updated, size);
  assert_true(memcmp(updated, saved, (size_t)size) != 0);
  free(saved), free(after), free(updated);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(box));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_restore_keeps_a_pending_cancel(void** state) {
  damaged_fixture* d = (damaged_fixture*)*state;
  scene_ids ids;
  sph_world* world = build_scene(d->context, &ids);
  sph_stats stats;
  EXPECT_OK(sph_world_cancel_step(world));
  EXPECT_OK(sph_world_restore(world, d->checkpoint, d->size));
  assert_int_equal(sph_world_step(world, 1.0f / 60.0f), SPH_INCOMPLETE);
  sph_stats_init(&stats);
  EXPECT_OK(sph_world_get_stats(world, &stats));
  assert_int_equal(stats.substeps, 0);
  EXPECT_OK(sph_world_step(world, 1.0f / 60.0f));
  EXPECT_OK(sph_world_destroy(world));
}

/* ---- (c) atomic files ----------------------------------------------------------------------- */
static void write_text(const char* path, const char* text) {
  FILE* f = fopen(path, "wb");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

static int file_has_text(const char* path, const char* text) {
  char buf[64] = {0};
  FILE* f = fopen(path, "rb");
  size_t n;
  if (!f) return 0;
  n = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  return n == strlen(text) && memcmp(buf, text, n) == 0;
}

static void test_save_file_is_atomic(void** state) {
  sph_context* context = NULL;
  sph_world *world, *loaded = NULL;
  scene_ids ids;
  char path[512], missing[512], directory[512];
  struct rlimit old_limit, small;
  struct stat st;
  (void)state;

  EXPECT_OK(sph_test_context_create(&context));
  world = build_scene(context, &ids);
  make_dir();

  /* An existing file is replaced by a complete checkpoint. */
  path_in_dir(path, sizeof path, "world.sphckpt");
  write_text(path, "OLD");
  EXPECT_OK(sph_world_save_file(world, path));
  EXPECT_OK(sph_world_load_file(context, path, &loaded));
  EXPECT_OK(sph_world_destroy(loaded));
  assert_int_equal(temporaries_left(), 0);

  /* A save that fails while writing (the file-size limit, as a full disk would) leaves the old
   * file as it was and no temporary file behind. */
  write_text(path, "OLD");
  signal(SIGXFSZ, SIG_IGN);
  assert_int_equal(getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  small = old_limit;
  small.rlim_cur = 1000;
  assert_int_equal(setrlimit(RLIMIT_FSIZE, &small), 0);
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "unchanged", sph_world_save_file(world, path));
  assert_int_equal(setrlimit(RLIMIT_FSIZE, &old_limit), 0);
  assert_true(file_has_text(path, "OLD"));
  assert_int_equal(temporaries_left(), 0);

  /* A directory in the way: the rename fails, the directory stays, no temporary is left. */
  path_in_dir(directory, sizeof directory, "a_directory");
  assert_int_equal(mkdir(directory, 0700), 0);
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "path", sph_world_save_file(world, directory));
  assert_int_equal(stat(directory, &st), 0);
  assert_true(S_ISDIR(st.st_mode));
  assert_int_equal(temporaries_left(), 0);

  /* A directory that does not exist: nothing is created. */
  path_in_dir(missing, sizeof missing, "no/such/dir/world.sphckpt");
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "path", sph_world_save_file(world, missing));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "cannot open", sph_world_load_file(context, missing, &loaded));

  /* Loading what is not a checkpoint: an empty file, a text file. */
  write_text(path, "");
  EXPECT_ERROR(SPH_ERROR_CORRUPT_DATA, "truncated", sph_world_load_file(context, path, &loaded));
  write_text(path, "not a checkpoint, but long enough to hold a whole header of 48 bytes");
  EXPECT_ERROR(SPH_ERROR_CORRUPT_DATA, "magic", sph_world_load_file(context, path, &loaded));

  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
  remove_dir();
}

/* ---- (d) argument errors -------------------------------------------------------------------- */
/* A world whose caller pinned a fixed step above the stability ceiling (dt_min = dt_max, which
 * sph_world_set_params accepts: dt_min is the caller's floor and wins over the ceiling) must
 * load back. The reader once refused it as corrupt, so such a world could be saved but never
 * restored. */
static void test_fixed_step_above_ceiling_round_trips(void** state) {
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_world* loaded = NULL;
  sph_world_def def;
  sph_world_params params, read_back;
  uint64_t size = 0;
  uint8_t* checkpoint;
  (void)state;

  EXPECT_OK(sph_test_context_create(&context));
  sph_world_def_init(&def);
  def.capacity = 64;
  EXPECT_OK(sph_world_create(context, &def, &world));
  sph_world_params_init(&params);
  EXPECT_OK(sph_world_get_params(world, &params));
  /* Defaults: h = 0.036 m, c = 10 m/s, so the ceiling 0.4 h / c is 1.44 ms; pin 10 ms. */
  params.dt_min = params.dt_max = 0.01f;
  EXPECT_OK(sph_world_set_params(world, &params));
  checkpoint = save_to_memory(world, &size);
  EXPECT_OK(sph_world_load(context, checkpoint, size, &loaded));
  sph_world_params_init(&read_back);
  EXPECT_OK(sph_world_get_params(loaded, &read_back));
  assert_true(read_back.dt_min == 0.01f && read_back.dt_max == 0.01f);
  EXPECT_OK(sph_world_restore(world, checkpoint, size));
  free(checkpoint);
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* A world at the kernel radius bounds sph_world_create accepts is one the reader loads: 5 x the
 * spacing as written (0.1f for 0.02f, one float step above 5.0f * 0.02f) saved a checkpoint its
 * own library refused ("outside [1, 5] x the particle spacing": the reader checked in float) until
 * the two shared one rule. And a forged radius create refuses (h = spacing: the lattice scale
 * divides by zero) is CORRUPT_DATA, not a world whose first step is non-finite. */
static void test_kernel_radius_bounds_round_trip(void** state) {
  sph_context* context = NULL;
  sph_world *world = NULL, *loaded = NULL;
  sph_world_def def;
  uint64_t size = 0;
  uint8_t* checkpoint;
  const float spacing = 0.02f, marker = 0.0271828f;
  (void)state;

  EXPECT_OK(sph_test_context_create(&context));
  sph_world_def_init(&def);
  def.capacity = 64;
  def.particle_spacing = spacing;
  def.kernel_radius = 0.1f;
  EXPECT_OK(sph_world_create(context, &def, &world));
  checkpoint = save_to_memory(world, &size);
  EXPECT_OK(sph_world_load(context, checkpoint, size, &loaded));
  EXPECT_OK(sph_world_restore(world, checkpoint, size));
  free(checkpoint);
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_world_destroy(world));
  loaded = NULL;

  def.kernel_radius = marker;
  EXPECT_OK(sph_world_create(context, &def, &world));
  checkpoint = save_to_memory(world, &size);
  forge_float(checkpoint, size, marker, spacing);
  EXPECT_ERROR(SPH_ERROR_CORRUPT_DATA, "too close to the particle spacing",
               sph_world_load(context, checkpoint, size, &loaded));
  assert_null(loaded);
  free(checkpoint);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_argument_errors(void** state) {
  sph_context* context = NULL;
  sph_world* world = NULL;
  sph_world* out = NULL;
  sph_world_def def;
  uint8_t small[64];
  uint64_t size = 0, needed = 0;
  uint8_t* checkpoint;
  size_t i;
  (void)state;

  EXPECT_OK(sph_test_context_create(&context));
  sph_world_def_init(&def);
  def.capacity = 64;
  EXPECT_OK(sph_world_create(context, &def, &world));

  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_save(NULL, NULL, 0, &size));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out_size", sph_world_save(world, NULL, 0, NULL));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "buffer", sph_world_save(world, NULL, 100, &size));
  EXPECT_OK(sph_world_save(world, NULL, 0, &needed));
  /* Too small: the size comes back, the buffer is untouched. */
  memset(small, 0xab, sizeof small);
  size = 0;
  EXPECT_ERROR(SPH_ERROR_BUFFER_TOO_SMALL, "buffer_size", sph_world_save(world, small, sizeof small, &size));
  assert_true(size == needed);
  for (i = 0; i < sizeof small; ++i) assert_int_equal(small[i], 0xab);

  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_save_file(NULL, "x"));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "path", sph_world_save_file(world, NULL));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "path", sph_world_save_file(world, ""));

  checkpoint = save_to_memory(world, &size);
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context", sph_world_load(NULL, checkpoint, size, &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context",
               sph_world_load((sph_context*)(void*)world, checkpoint, size, &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "data", sph_world_load(context, NULL, size, &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out", sph_world_load(context, checkpoint, size, NULL));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "context", sph_world_load_file(NULL, "x", &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "path", sph_world_load_file(context, NULL, &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out", sph_world_load_file(context, "x", NULL));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_restore(NULL, checkpoint, size));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "data", sph_world_restore(world, NULL, size));
  assert_null(out);

  /* An empty world round-trips too. */
  EXPECT_OK(sph_world_load(context, checkpoint, size, &out));
  EXPECT_OK(sph_world_restore(world, checkpoint, size));
  EXPECT_OK(sph_world_destroy(out));
  free(checkpoint);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

int main(void) {
  const struct CMUnitTest continuation[] = {
      cmocka_unit_test(test_scene_continues_bitwise_from_memory_and_file),
      cmocka_unit_test(test_options_continue_bitwise),
      cmocka_unit_test(test_save_file_is_atomic),
      cmocka_unit_test(test_argument_errors),
      cmocka_unit_test(test_fixed_step_above_ceiling_round_trips),
      cmocka_unit_test(test_kernel_radius_bounds_round_trip),
  };
  const struct CMUnitTest damaged[] = {
      cmocka_unit_test(test_every_truncation_is_refused),
      cmocka_unit_test(test_resealed_truncations_are_refused),
      cmocka_unit_test(test_every_byte_flip_is_refused),
      cmocka_unit_test(test_forged_corruption_never_crashes),
      cmocka_unit_test(test_extreme_forged_values_step_without_crashing),
      cmocka_unit_test(test_source_at_the_end_of_the_ids),
      cmocka_unit_test(test_failed_step_keeps_the_springs_state),
      cmocka_unit_test(test_forged_fast_source_region_is_refused),
      cmocka_unit_test(test_wrong_magic_future_version_and_trailing_bytes),
      cmocka_unit_test(test_failed_restore_changes_nothing),
      cmocka_unit_test(test_restore_keeps_a_pending_cancel),
      cmocka_unit_test(test_undone_deletion_shares_the_asset),
  };
  int failed = cmocka_run_group_tests_name("checkpoint", continuation, NULL, NULL);
  failed += cmocka_run_group_tests_name("damaged checkpoints", damaged, damaged_setup, damaged_teardown);
  return failed;
}
