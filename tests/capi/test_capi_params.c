// SPDX-License-Identifier: MIT
/* Runtime parameters through the one validation path (issue 15, items 1-2 and 6):
 * - a params struct that is all zeros but for struct_size is valid and yields exactly the
 *   values sph_c.h documents, for every params struct;
 * - every range rule and cross-field rule fires with its message, naming the field, and leaves
 *   the world unchanged;
 * - what sph_params_get_field_info / sph_get_physics_method_info tell tools is what the set calls do
 *   (each described bound is enforced at exactly that value, each offset is the header's). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

#define SPACING 0.02f /* h = 1.8 spacings = 0.036 m */

typedef struct world_fixture {
  sph_context* context;
  sph_world* world;
  sph_world* dfsph; /* the DFSPH solver's world: its params (it excludes Tait) */
} world_fixture;

/* The fixture's world that runs the method whose params are of `kind`. */
static sph_world* world_of(const world_fixture* f, uint32_t kind) {
  return kind == SPH_PARAMS_DFSPH ? f->dfsph : f->world;
}

/* A world that runs every method with parameters but DFSPH, and a DFSPH world, so every params
 * struct is accepted by one of them. */
static int open_all_options(void** state) {
  static world_fixture f;
  sph_world_def def;
  assert_int_equal(sph_test_context_create(&f.context), SPH_OK);
  sph_world_def_init(&def);
  def.capacity = 256;
  def.particle_spacing = SPACING;
  def.features = SPH_FEATURE_SURFACE_TENSION | SPH_FEATURE_SPRINGS | SPH_FEATURE_NORMALIZED_DENSITY |
                 SPH_FEATURE_DENSITY_DIFFUSION;
  def.viscosity_method = SPH_VISCOSITY_CLAVET;
  def.equation_of_state = SPH_EOS_TAIT;
  assert_int_equal(sph_world_create(f.context, &def, &f.world), SPH_OK);
  sph_world_def_init(&def);
  def.capacity = 256;
  def.particle_spacing = SPACING;
  def.solver = SPH_SOLVER_DFSPH;
  assert_int_equal(sph_world_create(f.context, &def, &f.dfsph), SPH_OK);
  *state = &f;
  return 0;
}

static int close_world(void** state) {
  world_fixture* f = (world_fixture*)*state;
  sph_world_destroy(f->world);
  sph_world_destroy(f->dfsph);
  sph_context_destroy(f->context);
  return 0;
}

/* A struct of `kind` with only struct_size set, in a buffer as large as any params struct. */
typedef struct params_buffer {
  union {
    unsigned char bytes[128];
    double align;
  } u;
} params_buffer;

static uint32_t params_size(sph_params_kind kind) {
  sph_params_info info;
  sph_params_info_init(&info);
  EXPECT_OK(sph_params_get_info(kind, &info));
  assert_true(info.params_size <= sizeof(((params_buffer*)0)->u.bytes));
  return info.params_size;
}

static params_buffer zeroed(sph_params_kind kind) {
  params_buffer b;
  const uint32_t size = params_size(kind);
  memset(&b, 0, sizeof b);
  memcpy(b.u.bytes, &size, sizeof size);
  return b;
}

static params_buffer read_back(sph_world* world, sph_params_kind kind) {
  params_buffer b = zeroed(kind);
  EXPECT_OK(sph_world_get_physics_params(world, kind, b.u.bytes));
  return b;
}

static float float_at(const params_buffer* b, uint32_t offset) {
  float v;
  memcpy(&v, b->u.bytes + offset, sizeof v);
  return v;
}

/* ---- zero means default ----------------------------------------------------------------- */

/* The values sph_c.h documents for a zeroed struct, field by field. */
static void test_zeroed_structs_take_the_documented_values(void** state) {
  world_fixture* f = (world_fixture*)*state;
  sph_world_params w;
  sph_surface_tension_params st;
  sph_clavet_viscosity_params cv;
  sph_tait_params tait;
  sph_spring_params sp;

  memset(&w, 0, sizeof w);
  w.struct_size = sizeof w;
  EXPECT_OK(sph_world_set_params(f->world, &w));
  memset(&w, 0xab, sizeof w);
  w.struct_size = sizeof w;
  EXPECT_OK(sph_world_get_params(f->world, &w));
  assert_int_equal(w.max_substeps, 10000);
  /* Gravity 0 is no gravity: zero is a physical value there, and a zeroed struct keeps it. */
  assert_true(w.gravity.x == 0.0f && w.gravity.y == 0.0f && w.gravity.z == 0.0f);
  assert_true(w.stiffness == 100.0f);
  assert_true(w.viscosity == 0.0f); /* an inviscid fluid */
  assert_true(w.step_factor == 0.4f);
  assert_true(w.dt_min == 1e-6f);
  assert_true(w.dt_max == 1e-3f);
  assert_int_equal(w.step_limits, 0);
  assert_int_equal(w.reserved0, 0);
  assert_true(w.tension_ratio == 0.0f); /* the clamp at zero below rho0 */

  memset(&st, 0, sizeof st);
  st.struct_size = sizeof st;
  EXPECT_OK(sph_world_set_surface_tension_params(f->world, &st));
  memset(&st, 0xab, sizeof st);
  st.struct_size = sizeof st;
  EXPECT_OK(sph_world_get_surface_tension_params(f->world, &st));
  assert_true(st.coefficient == 0.0f);      /* no tension */
  assert_true(st.normal_threshold == 0.0f); /* 0.2 / h, derived when the world steps */

  memset(&cv, 0, sizeof cv);
  cv.struct_size = sizeof cv;
  EXPECT_OK(sph_world_set_clavet_viscosity_params(f->world, &cv));
  memset(&cv, 0xab, sizeof cv);
  cv.struct_size = sizeof cv;
  EXPECT_OK(sph_world_get_clavet_viscosity_params(f->world, &cv));
  assert_true(cv.linear == 0.0f && cv.quadratic == 0.0f);

  memset(&tait, 0, sizeof tait);
  tait.struct_size = sizeof tait;
  EXPECT_OK(sph_world_set_tait_params(f->world, &tait));
  memset(&tait, 0xab, sizeof tait);
  tait.struct_size = sizeof tait;
  EXPECT_OK(sph_world_get_tait_params(f->world, &tait));
  assert_true(tait.speed_of_sound == 10.0f);

  memset(&sp, 0, sizeof sp);
  sp.struct_size = sizeof sp;
  EXPECT_OK(sph_world_set_spring_params(f->world, &sp));
  memset(&sp, 0xab, sizeof sp);
  sp.struct_size = sizeof sp;
  EXPECT_OK(sph_world_get_spring_params(f->world, &sp));
  assert_true(sp.stiffness == 0.0f && sp.link_radius == 0.0f && sp.yield_ratio == 0.0f &&
              sp.plasticity == 0.0f && sp.damping == 0.0f);

  /* A world set with zeroed structs steps (the derived values are usable). */
  {
    sph_fill_sphere_desc sphere;
    uint32_t added = 0;
    sph_fill_sphere_desc_init(&sphere);
    sphere.radius = 0.05f;
    EXPECT_OK(sph_world_fill_sphere(f->world, &sphere, &added));
    assert_true(added > 10);
    EXPECT_OK(sph_world_step(f->world, 1.0f / 120.0f));
  }
}

/* The same through the descriptions: a field whose zero is a default reads back its
 * default_value, every other field reads back 0; for every params struct. */
static void test_zero_rule_matches_the_descriptions(void** state) {
  world_fixture* f = (world_fixture*)*state;
  uint32_t kind;
  for (kind = 0; kind < SPH_PARAMS_KIND_COUNT; ++kind) {
    const params_buffer zero = zeroed((sph_params_kind)kind);
    params_buffer got;
    sph_params_info info;
    uint32_t k;
    EXPECT_OK(sph_world_set_physics_params(world_of(f, kind), (sph_params_kind)kind, zero.u.bytes));
    got = read_back(world_of(f, kind), (sph_params_kind)kind);
    sph_params_info_init(&info);
    EXPECT_OK(sph_params_get_info((sph_params_kind)kind, &info));
    for (k = 0; k < info.field_count; ++k) {
      sph_param_field_info field;
      int c;
      sph_param_field_info_init(&field);
      EXPECT_OK(sph_params_get_field_info((sph_params_kind)kind, k, &field));
      for (c = 0; c < (field.type == SPH_PARAM_VEC3 ? 3 : 1); ++c) {
        const uint32_t at = field.offset + 4u * (uint32_t)c;
        const float expected = field.zero == SPH_PARAM_ZERO_IS_DEFAULT ? field.default_value[c] : 0.0f;
        float value;
        if (field.type == SPH_PARAM_UINT32 || field.type == SPH_PARAM_FLAGS) {
          uint32_t u;
          memcpy(&u, got.u.bytes + at, sizeof u);
          value = (float)u;
        } else {
          value = float_at(&got, at);
        }
        if (value != expected)
          fail_msg("%s.%s[%d]: read back %g, expected %g", info.name, field.name, c, value, expected);
      }
    }
  }
}

/* ---- every rule, with its message ------------------------------------------------------- */

typedef struct rule_case {
  sph_params_kind kind;
  size_t offset;
  float value;
  sph_result code;
  const char* message; /* the whole last error after "sph_world_set_physics_params: " */
} rule_case;

/* The shortest decimal that reads back as the same float, as the library writes values. */
static void shortest(float v, char* out, size_t size) {
  int digits;
  for (digits = 6; digits <= 9; ++digits) {
    snprintf(out, size, "%.*g", digits, (double)v);
    if (strtof(out, NULL) == v) return;
  }
}

static void expect_rule(world_fixture* f, const rule_case* c, const params_buffer* base) {
  params_buffer p = *base, before, after;
  char expected[256];
  before = read_back(world_of(f, c->kind), c->kind);
  memcpy(p.u.bytes + c->offset, &c->value, sizeof c->value);
  assert_int_equal(sph_world_set_physics_params(world_of(f, c->kind), c->kind, p.u.bytes), c->code);
  snprintf(expected, sizeof expected, "sph_world_set_physics_params: %s", c->message);
  if (strcmp(sph_get_last_error(), expected) != 0)
    fail_msg("message \"%s\", expected \"%s\"", sph_get_last_error(), expected);
  after = read_back(world_of(f, c->kind), c->kind);
  assert_memory_equal(before.u.bytes, after.u.bytes, sizeof before.u.bytes);
}

/* Setting `dp` on the fixture's DFSPH world fails with `status` and `message`, its parameters still
 * `before`. */
static void expect_dfsph_refused(world_fixture* f, const sph_dfsph_params* dp, sph_result status,
                                 const char* message, const sph_dfsph_params* before) {
  sph_dfsph_params after;
  assert_int_equal(sph_world_set_dfsph_params(f->dfsph, dp), status);
  assert_string_equal(sph_get_last_error(), message);
  sph_dfsph_params_init(&after);
  EXPECT_OK(sph_world_get_dfsph_params(f->dfsph, &after));
  assert_memory_equal(before, &after, sizeof after);
}

static void test_each_rule_fires_with_its_message(void** state) {
  world_fixture* f = (world_fixture*)*state;
  const uint32_t unknown_bits = 0x10u, one = 1u, four = 4u;
  float bits_as_float, one_as_float, four_as_float;
  const rule_case cases[] = {
      {SPH_PARAMS_WORLD, offsetof(sph_world_params, stiffness), -1.0f, SPH_ERROR_INVALID_ARGUMENT,
       "params->stiffness: must be > 0, got -1"},
      {SPH_PARAMS_WORLD, offsetof(sph_world_params, stiffness), INFINITY, SPH_ERROR_INVALID_ARGUMENT,
       "params->stiffness: is not finite"},
      {SPH_PARAMS_WORLD, offsetof(sph_world_params, viscosity), -0.5f, SPH_ERROR_INVALID_ARGUMENT,
       "params->viscosity: must be >= 0, got -0.5"},
      {SPH_PARAMS_WORLD, offsetof(sph_world_params, step_factor), 10.5f, SPH_ERROR_INVALID_ARGUMENT,
       "params->step_factor: must be in (0, 10], got 10.5"},
      {SPH_PARAMS_WORLD, offsetof(sph_world_params, step_factor), -0.4f, SPH_ERROR_INVALID_ARGUMENT,
       "params->step_factor: must be in (0, 10], got -0.4"},
      {SPH_PARAMS_WORLD, offsetof(sph_world_params, dt_min), -1e-6f, SPH_ERROR_INVALID_ARGUMENT,
       "params->dt_min: must be > 0, got -1e-06"},
      {SPH_PARAMS_WORLD, offsetof(sph_world_params, dt_max), 1e-7f, SPH_ERROR_INVALID_ARGUMENT,
       "params->dt_max: 1e-07 is smaller than params->dt_min 1e-06"},
      {SPH_PARAMS_WORLD, offsetof(sph_world_params, gravity.y), NAN, SPH_ERROR_INVALID_ARGUMENT,
       "params->gravity: has a non-finite component"},
      {SPH_PARAMS_WORLD, offsetof(sph_world_params, tension_ratio), 0.25f, SPH_ERROR_INVALID_ARGUMENT,
       "params->tension_ratio: must be in [0, 0.125], got 0.25"},
      {SPH_PARAMS_SURFACE_TENSION, offsetof(sph_surface_tension_params, coefficient), -1.0f,
       SPH_ERROR_INVALID_ARGUMENT, "params->coefficient: must be >= 0, got -1"},
      {SPH_PARAMS_SURFACE_TENSION, offsetof(sph_surface_tension_params, normal_threshold), -2.0f,
       SPH_ERROR_INVALID_ARGUMENT, "params->normal_threshold: must be >= 0, got -2"},
      {SPH_PARAMS_CLAVET_VISCOSITY, offsetof(sph_clavet_viscosity_params, linear), -1.0f,
       SPH_ERROR_INVALID_ARGUMENT, "params->linear: must be >= 0, got -1"},
      {SPH_PARAMS_CLAVET_VISCOSITY, offsetof(sph_clavet_viscosity_params, quadratic), NAN,
       SPH_ERROR_INVALID_ARGUMENT, "params->quadratic: is not finite"},
      {SPH_PARAMS_TAIT, offsetof(sph_tait_params, speed_of_sound), -1.0f, SPH_ERROR_INVALID_ARGUMENT,
       "params->speed_of_sound: must be > 0, got -1"},
      {SPH_PARAMS_SPRINGS, offsetof(sph_spring_params, stiffness), -1.0f, SPH_ERROR_INVALID_ARGUMENT,
       "params->stiffness: must be >= 0, got -1"},
      {SPH_PARAMS_SPRINGS, offsetof(sph_spring_params, link_radius), -0.01f, SPH_ERROR_INVALID_ARGUMENT,
       "params->link_radius: must be >= 0, got -0.01"},
      {SPH_PARAMS_SPRINGS, offsetof(sph_spring_params, yield_ratio), 1.5f, SPH_ERROR_INVALID_ARGUMENT,
       "params->yield_ratio: must be in [0, 1], got 1.5"},
      {SPH_PARAMS_SPRINGS, offsetof(sph_spring_params, plasticity), -3.0f, SPH_ERROR_INVALID_ARGUMENT,
       "params->plasticity: must be >= 0, got -3"},
      {SPH_PARAMS_SPRINGS, offsetof(sph_spring_params, damping), -0.25f, SPH_ERROR_INVALID_ARGUMENT,
       "params->damping: must be >= 0, got -0.25"},
      {SPH_PARAMS_DFSPH, offsetof(sph_dfsph_params, density_error), 1.5f, SPH_ERROR_INVALID_ARGUMENT,
       "params->density_error: must be in (0, 1], got 1.5"},
      {SPH_PARAMS_DFSPH, offsetof(sph_dfsph_params, divergence_error), -1.0f, SPH_ERROR_INVALID_ARGUMENT,
       "params->divergence_error: must be > 0, got -1"},
      {SPH_PARAMS_DFSPH, offsetof(sph_dfsph_params, density_error_max), 1.5f, SPH_ERROR_INVALID_ARGUMENT,
       "params->density_error_max: must be in (0, 1], got 1.5"},
      {SPH_PARAMS_DFSPH, offsetof(sph_dfsph_params, depth_step_factor), -0.5f, SPH_ERROR_INVALID_ARGUMENT,
       "params->depth_step_factor: must be in (0, 1], got -0.5"},
      {SPH_PARAMS_DFSPH, offsetof(sph_dfsph_params, divergence_error_per_step), 2.0f,
       SPH_ERROR_INVALID_ARGUMENT, "params->divergence_error_per_step: must be in (0, 1], got 2"},
      {SPH_PARAMS_DENSITY_DIFFUSION, offsetof(sph_density_diffusion_params, delta), 1.5f,
       SPH_ERROR_INVALID_ARGUMENT, "params->delta: must be in (0, 1], got 1.5"},
  };
  size_t i;
  for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    const params_buffer base = read_back(world_of(f, cases[i].kind), cases[i].kind);
    expect_rule(f, &cases[i], &base);
  }
  /* Words that are not floats: unknown step-limit bits and the reserved words. */
  memcpy(&bits_as_float, &unknown_bits, sizeof bits_as_float);
  memcpy(&one_as_float, &one, sizeof one_as_float);
  memcpy(&four_as_float, &four, sizeof four_as_float);
  {
    const rule_case words[] = {
        {SPH_PARAMS_WORLD, offsetof(sph_world_params, step_limits), bits_as_float, SPH_ERROR_UNSUPPORTED,
         "params->step_limits: unknown bits 0x10"},
        {SPH_PARAMS_WORLD, offsetof(sph_world_params, reserved0), one_as_float, SPH_ERROR_INVALID_ARGUMENT,
         "params->reserved0: is reserved and must be 0"},
        {SPH_PARAMS_SPRINGS, offsetof(sph_spring_params, reserved0), one_as_float, SPH_ERROR_INVALID_ARGUMENT,
         "params->reserved0: is reserved and must be 0"},
        /* none of SPH_DFSPH_JACOBI, SPH_DFSPH_CONJUGATE_GRADIENTS, SPH_DFSPH_CHEBYSHEV */
        {SPH_PARAMS_DFSPH, offsetof(sph_dfsph_params, linear_solver), four_as_float,
         SPH_ERROR_INVALID_ARGUMENT, "params->linear_solver: must be in [1, 3], got 4"},
    };
    for (i = 0; i < sizeof words / sizeof words[0]; ++i) {
      const params_buffer base = read_back(world_of(f, words[i].kind), words[i].kind);
      expect_rule(f, &words[i], &base);
    }
  }
  /* The cross-field rule against the world: the link radius at most h. */
  {
    sph_world_def def;
    char message[128], h[32];
    rule_case c = {SPH_PARAMS_SPRINGS, offsetof(sph_spring_params, link_radius), 0.05f,
                   SPH_ERROR_INVALID_ARGUMENT, message};
    const params_buffer base = read_back(f->world, SPH_PARAMS_SPRINGS);
    sph_world_def_init(&def);
    EXPECT_OK(sph_world_get_def(f->world, &def));
    shortest(def.kernel_radius, h, sizeof h);
    snprintf(message, sizeof message, "params->link_radius: 0.05 m is above the kernel radius %s", h);
    expect_rule(f, &c, &base);
  }
  /* The typed calls report through the same rules, under their own name. */
  {
    sph_tait_params tait;
    sph_tait_params_init(&tait);
    tait.speed_of_sound = -1.0f;
    assert_int_equal(sph_world_set_tait_params(f->world, &tait), SPH_ERROR_INVALID_ARGUMENT);
    assert_string_equal(sph_get_last_error(),
                        "sph_world_set_tait_params: params->speed_of_sound: must be > 0, got -1");
  }
  /* DFSPH's corrected gradient is the Jacobi solves' only: with the conjugate gradients refused, the
   * parameters unchanged; with Jacobi accepted. */
  {
    sph_dfsph_params before, dp;
    sph_dfsph_params_init(&before);
    EXPECT_OK(sph_world_get_dfsph_params(f->dfsph, &before));
    dp = before;
    dp.flags = SPH_DFSPH_CORRECTED_GRADIENT;
    dp.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
    expect_dfsph_refused(
        f, &dp, SPH_ERROR_INVALID_ARGUMENT,
        "sph_world_set_dfsph_params: params->flags: 2 (SPH_DFSPH_CORRECTED_GRADIENT) works with "
        "SPH_DFSPH_JACOBI only, not params->linear_solver 2",
        &before);
    dp.linear_solver = SPH_DFSPH_JACOBI;
    EXPECT_OK(sph_world_set_dfsph_params(f->dfsph, &dp));
    EXPECT_OK(sph_world_set_dfsph_params(f->dfsph, &before));
  }
  /* DFSPH's Chebyshev solve: both backends run it, not with the corrected gradient (refused, the
   * parameters unchanged). */
  {
    sph_dfsph_params before, dp, after;
    sph_dfsph_params_init(&before);
    EXPECT_OK(sph_world_get_dfsph_params(f->dfsph, &before));
    dp = before;
    dp.flags = SPH_DFSPH_CORRECTED_GRADIENT;
    dp.linear_solver = SPH_DFSPH_CHEBYSHEV;
    expect_dfsph_refused(
        f, &dp, SPH_ERROR_INVALID_ARGUMENT,
        "sph_world_set_dfsph_params: params->flags: 2 (SPH_DFSPH_CORRECTED_GRADIENT) works with "
        "SPH_DFSPH_JACOBI only, not params->linear_solver 3",
        &before);
    dp.flags = 0;
    EXPECT_OK(sph_world_set_dfsph_params(f->dfsph, &dp));
    sph_dfsph_params_init(&after);
    EXPECT_OK(sph_world_get_dfsph_params(f->dfsph, &after));
    assert_int_equal(after.linear_solver, SPH_DFSPH_CHEBYSHEV);
    EXPECT_OK(sph_world_set_dfsph_params(f->dfsph, &before));
  }
}

/* Every described bound is enforced at that very value: just past it fails naming the field,
 * the bound itself passes when inclusive; NaN fails everywhere. */
static void test_described_ranges_are_enforced(void** state) {
  world_fixture* f = (world_fixture*)*state;
  uint32_t kind, k;
  for (kind = 0; kind < SPH_PARAMS_KIND_COUNT; ++kind) {
    sph_params_info info;
    sph_params_info_init(&info);
    EXPECT_OK(sph_params_get_info((sph_params_kind)kind, &info));
    for (k = 0; k < info.field_count; ++k) {
      sph_param_field_info field;
      const params_buffer base = read_back(world_of(f, kind), (sph_params_kind)kind);
      params_buffer p;
      char name[64];
      float bad;
      sph_param_field_info_init(&field);
      EXPECT_OK(sph_params_get_field_info((sph_params_kind)kind, k, &field));
      if (field.type != SPH_PARAM_FLOAT) continue;
      snprintf(name, sizeof name, "params->%s:", field.name);
      p = base;
      bad = NAN;
      memcpy(p.u.bytes + field.offset, &bad, sizeof bad);
      EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, name,
                   sph_world_set_physics_params(world_of(f, kind), (sph_params_kind)kind, p.u.bytes));
      if (field.lower_bound != SPH_BOUND_NONE) {
        const float lower = (float)field.lower;
        p = base;
        bad = field.lower_bound == SPH_BOUND_EXCLUSIVE ? lower : nextafterf(lower, -INFINITY);
        /* A zero that takes a default is not a value to refuse. */
        if (!(bad == 0.0f && field.zero == SPH_PARAM_ZERO_IS_DEFAULT)) {
          memcpy(p.u.bytes + field.offset, &bad, sizeof bad);
          EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, name,
                       sph_world_set_physics_params(world_of(f, kind), (sph_params_kind)kind, p.u.bytes));
        }
        if (field.lower_bound == SPH_BOUND_INCLUSIVE) {
          p = base;
          memcpy(p.u.bytes + field.offset, &lower, sizeof lower);
          EXPECT_OK(sph_world_set_physics_params(world_of(f, kind), (sph_params_kind)kind, p.u.bytes));
        }
      }
      if (field.upper_bound != SPH_BOUND_NONE) {
        const float upper = (float)field.upper;
        p = base;
        bad = field.upper_bound == SPH_BOUND_EXCLUSIVE ? upper : nextafterf(upper, INFINITY);
        memcpy(p.u.bytes + field.offset, &bad, sizeof bad);
        EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, name,
                     sph_world_set_physics_params(world_of(f, kind), (sph_params_kind)kind, p.u.bytes));
        p = base;
        memcpy(p.u.bytes + field.offset, &upper, sizeof upper);
        EXPECT_OK(sph_world_set_physics_params(world_of(f, kind), (sph_params_kind)kind, p.u.bytes));
      }
      EXPECT_OK(sph_world_set_physics_params(world_of(f, kind), (sph_params_kind)kind, base.u.bytes));
    }
  }
}

/* ---- the descriptions ------------------------------------------------------------------- */

static void test_descriptions_match_the_header(void** state) {
  const struct {
    sph_params_kind kind;
    const char* name;
    size_t offset;
    sph_param_type type;
    sph_param_zero zero;
  } fields[] = {
      {SPH_PARAMS_WORLD, "max_substeps", offsetof(sph_world_params, max_substeps), SPH_PARAM_UINT32,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_WORLD, "gravity", offsetof(sph_world_params, gravity), SPH_PARAM_VEC3,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_WORLD, "stiffness", offsetof(sph_world_params, stiffness), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_WORLD, "viscosity", offsetof(sph_world_params, viscosity), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_WORLD, "step_factor", offsetof(sph_world_params, step_factor), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_WORLD, "dt_min", offsetof(sph_world_params, dt_min), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_WORLD, "dt_max", offsetof(sph_world_params, dt_max), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_WORLD, "step_limits", offsetof(sph_world_params, step_limits), SPH_PARAM_FLAGS,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_WORLD, "tension_ratio", offsetof(sph_world_params, tension_ratio), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_SURFACE_TENSION, "coefficient", offsetof(sph_surface_tension_params, coefficient),
       SPH_PARAM_FLOAT, SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_SURFACE_TENSION, "normal_threshold", offsetof(sph_surface_tension_params, normal_threshold),
       SPH_PARAM_FLOAT, SPH_PARAM_ZERO_IS_DERIVED},
      {SPH_PARAMS_CLAVET_VISCOSITY, "linear", offsetof(sph_clavet_viscosity_params, linear), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_CLAVET_VISCOSITY, "quadratic", offsetof(sph_clavet_viscosity_params, quadratic),
       SPH_PARAM_FLOAT, SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_TAIT, "speed_of_sound", offsetof(sph_tait_params, speed_of_sound), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_SPRINGS, "stiffness", offsetof(sph_spring_params, stiffness), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_SPRINGS, "link_radius", offsetof(sph_spring_params, link_radius), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DERIVED},
      {SPH_PARAMS_SPRINGS, "yield_ratio", offsetof(sph_spring_params, yield_ratio), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_SPRINGS, "plasticity", offsetof(sph_spring_params, plasticity), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_SPRINGS, "damping", offsetof(sph_spring_params, damping), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_DFSPH, "density_error", offsetof(sph_dfsph_params, density_error), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_DFSPH, "divergence_error", offsetof(sph_dfsph_params, divergence_error), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_DFSPH, "max_iterations", offsetof(sph_dfsph_params, max_iterations), SPH_PARAM_UINT32,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_DFSPH, "max_divergence_iterations", offsetof(sph_dfsph_params, max_divergence_iterations),
       SPH_PARAM_UINT32, SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_DFSPH, "flags", offsetof(sph_dfsph_params, flags), SPH_PARAM_FLAGS,
       SPH_PARAM_ZERO_IS_VALUE},
      {SPH_PARAMS_DFSPH, "linear_solver", offsetof(sph_dfsph_params, linear_solver), SPH_PARAM_UINT32,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_DFSPH, "density_error_max", offsetof(sph_dfsph_params, density_error_max), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_DFSPH, "depth_step_factor", offsetof(sph_dfsph_params, depth_step_factor), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_DFSPH, "divergence_error_per_step", offsetof(sph_dfsph_params, divergence_error_per_step),
       SPH_PARAM_FLOAT, SPH_PARAM_ZERO_IS_DEFAULT},
      {SPH_PARAMS_DENSITY_DIFFUSION, "delta", offsetof(sph_density_diffusion_params, delta), SPH_PARAM_FLOAT,
       SPH_PARAM_ZERO_IS_DEFAULT},
  };
  const struct {
    const char* name;
    const char* type_name;
    uint32_t size, fields;
  } kinds[SPH_PARAMS_KIND_COUNT] = {
      {"world", "sph_world_params", sizeof(sph_world_params), 9},
      {"surface_tension", "sph_surface_tension_params", sizeof(sph_surface_tension_params), 2},
      {"clavet", "sph_clavet_viscosity_params", sizeof(sph_clavet_viscosity_params), 2},
      {"tait", "sph_tait_params", sizeof(sph_tait_params), 1},
      {"springs", "sph_spring_params", sizeof(sph_spring_params), 5},
      {"dfsph", "sph_dfsph_params", sizeof(sph_dfsph_params), 9},
      {"density_diffusion", "sph_density_diffusion_params", sizeof(sph_density_diffusion_params), 1},
  };
  size_t i, seen[SPH_PARAMS_KIND_COUNT] = {0};
  sph_params_info info;
  sph_param_field_info field;
  (void)state;
  for (i = 0; i < SPH_PARAMS_KIND_COUNT; ++i) {
    sph_params_info_init(&info);
    EXPECT_OK(sph_params_get_info((sph_params_kind)i, &info));
    assert_string_equal(info.name, kinds[i].name);
    assert_string_equal(info.type_name, kinds[i].type_name);
    assert_int_equal(info.params_size, kinds[i].size);
    assert_int_equal(info.field_count, kinds[i].fields);
  }
  for (i = 0; i < sizeof fields / sizeof fields[0]; ++i) {
    const uint32_t k = (uint32_t)seen[fields[i].kind]++;
    sph_param_field_info_init(&field);
    EXPECT_OK(sph_params_get_field_info(fields[i].kind, k, &field));
    assert_string_equal(field.name, fields[i].name);
    assert_int_equal(field.offset, fields[i].offset);
    assert_int_equal(field.type, fields[i].type);
    assert_int_equal(field.zero, fields[i].zero);
  }
  /* Defaults and ranges of a few, as sph_c.h writes them. */
  sph_param_field_info_init(&field);
  EXPECT_OK(sph_params_get_field_info(SPH_PARAMS_WORLD, 1, &field));
  assert_true(field.default_value[0] == 0.0f && field.default_value[1] == -9.81f &&
              field.default_value[2] == 0.0f);
  assert_string_equal(field.unit, "m/s^2");
  EXPECT_OK(sph_params_get_field_info(SPH_PARAMS_WORLD, 4, &field));
  assert_true(field.lower == 0.0 && field.lower_bound == SPH_BOUND_EXCLUSIVE && field.upper == 10.0 &&
              field.upper_bound == SPH_BOUND_INCLUSIVE && field.default_value[0] == 0.4f);
  EXPECT_OK(sph_params_get_field_info(SPH_PARAMS_WORLD, 7, &field));
  assert_true(field.upper == (double)(SPH_STEP_LIMIT_ACOUSTIC | SPH_STEP_LIMIT_FORCE));
  EXPECT_OK(sph_params_get_field_info(SPH_PARAMS_WORLD, 8, &field));
  assert_true(field.lower == 0.0 && field.lower_bound == SPH_BOUND_INCLUSIVE && field.upper == 0.125 &&
              field.upper_bound == SPH_BOUND_INCLUSIVE && field.default_value[0] == 0.0f);
  assert_string_equal(field.unit, "");
  EXPECT_OK(sph_params_get_field_info(SPH_PARAMS_SPRINGS, 2, &field));
  assert_true(field.lower == 0.0 && field.upper == 1.0 && field.default_value[0] == 0.1f);
  /* Bad queries. */
  EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "kind", sph_params_get_info((sph_params_kind)99, &info));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "index", sph_params_get_field_info(SPH_PARAMS_TAIT, 1, &field));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out", sph_params_get_info(SPH_PARAMS_TAIT, NULL));
}

static void test_methods_are_listed_with_their_switches(void** state) {
  const struct {
    const char* name;
    sph_method_switch by;
    uint32_t value, has_params;
    sph_params_kind params;
  } expected[] = {
      {"ideal_gas", SPH_METHOD_SWITCH_EQUATION_OF_STATE, SPH_EOS_IDEAL_GAS, 1, SPH_PARAMS_WORLD},
      {"tait", SPH_METHOD_SWITCH_EQUATION_OF_STATE, SPH_EOS_TAIT, 1, SPH_PARAMS_TAIT},
      {"mueller", SPH_METHOD_SWITCH_VISCOSITY, SPH_VISCOSITY_MUELLER, 1, SPH_PARAMS_WORLD},
      {"clavet", SPH_METHOD_SWITCH_VISCOSITY, SPH_VISCOSITY_CLAVET, 1, SPH_PARAMS_CLAVET_VISCOSITY},
      {"surface_tension", SPH_METHOD_SWITCH_FEATURE, SPH_FEATURE_SURFACE_TENSION, 1,
       SPH_PARAMS_SURFACE_TENSION},
      {"normalized_density", SPH_METHOD_SWITCH_FEATURE, SPH_FEATURE_NORMALIZED_DENSITY, 0, SPH_PARAMS_WORLD},
      {"springs", SPH_METHOD_SWITCH_FEATURE, SPH_FEATURE_SPRINGS, 1, SPH_PARAMS_SPRINGS},
      {"wcsph", SPH_METHOD_SWITCH_SOLVER, SPH_SOLVER_WCSPH, 1, SPH_PARAMS_WORLD}, /* tension_ratio */
      {"dfsph", SPH_METHOD_SWITCH_SOLVER, SPH_SOLVER_DFSPH, 1, SPH_PARAMS_DFSPH},
      {"boundary_density", SPH_METHOD_SWITCH_FEATURE, SPH_FEATURE_BOUNDARY_DENSITY, 0, SPH_PARAMS_WORLD},
      {"collider_loads", SPH_METHOD_SWITCH_FEATURE, SPH_FEATURE_COLLIDER_LOADS, 0, SPH_PARAMS_WORLD},
      {"density_diffusion", SPH_METHOD_SWITCH_FEATURE, SPH_FEATURE_DENSITY_DIFFUSION, 1,
       SPH_PARAMS_DENSITY_DIFFUSION},
  };
  const uint32_t n = (uint32_t)(sizeof expected / sizeof expected[0]);
  sph_physics_method_info info;
  uint32_t i;
  (void)state;
  for (i = 0; i < n; ++i) {
    sph_physics_method_info_init(&info);
    EXPECT_OK(sph_get_physics_method_info(i, &info));
    assert_int_equal(info.method_count, n);
    assert_string_equal(info.name, expected[i].name);
    assert_int_equal(info.switch_by, expected[i].by);
    assert_int_equal(info.value, expected[i].value);
    assert_int_equal(info.has_params, expected[i].has_params);
    if (info.has_params) assert_int_equal(info.params_kind, expected[i].params);
  }
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "index", sph_get_physics_method_info(n, &info));
}

/* The generic calls are the typed ones; a method the world does not run refuses both. */
static void test_generic_calls_are_the_typed_calls(void** state) {
  world_fixture* f = (world_fixture*)*state;
  sph_spring_params typed;
  params_buffer generic = zeroed(SPH_PARAMS_SPRINGS);
  sph_world* plain = NULL;
  sph_world_def def;
  sph_spring_params_init(&typed);
  typed.stiffness = 321.0f;
  typed.damping = 2.0f;
  EXPECT_OK(sph_world_set_physics_params(f->world, SPH_PARAMS_SPRINGS, &typed));
  EXPECT_OK(sph_world_get_spring_params(f->world, (sph_spring_params*)(void*)generic.u.bytes));
  assert_memory_equal(generic.u.bytes, &typed, sizeof typed);
  EXPECT_ERROR(SPH_ERROR_UNSUPPORTED, "kind",
               sph_world_set_physics_params(f->world, (sph_params_kind)7, &typed));
  sph_world_def_init(&def);
  def.capacity = 8;
  EXPECT_OK(sph_world_create(f->context, &def, &plain));
  EXPECT_ERROR(SPH_ERROR_FEATURE_DISABLED, "SPH_FEATURE_SPRINGS",
               sph_world_set_physics_params(plain, SPH_PARAMS_SPRINGS, &typed));
  EXPECT_ERROR(SPH_ERROR_FEATURE_DISABLED, "SPH_EOS_TAIT",
               sph_world_get_physics_params(plain, SPH_PARAMS_TAIT, generic.u.bytes));
  EXPECT_OK(sph_world_destroy(plain));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_zeroed_structs_take_the_documented_values),
      cmocka_unit_test(test_zero_rule_matches_the_descriptions),
      cmocka_unit_test(test_each_rule_fires_with_its_message),
      cmocka_unit_test(test_described_ranges_are_enforced),
      cmocka_unit_test(test_generic_calls_are_the_typed_calls),
  };
  const struct CMUnitTest static_tests[] = {
      cmocka_unit_test(test_descriptions_match_the_header),
      cmocka_unit_test(test_methods_are_listed_with_their_switches),
  };
  return cmocka_run_group_tests(tests, open_all_options, close_world) |
         cmocka_run_group_tests(static_tests, NULL, NULL);
}
