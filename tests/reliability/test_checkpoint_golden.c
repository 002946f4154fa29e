// SPDX-License-Identifier: MIT
/* Checkpoint format versions (issue 23 item 7). A fixed small world, built here from explicit
 * values and never stepped (so physics changes do not move its bytes), is saved and compared
 * byte for byte with tests/data/checkpoint_v<N>_world.sphckpt, N the version the writer writes:
 * a writer whose layout changed without a version bump fails here. Every golden file of every
 * format this library reads loads into the same world, and a format newer than the library's
 * answers VERSION_MISMATCH (never CORRUPT_DATA), whatever follows its version field.
 *
 * On the CPU backend whatever the test backend is: the writer's bytes are the point, and a CUDA
 * world's carried state (its max speed, say) may differ in the last bit.
 *
 * Run with `--write DIR` to write the current version's golden file into DIR (after a bump:
 * `build/tests/reliability_checkpoint_golden --write tests/data`, then commit the file; never
 * rewrite the file of a version that was already committed). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

#ifndef SPH_TEST_DATA_DIR
#error "SPH_TEST_DATA_DIR must name tests/data"
#endif

#define PARTICLES 27u
/* The header fields that may differ between two writers of one layout: the writer's backend
 * (u32 at 16), its library version (u32 at 20) and so the checksum (u64 at 32). */
#define BACKEND_OFFSET 16u
#define LIBRARY_VERSION_OFFSET 20u
#define CHECKSUM_OFFSET 32u

static uint32_t u32_at(const uint8_t* p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void put_u32(uint8_t* p, uint32_t v) {
  int k;
  for (k = 0; k < 4; ++k) p[k] = (uint8_t)(v >> (8 * k));
}

/* FNV-1a 64 over the header without its checksum, then the payload (docs/checkpoint.md). */
static void reseal(uint8_t* data, size_t size) {
  uint64_t h = 0xcbf29ce484222325ull;
  size_t i;
  int k;
  for (i = 0; i < size; ++i) {
    if (i >= CHECKSUM_OFFSET && i < CHECKSUM_OFFSET + 8) continue;
    h ^= data[i];
    h *= 0x100000001b3ull;
  }
  for (k = 0; k < 8; ++k) data[CHECKSUM_OFFSET + k] = (uint8_t)(h >> (8 * k));
}

static sph_sdf* sphere(sph_context* context, float radius) {
  sph_shape_desc d;
  sph_sdf* sdf = NULL;
  sph_shape_desc_init(&d);
  d.shape = SPH_SHAPE_SPHERE;
  d.radius = radius;
  d.voxel_size = 0.05f;
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

/* The fixed world: every section of the format has something in it, every value is typed here. */
static sph_world* build_fixed_world(sph_context* context) {
  sph_world_def def;
  sph_world_params params;
  sph_spawn_desc spawn;
  sph_collider_def collider;
  sph_source_def source;
  sph_sink_def sink;
  sph_force_field_def field;
  sph_collider_id collider_id;
  sph_source_id source_id;
  sph_sink_id sink_id;
  sph_force_field_id field_id;
  sph_world* world = NULL;
  sph_sdf *ball, *emitter;
  float positions[3 * PARTICLES], velocities[3 * PARTICLES];
  uint32_t i, first = 0;

  sph_world_def_init(&def);
  def.capacity = 64;
  def.particle_spacing = 0.05f;
  def.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_SPRINGS;
  EXPECT_OK(sph_world_create(context, &def, &world));
  sph_world_params_init(&params);
  params.max_substeps = 777;
  params.gravity.x = 0.25f;
  params.gravity.y = -9.5f;
  params.stiffness = 120.0f;
  params.dt_max = 2e-3f;
  EXPECT_OK(sph_world_set_params(world, &params));
  for (i = 0; i < PARTICLES; ++i) {
    positions[3 * i] = 0.05f * (float)(i % 3);
    positions[3 * i + 1] = 0.05f * (float)((i / 3) % 3);
    positions[3 * i + 2] = 0.05f * (float)(i / 9);
    velocities[3 * i] = 0.01f * (float)i;
    velocities[3 * i + 1] = -0.02f * (float)i;
    velocities[3 * i + 2] = 0.5f;
  }
  sph_spawn_desc_init(&spawn);
  spawn.count = PARTICLES;
  spawn.positions = positions;
  spawn.velocities = velocities;
  EXPECT_OK(sph_world_spawn(world, &spawn, &first));

  ball = sphere(context, 0.1f);
  emitter = sphere(context, 0.08f);
  sph_collider_def_init(&collider);
  collider.sdf = ball;
  collider.transform = at(0.5f, 0.0f, 0.0f);
  collider.restitution = 0.25f;
  collider.friction = 0.5f;
  EXPECT_OK(sph_collider_create(world, &collider, &collider_id));
  sph_source_def_init(&source);
  source.mode = SPH_SOURCE_CONTINUOUS;
  source.region = emitter;
  source.transform = at(0.0f, 0.6f, 0.0f);
  source.velocity.y = -1.0f;
  source.rate = 300.0f;
  EXPECT_OK(sph_source_create(world, &source, &source_id));
  sph_sink_def_init(&sink);
  sink.mode = SPH_SINK_OUTSIDE_BOUNDS;
  sink.bounds_min.x = sink.bounds_min.y = sink.bounds_min.z = -2.0f;
  sink.bounds_max.x = sink.bounds_max.y = sink.bounds_max.z = 2.0f;
  EXPECT_OK(sph_sink_create(world, &sink, &sink_id));
  sph_force_field_def_init(&field);
  field.kind = SPH_FORCE_FIELD_VORTEX;
  field.vector.y = 1.0f;
  field.strength = 1.5f;
  field.falloff_radius = 0.4f;
  field.region = ball; /* the collider's asset: saved once, used twice */
  EXPECT_OK(sph_force_field_create(world, &field, &field_id));
  EXPECT_OK(sph_sdf_destroy(ball));
  EXPECT_OK(sph_sdf_destroy(emitter));
  return world;
}

static uint8_t* save(const sph_world* world, uint64_t* size) {
  uint8_t* data;
  EXPECT_OK(sph_world_save(world, NULL, 0, size));
  data = (uint8_t*)malloc((size_t)*size);
  assert_non_null(data);
  EXPECT_OK(sph_world_save(world, data, *size, size));
  return data;
}

/* NULL when the file does not exist. */
static uint8_t* read_file(const char* path, uint64_t* size) {
  FILE* f = fopen(path, "rb");
  long n;
  uint8_t* data;
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  n = ftell(f);
  fseek(f, 0, SEEK_SET);
  data = (uint8_t*)malloc((size_t)n + 1);
  assert_non_null(data);
  assert_int_equal(fread(data, 1, (size_t)n, f), (size_t)n);
  fclose(f);
  *size = (uint64_t)n;
  return data;
}

static void golden_path(char* out, size_t size, const char* dir, uint32_t version) {
  snprintf(out, size, "%s/checkpoint_v%u_world.sphckpt", dir, (unsigned)version);
}

/* The section that holds byte `at` of a checkpoint (for the message), by walking the headers. */
static const char* section_of(const uint8_t* data, uint64_t size, uint64_t at) {
  static const char* names[] = {
      "world definition", "parameters", "clock and statistics", "particles", "SDF assets", "colliders",
      "sources",          "sinks",      "force fields",         "probes"};
  uint64_t offset = 48;
  uint32_t k;
  if (at < 48) return "header";
  for (k = 0; k < sizeof names / sizeof names[0] && offset + 16 <= size; ++k) {
    uint64_t length = 0;
    int b;
    for (b = 0; b < 8; ++b) length |= (uint64_t)data[offset + 8 + b] << (8 * b);
    if (at < offset + 16 + length) return names[k];
    offset += 16 + length;
  }
  return "after the last section";
}

/* The offset of the object ids' world tag: TIME's second u32 (format 15 on; 0 before), TIME being
 * the third section. */
static uint64_t world_tag_offset(const uint8_t* data, uint64_t size) {
  uint64_t offset = 48;
  uint32_t k;
  for (k = 0; k < 2; ++k) {
    uint64_t length = 0;
    int b;
    assert_true(offset + 16 <= size);
    for (b = 0; b < 8; ++b) length |= (uint64_t)data[offset + 8 + b] << (8 * b);
    offset += 16 + length;
  }
  assert_true(offset + 16 + 8 <= size);
  return offset + 16 + 4;
}

/* The current writer's bytes are the committed golden file's, but for who wrote them. */
static void test_writer_layout_matches_its_version(void** state) {
  sph_context* context = NULL;
  sph_world* world;
  uint8_t *now, *golden;
  uint64_t now_size = 0, golden_size = 0, i;
  uint32_t version;
  char path[512];
  (void)state;
  assert_int_equal(support_context_create(SPH_BACKEND_CPU, &context), SPH_OK);
  world = build_fixed_world(context);
  now = save(world, &now_size);
  version = u32_at(now + 8);
  golden_path(path, sizeof path, SPH_TEST_DATA_DIR, version);
  golden = read_file(path, &golden_size);
  if (!golden)
    fail_msg(
        "no golden file of checkpoint format version %u (%s). If you bumped kFormatVersion "
        "(src/core/checkpoint_format.h), write it with `reliability_checkpoint_golden --write "
        "tests/data` and commit it.",
        (unsigned)version, path);
  /* Who wrote it may differ; what it says may not. */
  memcpy(golden + BACKEND_OFFSET, now + BACKEND_OFFSET, 8);
  reseal(golden, (size_t)golden_size);
  /* The first difference but for the checksum, which differs whenever anything does. */
  for (i = 0; i < now_size && i < golden_size; ++i)
    if (now[i] != golden[i] && (i < CHECKSUM_OFFSET || i >= CHECKSUM_OFFSET + 8)) break;
  if (i == now_size && now_size == golden_size && memcmp(now, golden, (size_t)now_size) != 0)
    i = CHECKSUM_OFFSET;
  if (i < now_size || now_size != golden_size)
    fail_msg(
        "the checkpoint writer's output for the fixed world differs from %s (first at byte %llu, "
        "in section '%s'; %llu bytes now, %llu in the file) but the format version is still %u. "
        "A layout change needs a new format version: bump kFormatVersion in "
        "src/core/checkpoint_format.h, keep the reader of version %u (older files must still load), "
        "write the new golden file with `reliability_checkpoint_golden --write tests/data` and "
        "document the change in docs/checkpoint.md. Never rewrite a committed golden file.",
        path, (unsigned long long)i, section_of(now, now_size, i), (unsigned long long)now_size,
        (unsigned long long)golden_size, (unsigned)version, (unsigned)version);
  free(golden);
  free(now);
  EXPECT_OK(sph_world_destroy(world));
  sph_context_destroy(context);
}

static void copy_attribute(const sph_world* w, sph_attribute a, float* out, uint32_t n) {
  EXPECT_OK(sph_world_copy_attribute(w, a, out, 12ull * n, 0, 0, n, NULL));
}

/* Every golden world file of every version from 1 to the current one that exists loads into the
 * fixed world: the same particles, parameters and objects, saved again as the current version. */
static void test_every_golden_version_loads(void** state) {
  sph_context* context = NULL;
  sph_world *fixed, *loaded;
  uint8_t *now, *file, *resaved;
  uint64_t now_size = 0, file_size = 0, resaved_size = 0;
  uint32_t current, version, found = 0, count = 0;
  char path[512];
  (void)state;
  assert_int_equal(support_context_create(SPH_BACKEND_CPU, &context), SPH_OK);
  fixed = build_fixed_world(context);
  now = save(fixed, &now_size);
  current = u32_at(now + 8);
  for (version = 1; version <= current; ++version) {
    int a;
    sph_world_params p, q;
    golden_path(path, sizeof path, SPH_TEST_DATA_DIR, version);
    file = read_file(path, &file_size);
    if (!file) continue; /* the world files start at version 2 (version 1: test_checkpoint_formats) */
    ++found;
    assert_int_equal(u32_at(file + 8), version);
    loaded = NULL;
    if (sph_world_load(context, file, file_size, &loaded) != SPH_OK)
      fail_msg("%s (format version %u) no longer loads: %s", path, (unsigned)version, sph_get_last_error());
    EXPECT_OK(sph_world_get_particle_count(loaded, &count));
    assert_int_equal(count, PARTICLES);
    for (a = 0; a <= SPH_ATTRIBUTE_ID; ++a) { /* the golden worlds carry no user attribute */
      float x[3 * PARTICLES], y[3 * PARTICLES];
      copy_attribute(fixed, (sph_attribute)a, x, PARTICLES);
      copy_attribute(loaded, (sph_attribute)a, y, PARTICLES);
      if (memcmp(x, y, sizeof x) != 0) fail_msg("%s: attribute %d differs from the fixed world's", path, a);
    }
    sph_world_params_init(&p);
    sph_world_params_init(&q);
    EXPECT_OK(sph_world_get_params(fixed, &p));
    EXPECT_OK(sph_world_get_params(loaded, &q));
    assert_memory_equal(&p, &q, sizeof p);
    /* Saved again, it is the current format and the current writer's bytes for this world: the
     * objects, assets, clock and everything else came back too. */
    resaved = save(loaded, &resaved_size);
    assert_int_equal(u32_at(resaved + 8), current);
    assert_int_equal(resaved_size, now_size);
    if (version < 15) {
      /* A file before the world tag loads with tag 0 (its ids as saved); the fixed world, the
       * first of its context, has tag 1. */
      const uint64_t tag_at = world_tag_offset(resaved, resaved_size);
      assert_int_equal(u32_at(resaved + tag_at), 0);
      assert_int_equal(u32_at(now + tag_at), 1);
      memcpy(resaved + tag_at, now + tag_at, 4);
    }
    assert_memory_equal(resaved + 48, now + 48, (size_t)now_size - 48);
    free(resaved);
    free(file);
    EXPECT_OK(sph_world_destroy(loaded));
  }
  /* One world file for each version from 2 on (version 1: test_checkpoint_formats), so that a
   * golden file that goes missing fails here rather than leaving its version untested. */
  if (found != current - 1)
    fail_msg("%u golden world files for format versions 2..%u in %s: one per version expected",
             (unsigned)found, (unsigned)current, SPH_TEST_DATA_DIR);
  free(now);
  EXPECT_OK(sph_world_destroy(fixed));
  sph_context_destroy(context);
}

/* A newer format is VERSION_MISMATCH with a message that says so, before anything else of the
 * file is read: its checksum, sizes and sections may be laid out differently. */
static void test_newer_format_is_version_mismatch(void** state) {
  sph_context* context = NULL;
  sph_world *fixed, *out = NULL;
  uint8_t* data;
  uint64_t size = 0;
  uint32_t current;
  char expected[160];
  (void)state;
  assert_int_equal(support_context_create(SPH_BACKEND_CPU, &context), SPH_OK);
  fixed = build_fixed_world(context);
  data = save(fixed, &size);
  current = u32_at(data + 8);
  put_u32(data + 8, current + 1);
  reseal(data, (size_t)size);
  assert_int_equal(sph_world_load(context, data, size, &out), SPH_ERROR_VERSION_MISMATCH);
  assert_null(out);
  snprintf(expected, sizeof expected, "format version %u is newer than this library",
           (unsigned)(current + 1));
  if (!strstr(sph_get_last_error(), expected)) fail_msg("message \"%s\"", sph_get_last_error());
  /* Unsealed, truncated after the header, with another section count: still the version. */
  data[CHECKSUM_OFFSET] ^= 0xff;
  assert_int_equal(sph_world_load(context, data, 48, &out), SPH_ERROR_VERSION_MISMATCH);
  put_u32(data + 8, 0xffffffffu);
  assert_int_equal(sph_world_load(context, data, size, &out), SPH_ERROR_VERSION_MISMATCH);
  put_u32(data + 8, 0); /* never a version */
  assert_int_equal(sph_world_load(context, data, size, &out), SPH_ERROR_VERSION_MISMATCH);
  assert_null(out);
  free(data);
  EXPECT_OK(sph_world_destroy(fixed));
  sph_context_destroy(context);
}

static int write_golden(const char* dir) {
  sph_context* context = NULL;
  sph_world* world;
  uint8_t* data;
  uint64_t size = 0;
  char path[512];
  FILE* f;
  if (support_context_create(SPH_BACKEND_CPU, &context) != SPH_OK) return 1;
  world = build_fixed_world(context);
  data = save(world, &size);
  golden_path(path, sizeof path, dir, u32_at(data + 8));
  f = fopen(path, "wb");
  if (!f || fwrite(data, 1, (size_t)size, f) != (size_t)size || fclose(f) != 0) {
    fprintf(stderr, "cannot write %s\n", path);
    return 1;
  }
  printf("wrote %s (%llu bytes, format version %u)\n", path, (unsigned long long)size,
         (unsigned)u32_at(data + 8));
  free(data);
  sph_world_destroy(world);
  sph_context_destroy(context);
  return 0;
}

int main(int argc, char** argv) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_writer_layout_matches_its_version),
      cmocka_unit_test(test_every_golden_version_loads),
      cmocka_unit_test(test_newer_format_is_version_mismatch),
  };
  if (argc == 3 && strcmp(argv[1], "--write") == 0) return write_golden(argv[2]);
  return cmocka_run_group_tests(tests, NULL, NULL);
}
