// SPDX-License-Identifier: MIT
/* Hostile use of the C API (issue 23, items 4, 5, 6 and 8): each test replays one class of
 * input that once crashed, over-read, lost a message or made a world its own save could not
 * restore, and checks the clear error (or the round trip) that replaced it.
 *
 * Part of the hostile-input suite: ctest label `hostile`. Under the sanitizer build
 * (build-sanitize/: ASan + UBSan) the enum and span cases also prove the absence of undefined
 * behaviour, which a Release build cannot show. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "capi_test.h"

static sph_context* make_context(sph_log_fn log, void* user) {
  sph_context_def def;
  sph_context* context = NULL;
  EXPECT_OK(sph_test_context_def_init(&def));
  def.cpu_worker_count = 1;
  def.log_fn = log;
  def.log_user_data = user;
  EXPECT_OK(sph_context_create(&def, &context));
  return context;
}

static sph_world* make_world(sph_context* context, uint32_t capacity) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_world_def_init(&def);
  def.capacity = capacity;
  EXPECT_OK(sph_world_create(context, &def, &world));
  return world;
}

/* The whole checkpoint of a world (malloc'd; *size its length). */
static uint8_t* save(const sph_world* world, uint64_t* size) {
  uint8_t* bytes;
  EXPECT_OK(sph_world_save(world, NULL, 0, size));
  bytes = (uint8_t*)malloc((size_t)*size);
  assert_non_null(bytes);
  EXPECT_OK(sph_world_save(world, bytes, *size, size));
  return bytes;
}

/* Every attribute of every particle bitwise, and the step's statistics but its wall times. */
static void expect_same_particles(const sph_world* a, const sph_world* b) {
  uint32_t count_a = 0, count_b = 0;
  sph_stats sa, sb;
  EXPECT_OK(sph_world_get_particle_count(a, &count_a));
  EXPECT_OK(sph_world_get_particle_count(b, &count_b));
  assert_int_equal(count_a, count_b);
  for (int k = 0; k <= SPH_ATTRIBUTE_ID; ++k) {
    const size_t bytes = 12u * count_a + 4u;
    void* va = malloc(bytes);
    void* vb = malloc(bytes);
    assert_true(va && vb);
    EXPECT_OK(sph_world_copy_attribute(a, (sph_attribute)k, va, bytes, 0, 0, count_a, NULL));
    EXPECT_OK(sph_world_copy_attribute(b, (sph_attribute)k, vb, bytes, 0, 0, count_b, NULL));
    assert_memory_equal(va, vb,
                        (k == SPH_ATTRIBUTE_POSITION || k == SPH_ATTRIBUTE_VELOCITY ? 12u : 4u) * count_a);
    free(va);
    free(vb);
  }
  sph_stats_init(&sa);
  sph_stats_init(&sb);
  EXPECT_OK(sph_world_get_stats(a, &sa));
  EXPECT_OK(sph_world_get_stats(b, &sb));
  assert_int_equal(sa.substeps, sb.substeps);
  assert_memory_equal(&sa.simulated_time, &sb.simulated_time, sizeof sa.simulated_time);
  assert_memory_equal(&sa.max_speed, &sb.max_speed, sizeof sa.max_speed);
  assert_memory_equal(&sa.dt_min, &sb.dt_min, sizeof sa.dt_min);
}

static void expect_same_checkpoint(const sph_world* a, const sph_world* b) {
  uint64_t size_a = 0, size_b = 0;
  uint8_t* bytes_a = save(a, &size_a);
  uint8_t* bytes_b = save(b, &size_b);
  assert_int_equal(size_a, size_b);
  assert_memory_equal(bytes_a, bytes_b, (size_t)size_a);
  free(bytes_a);
  free(bytes_b);
}

/* ---- item 8: struct_size far beyond any struct ---------------------------------------------- */
static void test_struct_size_beyond_any_struct_is_refused(void** state) {
  sph_context* context = make_context(NULL, NULL);
  /* A real def followed by zeros: a newer header's larger struct, accepted. */
  static unsigned char newer[sizeof(sph_world_def) + 256];
  sph_world_def* def = (sph_world_def*)newer;
  sph_world* world = NULL;
  static unsigned char big_init[1u << 17];
  (void)state;
  sph_world_def_init(def);
  def->struct_size = sizeof newer;
  EXPECT_OK(sph_world_create(context, def, &world));
  EXPECT_OK(sph_world_destroy(world));
  /* 4 GiB, 2 GiB and just over 64 KiB: refused without reading a byte past our struct (the
   * bytes beyond `newer` are not the caller's; ASan would report reading them). */
  {
    const uint32_t sizes[] = {UINT32_MAX, 0x80000000u, 64u * 1024u + 1u};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; ++i) {
      def->struct_size = sizes[i];
      world = NULL;
      EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "struct_size", sph_world_create(context, def, &world));
      assert_null(world);
    }
  }
  /* _init_sized with a size beyond 64 KiB is refused before it clears anything. */
  memset(big_init, 0xab, sizeof big_init);
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "size",
               sph_world_def_init_sized((sph_world_def*)big_init, (uint32_t)sizeof big_init));
  assert_int_equal(big_init[0], 0xab);
  assert_int_equal(big_init[sizeof big_init - 1], 0xab);
  /* Exactly 64 KiB is still a plausible (zero-padded) struct. */
  EXPECT_OK(sph_world_def_init_sized((sph_world_def*)big_init, 64u * 1024u));
  /* The parameter structs (read through their own tables) follow the same rule. */
  {
    static unsigned char params_buffer[sizeof(sph_world_params) + 64];
    sph_world_params* params = (sph_world_params*)params_buffer;
    world = NULL;
    def->struct_size = sizeof(sph_world_def);
    EXPECT_OK(sph_world_create(context, def, &world));
    sph_world_params_init(params);
    EXPECT_OK(sph_world_get_params(world, params));
    params->struct_size = UINT32_MAX;
    EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "struct_size", sph_world_set_params(world, params));
    memset(big_init, 0xab, sizeof big_init);
    EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "size",
                 sph_world_params_init_sized((sph_world_params*)big_init, (uint32_t)sizeof big_init));
    assert_int_equal(big_init[0], 0xab);
    EXPECT_OK(sph_world_destroy(world));
  }
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- item 8: spans that overflow 64 bits ------------------------------------------------------- */
static void test_spans_that_overflow_are_refused(void** state) {
  sph_context* context = make_context(NULL, NULL);
  sph_world* world = make_world(context, 64);
  static float positions[3 * 4] = {0.0f, 0.0f, 0.0f, 0.02f, 0.0f, 0.0f, 0.0f, 0.02f, 0.0f, 0.0f, 0.0f, 0.02f};
  static float out[64];
  sph_spawn_desc spawn;
  uint32_t count = 0;
  (void)state;
  sph_spawn_desc_init(&spawn);
  spawn.count = 4;
  spawn.positions = positions;
  /* 3 x 2^63 bytes between particles: the span wraps 64 bits (the reader would wrap memory). */
  spawn.position_stride = (uint64_t)1 << 63;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc->position_stride", sph_world_spawn(world, &spawn, NULL));
  spawn.position_stride = 0;
  spawn.velocities = positions;
  spawn.velocity_stride = UINT64_MAX / 2;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc->velocity_stride", sph_world_spawn(world, &spawn, NULL));
  EXPECT_OK(sph_world_get_particle_count(world, &count));
  assert_int_equal(count, 0);
  spawn.velocities = NULL;
  EXPECT_OK(sph_world_spawn(world, &spawn, NULL));
  /* A copy whose span overflows 64 bits is refused even when dst_size claims everything. */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "dst_stride",
               sph_world_copy_attribute(world, SPH_ATTRIBUTE_DENSITY, out, UINT64_MAX, UINT64_MAX / 2 + 1, 0,
                                        4, NULL));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "dst_stride",
               sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, out, UINT64_MAX, (uint64_t)1 << 62, 0,
                                        4, NULL));
  EXPECT_OK(sph_world_copy_attribute(world, SPH_ATTRIBUTE_DENSITY, out, sizeof out, 0, 0, 4, &count));
  assert_int_equal(count, 4);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- item 8: a log callback that calls back into the library -------------------------------- */
typedef struct reentrant_log {
  sph_world* world; /* the callback calls into it: a successful and a failing call */
  int calls;
  char first_message[256];
} reentrant_log;

static void SPH_CALL reentrant_callback(void* user, sph_log_level level, sph_result code,
                                        const char* message) {
  reentrant_log* log = (reentrant_log*)user;
  sph_stats stats;
  uint32_t count = 0;
  (void)level;
  (void)code;
  if (log->calls++ == 0) snprintf(log->first_message, sizeof log->first_message, "%s", message);
  sph_stats_init(&stats);
  /* A call that succeeds clears the thread's last error; one that fails sets its own. Neither
   * may replace the message of the call being reported, nor call back here again. */
  (void)sph_world_get_stats(log->world, &stats);
  (void)sph_world_get_particle_count(log->world, NULL);
  (void)sph_world_get_particle_count(log->world, &count);
}

static void test_reentrant_log_callback_keeps_the_message(void** state) {
  reentrant_log log;
  sph_context* context;
  sph_world* world;
  (void)state;
  memset(&log, 0, sizeof log);
  context = make_context(reentrant_callback, &log);
  world = make_world(context, 16);
  log.world = world;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step(world, -1.0f));
  assert_non_null(strstr(sph_get_last_error(), "sph_world_step"));
  /* Called once, for the step (the failing call inside the callback is not reported back). */
  assert_int_equal(log.calls, 1);
  assert_string_equal(log.first_message, sph_get_last_error());
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- item 4: caller enums with their top bits set ------------------------------------------- */
static void set_memory_kind(sph_grid_desc* grid, uint32_t bits) { memcpy(&grid->memory, &bits, sizeof bits); }

static void test_memory_kinds_with_top_bits_are_refused(void** state) {
  sph_context* context = make_context(NULL, NULL);
  sph_world* world = make_world(context, 16);
  const uint32_t kinds[] = {0x80000000u, 0xffffffffu, 0x80000001u, 2u};
  float voxels[27];
  sph_sdf_desc desc;
  sph_sdf* sdf = NULL;
  sph_force_field_def field;
  sph_grid_desc grid;
  sph_force_field_id field_id;
  const uint32_t origin[3] = {0, 0, 0}, size[3] = {1, 1, 1};
  (void)state;
  for (int i = 0; i < 27; ++i) voxels[i] = 1.0f;
  for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; ++k) {
    sph_memory_kind kind;
    sph_sdf_desc_init(&desc);
    desc.distance.dims[0] = desc.distance.dims[1] = desc.distance.dims[2] = 3;
    desc.distance.data = voxels;
    set_memory_kind(&desc.distance, kinds[k]);
    EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "memory", sph_sdf_create(context, &desc, &sdf));
    set_memory_kind(&desc.distance, SPH_MEMORY_HOST);
    EXPECT_OK(sph_sdf_create(context, &desc, &sdf));
    memcpy(&kind, &kinds[k], sizeof kind);
    EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "memory",
                 sph_sdf_update(sdf, SPH_SDF_CHANNEL_DISTANCE, origin, size, voxels, kind));
    EXPECT_OK(sph_sdf_destroy(sdf));
    sph_grid_desc_init(&grid);
    grid.dims[0] = grid.dims[1] = grid.dims[2] = 1;
    grid.components = 3;
    grid.data = voxels;
    set_memory_kind(&grid, kinds[k]);
    sph_force_field_def_init(&field);
    field.kind = SPH_FORCE_FIELD_GRID;
    field.grid = &grid;
    EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "memory", sph_force_field_create(world, &field, &field_id));
  }
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- item 6: whatever a world accepts, its own save restores ------------------------------- */
static void test_extreme_speeds_save_and_restore(void** state) {
  sph_context* context = make_context(NULL, NULL);
  sph_world* world = make_world(context, 16);
  sph_world* loaded = NULL;
  const float position[3] = {0.0f, 0.0f, 0.0f};
  /* Finite components whose squared length overflows float32 (|v|^2 = 1.2e39): a step treats
   * such a particle as non-finite, so spawning one is refused, with the limit in the message. */
  const float too_fast[3] = {2e19f, 2e19f, 2e19f};
  /* Just inside the limit: |v|^2 = 3e38 < FLT_MAX. */
  const float fast[3] = {1e19f, 1e19f, 1e19f};
  sph_spawn_desc spawn;
  sph_fill_box_desc box;
  sph_world_params params;
  sph_force_field_def field;
  sph_force_field_id field_id;
  uint64_t size = 0;
  uint8_t* bytes;
  sph_result stepped, stepped_loaded;
  (void)state;
  sph_spawn_desc_init(&spawn);
  spawn.count = 1;
  spawn.positions = position;
  spawn.velocities = too_fast;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc->velocities[0]", sph_world_spawn(world, &spawn, NULL));
  assert_non_null(strstr(sph_get_last_error(), "1.8e19 m/s"));
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 0.05f;
  box.velocity.y = -2e19f;
  box.velocity.x = 2e19f;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "desc->velocity", sph_world_fill_box(world, &box, NULL));
  spawn.velocities = fast;
  EXPECT_OK(sph_world_spawn(world, &spawn, NULL));
  bytes = save(world, &size);
  EXPECT_OK(sph_world_load(context, bytes, size, &loaded));
  expect_same_checkpoint(world, loaded);
  free(bytes);
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_world_destroy(world));

  /* A step can still leave a carried maximum infinite: an acceleration of 1e20 m/s^2 has finite
   * components but |a|^2 = 1e40 overflows, while one 1e-9 s substep keeps |v| finite. The world
   * carries max acceleration = +Inf; before the fix its save loaded as CORRUPT_DATA. */
  world = make_world(context, 16);
  spawn.velocities = NULL;
  EXPECT_OK(sph_world_spawn(world, &spawn, NULL));
  sph_world_params_init(&params);
  EXPECT_OK(sph_world_get_params(world, &params));
  params.dt_min = params.dt_max = 1e-9f;
  EXPECT_OK(sph_world_set_params(world, &params));
  sph_force_field_def_init(&field);
  field.kind = SPH_FORCE_FIELD_UNIFORM;
  field.vector.x = 1e20f;
  EXPECT_OK(sph_force_field_create(world, &field, &field_id));
  EXPECT_OK(sph_world_step(world, 1e-9f));
  bytes = save(world, &size);
  EXPECT_OK(sph_world_load(context, bytes, size, &loaded));
  expect_same_checkpoint(world, loaded);
  EXPECT_OK(sph_world_restore(loaded, bytes, size));
  expect_same_checkpoint(world, loaded);
  /* The loaded world steps as the original does, whatever that gives. */
  stepped = sph_world_step(world, 1e-9f);
  stepped_loaded = sph_world_step(loaded, 1e-9f);
  print_message(
      "max acceleration +Inf carried: save -> load and restore round-trip; the next step answers %s\n",
      sph_result_string(stepped));
  assert_int_equal(stepped, stepped_loaded);
  expect_same_particles(world, loaded); /* (the checkpoints differ in the steps' wall times) */
  free(bytes);
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- item 6: a failed step restores every carried field ----------------------------------- */
static sph_sdf* make_shape(sph_context* context, sph_shape shape, float half, float wall) {
  sph_shape_desc d;
  sph_sdf* sdf = NULL;
  sph_shape_desc_init(&d);
  d.shape = shape;
  d.half_extents.x = d.half_extents.y = d.half_extents.z = half;
  d.radius = half;
  d.wall_thickness = wall;
  d.voxel_size = 0.02f;
  EXPECT_OK(sph_sdf_create_shape(context, &d, &sdf));
  return sdf;
}

static void test_failed_step_after_emission_restores_carried_fields(void** state) {
  sph_context* context = make_context(NULL, NULL);
  sph_world* world = make_world(context, 2000);
  sph_sdf* blob = make_shape(context, SPH_SHAPE_SPHERE, 0.05f, 0.0f);
  sph_source_def source;
  sph_sink_def sink;
  sph_force_field_def field;
  sph_fill_box_desc box;
  sph_spawn_desc spawn;
  sph_source_id source_id;
  sph_sink_id sink_id;
  sph_force_field_id field_ids[2];
  sph_stats stats;
  uint64_t size_before = 0, size_after = 0;
  uint8_t *before, *after;
  uint32_t count = 0, count_before = 0, count_after = 0;
  static float velocity[3 * 2000];
  const float fast_position[3] = {0.998f, 0.5f, 0.0f}, fast_velocity[3] = {5.0f, 0.0f, 0.0f};
  float recomputed = 0.0f;
  (void)state;
  /* A block at rest, and one particle at 5 m/s about to leave through an OUTSIDE_BOUNDS sink.
   * The frame (1 ms, one substep) takes the max speed, 5 m/s, before the sink removes that
   * particle: the world then carries a max speed its velocities no longer give. */
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 0.1f;
  EXPECT_OK(sph_world_fill_box(world, &box, NULL));
  sph_spawn_desc_init(&spawn);
  spawn.count = 1;
  spawn.positions = fast_position;
  spawn.velocities = fast_velocity;
  EXPECT_OK(sph_world_spawn(world, &spawn, NULL));
  sph_sink_def_init(&sink);
  sink.mode = SPH_SINK_OUTSIDE_BOUNDS;
  sink.bounds_min.x = sink.bounds_min.y = sink.bounds_min.z = -1.0f;
  sink.bounds_max.x = sink.bounds_max.y = sink.bounds_max.z = 1.0f;
  EXPECT_OK(sph_sink_create(world, &sink, &sink_id));
  EXPECT_OK(sph_world_get_particle_count(world, &count_before));
  EXPECT_OK(sph_world_step(world, 1e-3f));
  sph_stats_init(&stats);
  EXPECT_OK(sph_world_get_stats(world, &stats));
  EXPECT_OK(sph_world_get_particle_count(world, &count));
  assert_int_equal(count, count_before - 1); /* the fast particle left */
  assert_int_equal(stats.substeps, 1);
  EXPECT_OK(
      sph_world_copy_attribute(world, SPH_ATTRIBUTE_VELOCITY, velocity, sizeof velocity, 0, 0, count, NULL));
  for (uint32_t i = 0; i < count; ++i) {
    const float* v = &velocity[3 * i];
    recomputed = fmaxf(recomputed, sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
  }
  print_message("carried max speed %.9g m/s, max over the velocities %.9g m/s\n", (double)stats.max_speed,
                (double)recomputed);
  assert_true(stats.max_speed > 4.9f && recomputed < 1.0f); /* the precondition */
  /* A source that fills once at the next step (an emission), and two uniform fields of 3e38
   * m/s^2 that add up to +Inf: that step fails after its emission. */
  sph_source_def_init(&source);
  source.mode = SPH_SOURCE_FILL_ONCE;
  source.region = blob;
  source.transform.position.x = 0.5f;
  source.transform.rotation.w = 1.0f;
  EXPECT_OK(sph_source_create(world, &source, &source_id));
  for (int k = 0; k < 2; ++k) {
    sph_force_field_def_init(&field);
    field.kind = SPH_FORCE_FIELD_UNIFORM;
    field.vector.x = 3e38f;
    EXPECT_OK(sph_force_field_create(world, &field, &field_ids[k]));
  }
  before = save(world, &size_before);
  EXPECT_ERROR(SPH_ERROR_NON_FINITE, NULL, sph_world_step(world, 1e-3f));
  EXPECT_OK(sph_world_get_particle_count(world, &count_after));
  assert_int_equal(count_after, count);
  /* Every carried field, the max speed and the last step's events (the sink's) among them, is
   * as it was: the checkpoints are identical byte for byte. */
  after = save(world, &size_after);
  assert_int_equal(size_before, size_after);
  assert_memory_equal(before, after, (size_t)size_before);
  /* The emission is undone too: without the fields the next step emits and succeeds. */
  EXPECT_OK(sph_force_field_destroy(world, field_ids[0]));
  EXPECT_OK(sph_force_field_destroy(world, field_ids[1]));
  EXPECT_OK(sph_world_step(world, 1e-3f));
  EXPECT_OK(sph_world_get_particle_count(world, &count_after));
  assert_true(count_after > count);
  free(before);
  free(after);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(blob));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- item 5: checkpoints are read from regular files of bounded size ------------------------ */
static void test_load_file_refuses_special_files(void** state) {
  sph_context* context = make_context(NULL, NULL);
  sph_world* world = NULL;
  char dir[] = "/tmp/sph_hostile_XXXXXX";
  char fifo[64], big[64];
  int fd;
  (void)state;
  assert_non_null(mkdtemp(dir));
  /* /dev/zero never ends; before the fix the loader read it until the OOM killer came. */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "not a regular file",
               sph_world_load_file(context, "/dev/zero", &world));
  assert_null(world);
  /* A FIFO with no writer: opening it for reading would block forever. */
  snprintf(fifo, sizeof fifo, "%s/fifo", dir);
  assert_int_equal(mkfifo(fifo, 0600), 0);
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "not a regular file", sph_world_load_file(context, fifo, &world));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "not a regular file", sph_world_load_file(context, dir, &world));
  assert_null(world);
  /* A sparse file beyond the 256 GiB cap is refused from its size, without reading it. */
  snprintf(big, sizeof big, "%s/big.sph", dir);
  fd = open(big, O_WRONLY | O_CREAT | O_EXCL, 0600);
  assert_true(fd >= 0);
  if (ftruncate(fd, (off_t)((1ll << 38) + 1)) == 0) {
    EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "256 GiB", sph_world_load_file(context, big, &world));
    assert_null(world);
  } else {
    print_message("(this file system cannot hold a sparse 256 GiB file: the size cap is not tried)\n");
  }
  close(fd);
  unlink(big);
  unlink(fifo);
  rmdir(dir);
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- item 8: the temporary files of killed saves --------------------------------------------- */
static int count_entries_with(const char* dir, const char* part) {
  DIR* listing = opendir(dir);
  const struct dirent* entry;
  int n = 0;
  assert_non_null(listing);
  while ((entry = readdir(listing)) != NULL)
    if (strstr(entry->d_name, part)) ++n;
  closedir(listing);
  return n;
}

static void remove_tree(const char* dir) {
  DIR* listing = opendir(dir);
  const struct dirent* entry;
  char path[512];
  if (!listing) return;
  while ((entry = readdir(listing)) != NULL) {
    if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0) continue;
    snprintf(path, sizeof path, "%s/%s", dir, entry->d_name);
    unlink(path);
  }
  closedir(listing);
  rmdir(dir);
}

static void touch(const char* path) {
  const int fd = open(path, O_WRONLY | O_CREAT | O_EXCL, 0600);
  assert_true(fd >= 0);
  close(fd);
}

static void test_save_removes_temporaries_of_killed_saves(void** state) {
  /* The CPU backend whatever SPH_TEST_BACKEND says: a child of fork() must not use CUDA. */
  sph_context_def cpu;
  sph_context* context = NULL;
  sph_context_def_init(&cpu);
  cpu.backend = SPH_BACKEND_CPU;
  cpu.cpu_worker_count = 1;
  EXPECT_OK(sph_context_create(&cpu, &context));
  sph_world* world = make_world(context, 200000);
  sph_fill_box_desc box;
  char dir[] = "/tmp/sph_hostile_XXXXXX";
  char path[64], stale[256], live[256], foreign[128], host[128], tag[128];
  pid_t dead, saver;
  int status = 0;
  size_t t = 0;
  (void)state;
  assert_non_null(mkdtemp(dir));
  snprintf(path, sizeof path, "%s/world.sph", dir);
  sph_fill_box_desc_init(&box);
  box.max.x = box.max.y = box.max.z = 0.5f; /* 19,652 particles: a save of about 1 MB */
  EXPECT_OK(sph_world_fill_box(world, &box, NULL));
  /* The temporary-name tag of this host, as the library writes it. */
  assert_int_equal(gethostname(host, sizeof host - 1), 0);
  host[sizeof host - 1] = '\0';
  for (const char* c = host; *c && t < 64; ++c, ++t)
    tag[t] = (char)((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
                            *c == '.' || *c == '_'
                        ? *c
                        : '_');
  tag[t] = '\0';
  /* 1. A save killed while it wrote: a child saves in a loop and is killed mid-way. */
  saver = fork();
  assert_true(saver >= 0);
  if (saver == 0) {
    for (;;) sph_world_save_file(world, path);
  }
  usleep(300000);
  kill(saver, SIGKILL);
  waitpid(saver, &status, 0);
  /* 2. A temporary file of a process that is gone, one of a live process (this one), and
   *    files that only look alike (another host, another name, an older library's). */
  dead = fork();
  assert_true(dead >= 0);
  if (dead == 0) _exit(0);
  waitpid(dead, &status, 0);
  snprintf(stale, sizeof stale, "%s.tmp-%ld-0-12345-%s", path, (long)dead, tag);
  snprintf(live, sizeof live, "%s.tmp-%ld-0-12345-%s", path, (long)getpid(), tag);
  touch(stale);
  touch(live);
  snprintf(foreign, sizeof foreign, "%s.tmp-%ld-0-12345-another.host", path, (long)dead);
  touch(foreign);
  snprintf(foreign, sizeof foreign, "%s.tmp-%ld-0-12345", path, (long)dead);
  touch(foreign);
  snprintf(foreign, sizeof foreign, "%s/.hidden.tmp", dir);
  touch(foreign);
  EXPECT_OK(sph_world_save_file(world, path));
  {
    char killed_prefix[64];
    snprintf(killed_prefix, sizeof killed_prefix, ".tmp-%ld-", (long)saver);
    assert_int_equal(count_entries_with(dir, killed_prefix), 0); /* the killed child's */
  }
  assert_int_equal(access(stale, F_OK), -1);
  assert_int_equal(access(live, F_OK), 0);
  /* Kept: the other host's, the older library's (no host), the hidden foreign file. */
  assert_int_equal(count_entries_with(dir, ".tmp"), 4);
  remove_tree(dir);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_struct_size_beyond_any_struct_is_refused),
      cmocka_unit_test(test_spans_that_overflow_are_refused),
      cmocka_unit_test(test_reentrant_log_callback_keeps_the_message),
      cmocka_unit_test(test_memory_kinds_with_top_bits_are_refused),
      cmocka_unit_test(test_extreme_speeds_save_and_restore),
      cmocka_unit_test(test_failed_step_after_emission_restores_carried_fields),
      cmocka_unit_test(test_load_file_refuses_special_files),
      cmocka_unit_test(test_save_removes_temporaries_of_killed_saves),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
