// SPDX-License-Identifier: MIT
/* Worlds and their parameters through the C API: every bad def, handle and parameter returns
 * its code, names the argument, writes no output and leaves the world as it was. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "capi_test.h"

typedef struct {
  sph_world_def def;
  unsigned char extra[16];
} grown_world_def;

typedef struct {
  sph_world_params params;
  unsigned char extra[16];
} grown_world_params;

typedef struct {
  size_t offset;
  const char* name;
} float_field;

static uint32_t live_objects(void) {
  uint32_t n = 0xdeadbeefu;
  assert_int_equal(sph_get_live_object_count(&n), SPH_OK);
  return n;
}

static sph_context* make_context(void) {
  sph_context* context = NULL;
  EXPECT_OK(sph_test_context_create(&context));
  return context;
}

static void small_world_def(sph_world_def* def) {
  sph_world_def_init(def);
  def->capacity = 64;
}

/* sph_world_create must fail with (code, name), leave *out alone and create nothing. */
static void expect_create_fails_at(int line, sph_context* context, const sph_world_def* def, sph_result code,
                                   const char* name) {
  sph_world* const sentinel = (sph_world*)(uintptr_t)0x5678;
  sph_world* out = sentinel;
  const uint32_t before = live_objects();
  EXPECT_ERROR_AT(line, code, name, sph_world_create(context, def, &out));
  assert_ptr_equal(out, sentinel);
  assert_int_equal(live_objects(), before);
}
#define EXPECT_CREATE_FAILS(...) expect_create_fails_at(__LINE__, __VA_ARGS__)

static void expect_create_ok(sph_context* context, const sph_world_def* def) {
  sph_world* world = NULL;
  EXPECT_OK(sph_world_create(context, def, &world));
  assert_non_null(world);
  EXPECT_OK(sph_world_destroy(world));
}

/* ---- defs ------------------------------------------------------------------------------------ */

static void test_def_init(void** state) {
  sph_world_def def;
  grown_world_def grown;
  (void)state;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "def", sph_world_def_init_sized(NULL, sizeof def));
  memset(&def, 0xab, sizeof def);
  /* Below the struct's first released size (0.1.0: 40 bytes, before the solver): refused. */
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "def", sph_world_def_init_sized(&def, 40 - 1));
  assert_int_equal(def.struct_size, 0xababababu);
  /* A 0.1.0 caller's size: its prefix is filled, nothing past it. */
  EXPECT_OK(sph_world_def_init_sized(&def, 40));
  assert_int_equal(def.struct_size, 40);
  assert_int_equal(def.capacity, 65536);
  assert_int_equal((uint32_t)def.solver, 0xababababu);
  EXPECT_OK(sph_world_def_init(&def));
  assert_int_equal(def.solver, SPH_SOLVER_WCSPH);
  EXPECT_OK(sph_world_def_init(&def));
  assert_int_equal(def.struct_size, sizeof def);
  assert_int_equal(def.header_version, SPH_VERSION);
  assert_int_equal(def.capacity, 65536);
  assert_int_equal(def.features, SPH_FEATURE_NONE);
  assert_int_equal(def.integrator, SPH_INTEGRATOR_SYMPLECTIC_EULER);
  assert_int_equal(def.viscosity_method, SPH_VISCOSITY_MUELLER);
  assert_true(def.particle_spacing == 0.02f);
  assert_true(def.kernel_radius == 0.0f);
  assert_true(def.rest_density == 1000.0f);
  assert_int_equal(def.equation_of_state, SPH_EOS_IDEAL_GAS);
  memset(&grown, 0xab, sizeof grown);
  EXPECT_OK(sph_world_def_init_sized(&grown.def, sizeof grown));
  assert_int_equal(grown.def.struct_size, sizeof grown);
  for (size_t i = 0; i < sizeof grown.extra; ++i) assert_int_equal(grown.extra[i], 0);
}

static void test_create_bad_context(void** state) {
  sph_world_def def;
  sph_context* stale = make_context();
  sph_context* context = NULL;
  sph_world* world = NULL;
  int foreign = 0;
  (void)state;
  small_world_def(&def);
  EXPECT_OK(sph_context_destroy(stale));
  EXPECT_CREATE_FAILS(stale, &def, SPH_ERROR_INVALID_HANDLE, "context");
  EXPECT_CREATE_FAILS(NULL, &def, SPH_ERROR_INVALID_HANDLE, "context");
  EXPECT_CREATE_FAILS((sph_context*)(void*)&foreign, &def, SPH_ERROR_INVALID_HANDLE, "context");
  context = make_context();
  EXPECT_OK(sph_world_create(context, &def, &world));
  EXPECT_CREATE_FAILS((sph_context*)(void*)world, &def, SPH_ERROR_INVALID_HANDLE, "context");
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_create_null_arguments(void** state) {
  sph_context* context = make_context();
  sph_world_def def;
  (void)state;
  small_world_def(&def);
  EXPECT_CREATE_FAILS(context, NULL, SPH_ERROR_INVALID_ARGUMENT, "def");
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out", sph_world_create(context, &def, NULL));
  assert_int_equal(live_objects(), 1);
  EXPECT_OK(sph_context_destroy(context));
}

static void test_create_struct_size(void** state) {
  sph_context* context = make_context();
  grown_world_def grown;
  (void)state;
  memset(&grown, 0, sizeof grown);
  small_world_def(&grown.def);
  grown.def.struct_size = 40 - 4;
  EXPECT_CREATE_FAILS(context, &grown.def, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  /* A 0.1.0 caller's def, without the solver: accepted, the solver reads as zero (WCSPH),
     whatever the bytes after its struct hold. */
  grown.def.struct_size = 40;
  grown.def.solver = (sph_solver)77;
  expect_create_ok(context, &grown.def);
  grown.def.solver = SPH_SOLVER_WCSPH;
  grown.def.struct_size = 0;
  EXPECT_CREATE_FAILS(context, &grown.def, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  grown.def.struct_size = sizeof grown;
  grown.extra[15] = 0x80;
  EXPECT_CREATE_FAILS(context, &grown.def, SPH_ERROR_UNSUPPORTED, "struct_size");
  grown.extra[15] = 0;
  expect_create_ok(context, &grown.def);
  EXPECT_OK(sph_context_destroy(context));
}

static void test_create_header_version(void** state) {
  sph_context* context = make_context();
  sph_world_def def;
  (void)state;
  small_world_def(&def);
  def.header_version = SPH_MAKE_VERSION(SPH_VERSION_MAJOR + 1, SPH_VERSION_MINOR, 0);
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_VERSION_MISMATCH, "header_version");
  def.header_version = SPH_MAKE_VERSION(SPH_VERSION_MAJOR, SPH_VERSION_MINOR + 1, 0);
  expect_create_ok(context, &def);
  EXPECT_OK(sph_context_destroy(context));
}

static void test_create_capacity(void** state) {
  sph_context* context = make_context();
  sph_world_def def;
  (void)state;
  small_world_def(&def);
  def.capacity = (1u << 30) + 1u; /* the documented limit is 2^30 */
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "capacity");
  def.capacity = 0xffffffffu;
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "capacity");
  def.capacity = 1;
  expect_create_ok(context, &def);
  EXPECT_OK(sph_context_destroy(context));
}

static void test_create_unknown_enums_and_bits(void** state) {
  const uint32_t features[] = {0x80u, 0x100u, 0x200u, 0x80000000u, 0xffffffffu};
  const int32_t integrators[] = {2, 3, 1000, 0x7fffffff, -1};
  sph_context* context = make_context();
  sph_world_def def;
  (void)state;
  for (size_t i = 0; i < sizeof features / sizeof features[0]; ++i) {
    small_world_def(&def);
    def.features = features[i];
    EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_UNSUPPORTED, "features");
  }
  for (size_t i = 0; i < sizeof integrators / sizeof integrators[0]; ++i) {
    small_world_def(&def);
    def.integrator = (sph_integrator)integrators[i];
    EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_UNSUPPORTED, "integrator");
  }
  small_world_def(&def);
  def.integrator = SPH_INTEGRATOR_RK4;
  expect_create_ok(context, &def);
  EXPECT_OK(sph_context_destroy(context));
}

static void test_create_reserved(void** state) {
  sph_context* context = make_context();
  sph_world_def def;
  (void)state;
  small_world_def(&def);
  def.viscosity_method = (sph_viscosity_method)7;
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_UNSUPPORTED, "viscosity_method");
  small_world_def(&def);
  def.equation_of_state = (sph_equation_of_state)9;
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_UNSUPPORTED, "equation_of_state");
  EXPECT_OK(sph_context_destroy(context));
}

static void test_create_non_finite(void** state) {
  const float_field fields[] = {
      {offsetof(sph_world_def, particle_spacing), "particle_spacing"},
      {offsetof(sph_world_def, kernel_radius), "kernel_radius"},
      {offsetof(sph_world_def, rest_density), "rest_density"},
  };
  sph_context* context = make_context();
  sph_world_def def;
  (void)state;
  for (size_t f = 0; f < sizeof fields / sizeof fields[0]; ++f)
    for (int v = 0; v < CAPI_NON_FINITE_COUNT; ++v) {
      small_world_def(&def);
      capi_set_float(&def, fields[f].offset, capi_non_finite(v));
      EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, fields[f].name);
    }
  EXPECT_OK(sph_context_destroy(context));
}

static void test_create_out_of_range(void** state) {
  /* (0 is the default: test_capi_zero_defaults.c) */
  const float spacings[] = {-0.02f, -1e-30f, 1e-30f /* coefficients overflow float */};
  const float densities[] = {-1000.0f, -1e-30f};
  sph_context* context = make_context();
  sph_world_def def;
  (void)state;
  for (size_t i = 0; i < sizeof spacings / sizeof spacings[0]; ++i) {
    small_world_def(&def);
    def.particle_spacing = spacings[i];
    EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "particle_spacing");
  }
  for (size_t i = 0; i < sizeof densities / sizeof densities[0]; ++i) {
    small_world_def(&def);
    def.rest_density = densities[i];
    EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "rest_density");
  }
  /* h < spacing, negative h, and h above the documented 5 x spacing. */
  small_world_def(&def);
  def.kernel_radius = 0.5f * def.particle_spacing;
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "kernel_radius");
  def.kernel_radius = nextafterf(def.particle_spacing, 0.0f);
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "kernel_radius");
  def.kernel_radius = -0.036f;
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "kernel_radius");
  def.kernel_radius = 5.5f * def.particle_spacing;
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "kernel_radius");
  /* h = spacing, and a float step above it, are refused: the lattice's nearest neighbours would
   * lie on the kernel's edge, where the lattice scale divides by (nearly) zero (a filled block's
   * densities were non-finite at its first step; a technical artist's review). At 1.001 spacings
   * a block reads rho0. */
  def.kernel_radius = def.particle_spacing;
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "kernel_radius");
  def.kernel_radius = nextafterf(def.particle_spacing, 1.0f);
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "kernel_radius");
  def.kernel_radius = def.particle_spacing * 1.001f;
  expect_create_ok(context, &def);
  /* 5 x spacing as written is allowed: 0.1f for 0.02f lies one float step above 5.0f * 0.02f. */
  def.particle_spacing = 0.02f;
  def.kernel_radius = 0.1f;
  expect_create_ok(context, &def);
  def.kernel_radius = 0.1001f;
  EXPECT_CREATE_FAILS(context, &def, SPH_ERROR_INVALID_ARGUMENT, "kernel_radius");
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- destroy, get_def, particle mass --------------------------------------------------------- */

static void test_destroy(void** state) {
  sph_context* context = make_context();
  sph_world_def def;
  sph_world* world = NULL;
  int foreign = 0;
  (void)state;
  small_world_def(&def);
  EXPECT_OK(sph_world_destroy(NULL));
  EXPECT_OK(sph_world_create(context, &def, &world));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_destroy(world));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_destroy((sph_world*)(void*)&foreign));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_destroy((sph_world*)(void*)context));
  assert_int_equal(live_objects(), 1);
  EXPECT_OK(sph_context_destroy(context));
}

static void test_get_def(void** state) {
  sph_context* context = make_context();
  sph_world_def def, out;
  sph_world* world = NULL;
  grown_world_def grown;
  int foreign = 0;
  (void)state;
  small_world_def(&def);
  def.particle_spacing = 0.05f;
  def.rest_density = 850.0f;
  def.integrator = SPH_INTEGRATOR_RK4;
  EXPECT_OK(sph_world_create(context, &def, &world));
  sph_world_def_init(&out);
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_def(NULL, &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_def((sph_world*)(void*)&foreign, &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out_def", sph_world_get_def(world, NULL));
  out.struct_size = 4;
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "struct_size", sph_world_get_def(world, &out));
  assert_int_equal(out.struct_size, 4);

  /* The resolved def: kernel_radius 0 became 1.8 x spacing, everything else as given. */
  sph_world_def_init(&out);
  EXPECT_OK(sph_world_get_def(world, &out));
  assert_int_equal(out.struct_size, sizeof out);
  assert_int_equal(out.header_version, SPH_VERSION);
  assert_int_equal(out.capacity, 64);
  assert_int_equal(out.features, SPH_FEATURE_NONE);
  assert_int_equal(out.integrator, SPH_INTEGRATOR_RK4);
  assert_true(out.particle_spacing == 0.05f);
  assert_true(out.rest_density == 850.0f);
  /* 1e-6 relative: the library may form 1.8 x spacing in float or double. */
  assert_true(fabs(out.kernel_radius - 1.8 * 0.05) <= 1e-6 * 0.09);

  /* A shorter struct_size (an older caller): only that prefix is written. */
  memset(&out, 0xab, sizeof out);
  out.struct_size = (uint32_t)offsetof(sph_world_def, particle_spacing);
  EXPECT_OK(sph_world_get_def(world, &out));
  assert_int_equal(out.struct_size, offsetof(sph_world_def, particle_spacing));
  assert_int_equal(out.capacity, 64);
  assert_int_equal(out.viscosity_method, SPH_VISCOSITY_MUELLER);
  {
    uint32_t bits;
    memcpy(&bits, &out.particle_spacing, sizeof bits);
    assert_int_equal(bits, 0xababababu);
  }
  /* A longer one (a newer caller): the unknown tail is left alone. */
  memset(&grown, 0xcd, sizeof grown);
  grown.def.struct_size = sizeof grown;
  EXPECT_OK(sph_world_get_def(world, &grown.def));
  assert_true(grown.def.particle_spacing == 0.05f);
  for (size_t i = 0; i < sizeof grown.extra; ++i) assert_int_equal(grown.extra[i], 0xcd);
  EXPECT_OK(sph_world_destroy(world));

  /* An explicit kernel radius is kept as given. */
  small_world_def(&def);
  def.kernel_radius = 0.05f;
  EXPECT_OK(sph_world_create(context, &def, &world));
  sph_world_def_init(&out);
  EXPECT_OK(sph_world_get_def(world, &out));
  assert_true(out.kernel_radius == 0.05f);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

static void test_particle_mass(void** state) {
  sph_context* context = make_context();
  sph_world_def def;
  sph_world* world = NULL;
  float mass = -1.0f, heavier = -1.0f;
  int foreign = 0;
  (void)state;
  small_world_def(&def);
  EXPECT_OK(sph_world_create(context, &def, &world));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_particle_mass(NULL, &mass));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world",
               sph_world_get_particle_mass((sph_world*)(void*)&foreign, &mass));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out_mass", sph_world_get_particle_mass(world, NULL));
  assert_true(mass == -1.0f);
  EXPECT_OK(sph_world_get_particle_mass(world, &mass));
  EXPECT_OK(sph_world_destroy(world));
  /* An FCC cell of volume a^3 (a = spacing sqrt 2) holds 4 particles: rho0 s^3 / sqrt 2 each.
   * The library sums W_poly6 over the lattice instead of integrating, which differs by about
   * 1 % at h = 1.8 s; 5 % catches a wrong formula (a factor sqrt 2 or 4 is far outside). */
  {
    const double expected = 1000.0 * 0.02 * 0.02 * 0.02 / sqrt(2.0);
    assert_true(fabs(mass - expected) <= 0.05 * expected);
  }
  /* Mass is linear in rest density. */
  def.rest_density = 2000.0f;
  EXPECT_OK(sph_world_create(context, &def, &world));
  EXPECT_OK(sph_world_get_particle_mass(world, &heavier));
  assert_true(fabs(heavier - 2.0 * mass) <= 1e-6 * mass);
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_context_destroy(context));
}

/* ---- runtime parameters ---------------------------------------------------------------------- */

static void test_params_init(void** state) {
  sph_world_params p;
  grown_world_params grown;
  (void)state;
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "params", sph_world_params_init_sized(NULL, sizeof p));
  memset(&p, 0xab, sizeof p);
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "params", sph_world_params_init_sized(&p, 8));
  assert_int_equal(p.struct_size, 0xababababu);
  EXPECT_OK(sph_world_params_init(&p));
  assert_int_equal(p.struct_size, sizeof p);
  assert_int_equal(p.max_substeps, 10000);
  assert_true(p.gravity.x == 0.0f && p.gravity.y == -9.81f && p.gravity.z == 0.0f);
  assert_true(p.stiffness == 100.0f);
  assert_true(p.viscosity == 1.0f);
  assert_true(p.step_factor == 0.4f);
  assert_true(p.dt_min == 1e-6f);
  assert_true(p.dt_max == 1e-3f);
  memset(&grown, 0xab, sizeof grown);
  EXPECT_OK(sph_world_params_init_sized(&grown.params, sizeof grown));
  for (size_t i = 0; i < sizeof grown.extra; ++i) assert_int_equal(grown.extra[i], 0);
}

/* set_params with one bad field: (code, name), and the world unchanged. */
static void expect_set_fails_at(int line, const capi_fixture* f, const sph_world_params* p, sph_result code,
                                const char* name) {
  static capi_snapshot before;
  capi_snapshot_take(f->world, &before);
  EXPECT_ERROR_AT(line, code, name, sph_world_set_params(f->world, p));
  EXPECT_UNCHANGED_AT(line, f->world, &before);
}
#define EXPECT_SET_FAILS(...) expect_set_fails_at(__LINE__, __VA_ARGS__)

static void test_set_params_handles_and_sizes(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  grown_world_params grown;
  sph_world_params back;
  int foreign = 0;
  memset(&grown, 0, sizeof grown);
  grown.params = f->params;
  grown.params.viscosity = 1.0f;
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_set_params(NULL, &grown.params));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world",
               sph_world_set_params((sph_world*)(void*)&foreign, &grown.params));
  EXPECT_SET_FAILS(f, NULL, SPH_ERROR_INVALID_ARGUMENT, "params");
  grown.params.struct_size = 48 - 4; /* below 0.1.0's struct (48 bytes; 48 itself is read) */
  EXPECT_SET_FAILS(f, &grown.params, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  grown.params.struct_size = 0;
  EXPECT_SET_FAILS(f, &grown.params, SPH_ERROR_VERSION_MISMATCH, "struct_size");
  grown.params.struct_size = sizeof grown;
  grown.extra[0] = 1;
  EXPECT_SET_FAILS(f, &grown.params, SPH_ERROR_UNSUPPORTED, "struct_size");
  /* Larger with a zero tail: accepted and applied. */
  grown.extra[0] = 0;
  EXPECT_OK(sph_world_set_params(f->world, &grown.params));
  sph_world_params_init(&back);
  EXPECT_OK(sph_world_get_params(f->world, &back));
  assert_true(back.viscosity == 1.0f);
  EXPECT_OK(sph_world_set_params(f->world, &f->params));
}

static void test_set_params_non_finite(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  const float_field fields[] = {
      {offsetof(sph_world_params, gravity.x), "gravity"},
      {offsetof(sph_world_params, gravity.y), "gravity"},
      {offsetof(sph_world_params, gravity.z), "gravity"},
      {offsetof(sph_world_params, stiffness), "stiffness"},
      {offsetof(sph_world_params, viscosity), "viscosity"},
      {offsetof(sph_world_params, step_factor), "step_factor"},
      {offsetof(sph_world_params, dt_min), "dt_min"},
      {offsetof(sph_world_params, dt_max), "dt_max"},
  };
  sph_world_params p;
  for (size_t i = 0; i < sizeof fields / sizeof fields[0]; ++i)
    for (int v = 0; v < CAPI_NON_FINITE_COUNT; ++v) {
      p = f->params;
      capi_set_float(&p, fields[i].offset, capi_non_finite(v));
      EXPECT_SET_FAILS(f, &p, SPH_ERROR_INVALID_ARGUMENT, fields[i].name);
    }
}

static void test_set_params_out_of_range(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  const struct {
    size_t offset;
    float value;
    const char* name;
  } cases[] = {
      {offsetof(sph_world_params, stiffness), -100.0f, "stiffness"},
      {offsetof(sph_world_params, viscosity), -0.001f, "viscosity"},
      {offsetof(sph_world_params, step_factor), -0.4f, "step_factor"},
      {offsetof(sph_world_params, step_factor), 10.5f, "step_factor"},
      {offsetof(sph_world_params, dt_min), -1e-6f, "dt_min"},
      {offsetof(sph_world_params, dt_max), -1e-3f, "dt_max"},
      {offsetof(sph_world_params, dt_max), 1e-6f /* < the fixture's dt_min 2e-6 */, "dt_max"},
  };
  sph_world_params p;
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    p = f->params;
    capi_set_float(&p, cases[i].offset, cases[i].value);
    EXPECT_SET_FAILS(f, &p, SPH_ERROR_INVALID_ARGUMENT, cases[i].name);
  }
  p = f->params;
  p.dt_min = 0.01f; /* above the fixture's dt_max */
  EXPECT_SET_FAILS(f, &p, SPH_ERROR_INVALID_ARGUMENT, "dt_max");
  p = f->params;
  p.dt_max = 0.0f; /* the default 1e-3, below this dt_min */
  p.dt_min = 0.01f;
  EXPECT_SET_FAILS(f, &p, SPH_ERROR_INVALID_ARGUMENT, "dt_max");
  /* A 0 in stiffness, step_factor, dt_min, dt_max and max_substeps takes the default
   * (tests/capi/test_capi_params.c checks every field of every params struct). */
  /* The edges of each range are accepted. */
  p = f->params;
  p.viscosity = 0.0f;
  p.step_factor = 10.0f;
  p.dt_max = p.dt_min;
  p.max_substeps = 1;
  EXPECT_OK(sph_world_set_params(f->world, &p));
  EXPECT_OK(sph_world_set_params(f->world, &f->params));
}

static void test_get_params(void** state) {
  const capi_fixture* f = (const capi_fixture*)*state;
  sph_world_params out;
  grown_world_params grown;
  int foreign = 0;
  sph_world_params_init(&out);
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_params(NULL, &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "world", sph_world_get_params((sph_world*)(void*)&foreign, &out));
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "out", sph_world_get_params(f->world, NULL));
  out.struct_size = 0;
  EXPECT_ERROR(SPH_ERROR_VERSION_MISMATCH, "struct_size", sph_world_get_params(f->world, &out));
  /* Round trip of what the fixture set. */
  sph_world_params_init(&out);
  EXPECT_OK(sph_world_get_params(f->world, &out));
  assert_memory_equal(&out, &f->params, sizeof out);
  /* Shorter and longer struct_size: only the known prefix is written. */
  memset(&out, 0xab, sizeof out);
  out.struct_size = (uint32_t)offsetof(sph_world_params, stiffness);
  EXPECT_OK(sph_world_get_params(f->world, &out));
  assert_int_equal(out.max_substeps, 777);
  assert_true(out.gravity.y == -9.0f);
  {
    uint32_t bits;
    memcpy(&bits, &out.stiffness, sizeof bits);
    assert_int_equal(bits, 0xababababu);
  }
  memset(&grown, 0xcd, sizeof grown);
  grown.params.struct_size = sizeof grown;
  EXPECT_OK(sph_world_get_params(f->world, &grown.params));
  assert_true(grown.params.dt_max == f->params.dt_max);
  for (size_t i = 0; i < sizeof grown.extra; ++i) assert_int_equal(grown.extra[i], 0xcd);
}

/* ---- ids of objects inside a world ------------------------------------------------------------ */
/* One object of every kind (ids in a world: sph_c.h). */
typedef struct {
  sph_collider_id collider;
  sph_source_id source;
  sph_sink_id sink;
  sph_force_field_id field;
  sph_probe_id probe;
} scene_ids;

static sph_world* scene_world(sph_context* context) {
  sph_world_def def;
  sph_world* world = NULL;
  small_world_def(&def);
  def.features = SPH_FEATURE_COLLIDER_LOADS;
  EXPECT_OK(sph_world_create(context, &def, &world));
  return world;
}

static sph_sdf* ball(sph_context* context) {
  sph_shape_desc d;
  sph_sdf* sdf = NULL;
  sph_shape_desc_init(&d);
  d.shape = SPH_SHAPE_SPHERE;
  d.radius = 0.1f;
  d.voxel_size = 0.02f;
  EXPECT_OK(sph_sdf_create_shape(context, &d, &sdf));
  return sdf;
}

static sph_collider_id add_collider(sph_world* world, sph_sdf* sdf, float x) {
  sph_collider_def d;
  sph_collider_id id = {0};
  sph_collider_def_init(&d);
  d.sdf = sdf;
  d.transform.position.x = x;
  EXPECT_OK(sph_collider_create(world, &d, &id));
  return id;
}

static scene_ids add_scene(sph_world* world, sph_sdf* sdf) {
  scene_ids ids;
  sph_source_def source;
  sph_sink_def sink;
  sph_force_field_def field;
  sph_probe_def probe;
  ids.collider = add_collider(world, sdf, 0.5f);
  sph_source_def_init(&source);
  source.region = sdf;
  EXPECT_OK(sph_source_create(world, &source, &ids.source));
  sph_sink_def_init(&sink);
  sink.region = sdf;
  EXPECT_OK(sph_sink_create(world, &sink, &ids.sink));
  sph_force_field_def_init(&field);
  EXPECT_OK(sph_force_field_create(world, &field, &ids.field));
  sph_probe_def_init(&probe);
  EXPECT_OK(sph_probe_create(world, &probe, &ids.probe));
  return ids;
}

/* Every call that takes an id refuses `ids` in `world` (INVALID_HANDLE naming the id), writes
 * no output, and the world saves the same bytes afterwards. */
static void expect_ids_refused_at(int line, sph_world* world, const scene_ids* ids) {
  uint64_t size_before = 0, size_after = 0;
  unsigned char *before = capi_save(world, &size_before), *after;
  sph_transform t = sph_transform_identity(), out, untouched;
  sph_collider_material material;
  sph_collider_loads loads;
  sph_probe_reading reading;
  const sph_vec3 point = {0.1f, 0.2f, 0.3f};
  t.position.x = 9.0f;
  memset(&out, 0x5a, sizeof out);
  untouched = out;
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id",
                  sph_collider_get_transform(world, ids->collider, &out));
  assert_memory_equal(&out, &untouched, sizeof out);
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_collider_teleport(world, ids->collider, &t));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id",
                  sph_collider_set_target_transform(world, ids->collider, &t));
  sph_collider_material_init(&material);
  material.friction = 0.75f;
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id",
                  sph_collider_set_material(world, ids->collider, &material));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id",
                  sph_collider_get_material(world, ids->collider, &material));
  sph_collider_loads_init(&loads);
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_collider_get_loads(world, ids->collider, &loads));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id",
                  sph_collider_set_load_point(world, ids->collider, &point));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id",
                  sph_collider_set_load_threshold(world, ids->collider, 5.0f));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_collider_destroy(world, ids->collider));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_source_set_transform(world, ids->source, &t));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_source_destroy(world, ids->source));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_sink_destroy(world, ids->sink));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_force_field_set_transform(world, ids->field, &t));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_force_field_destroy(world, ids->field));
  sph_probe_reading_init(&reading);
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_probe_get_reading(world, ids->probe, &reading));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id",
                  sph_probe_set_pressure_threshold(world, ids->probe, 100.0f));
  EXPECT_ERROR_AT(line, SPH_ERROR_INVALID_HANDLE, "id", sph_probe_destroy(world, ids->probe));
  after = capi_save(world, &size_after);
  assert_int_equal(size_after, size_before);
  assert_memory_equal(after, before, (size_t)size_before);
  free(after);
  free(before);
}
#define EXPECT_IDS_REFUSED(world, ids) expect_ids_refused_at(__LINE__, (world), (ids))

/* No id of `a` has the bits of the same kind's id in `b`. */
static void expect_all_ids_differ(const scene_ids* a, const scene_ids* b) {
  assert_true(a->collider.bits != b->collider.bits);
  assert_true(a->source.bits != b->source.bits);
  assert_true(a->sink.bits != b->sink.bits);
  assert_true(a->field.bits != b->field.bits);
  assert_true(a->probe.bits != b->probe.bits);
}

/* The ids of every kind of object work in their own world only: two worlds of one context, made
 * alike, each refuse the other's ids (before the world tag in the ids, the first collider of
 * every world had the same bits, and world B moved or destroyed its own collider when given
 * world A's id). Their bits differ; a world loaded from A's checkpoint shares A's ids (by
 * design: it accepts the saved ids) and still refuses B's. */
static void test_ids_of_another_world_are_refused(void** state) {
  sph_context* context = make_context();
  sph_sdf* sdf = ball(context);
  sph_world *a = scene_world(context), *b = scene_world(context), *loaded = NULL;
  const scene_ids in_a = add_scene(a, sdf), in_b = add_scene(b, sdf);
  sph_transform t;
  uint64_t size = 0;
  unsigned char* saved;
  (void)state;
  expect_all_ids_differ(&in_a, &in_b);
  EXPECT_IDS_REFUSED(b, &in_a);
  EXPECT_IDS_REFUSED(a, &in_b);
  /* Each world's own ids still work. */
  EXPECT_OK(sph_collider_get_transform(a, in_a.collider, &t));
  EXPECT_OK(sph_collider_get_transform(b, in_b.collider, &t));
  /* A world loaded from A's checkpoint takes A's ids (and issues A's next ones), not B's. */
  saved = capi_save(a, &size);
  EXPECT_OK(sph_world_load(context, saved, size, &loaded));
  EXPECT_OK(sph_collider_get_transform(loaded, in_a.collider, &t));
  assert_true(t.position.x == 0.5f);
  EXPECT_IDS_REFUSED(loaded, &in_b);
  free(saved);
  EXPECT_OK(sph_world_destroy(loaded));
  EXPECT_OK(sph_world_destroy(b));
  EXPECT_OK(sph_world_destroy(a));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(sph_context_destroy(context));
}

/* An id is never reused, a restore included: save, create X, restore, create Y: Y is not X, and
 * X stays refused (before, Y got X's bits and the engine's stale id of X named Y). The same
 * after a restore of another world's checkpoint, and across several restores. */
static void test_ids_are_not_reused_after_restore(void** state) {
  sph_context* context = make_context();
  sph_sdf* sdf = ball(context);
  sph_world *a = scene_world(context), *b = scene_world(context);
  scene_ids in_a = add_scene(a, sdf), extra, again, in_b;
  sph_collider_id first_b, second_b;
  sph_transform t;
  uint64_t size = 0;
  unsigned char* saved;
  (void)state;
  saved = capi_save(a, &size);
  extra = add_scene(a, sdf);
  EXPECT_OK(sph_world_restore(a, saved, size));
  EXPECT_OK(sph_collider_get_transform(a, in_a.collider, &t)); /* the saved ids are back */
  EXPECT_IDS_REFUSED(a, &extra);
  again = add_scene(a, sdf);
  expect_all_ids_differ(&again, &extra);
  EXPECT_IDS_REFUSED(a, &extra);
  /* Once more: neither id issued after the save comes back. */
  EXPECT_OK(sph_world_restore(a, saved, size));
  {
    const scene_ids third = add_scene(a, sdf);
    assert_true(third.collider.bits != extra.collider.bits && third.collider.bits != again.collider.bits);
    assert_true(third.probe.bits != extra.probe.bits && third.probe.bits != again.probe.bits);
  }
  EXPECT_IDS_REFUSED(a, &extra);
  EXPECT_IDS_REFUSED(a, &again);
  /* B restores A's checkpoint: B's own ids are refused (B now has A's saved scene and ids), and
   * no id B issued, before or after that restore, is issued again. */
  in_b = add_scene(b, sdf);
  EXPECT_OK(sph_world_restore(b, saved, size));
  EXPECT_IDS_REFUSED(b, &in_b);
  EXPECT_OK(sph_collider_get_transform(b, in_a.collider, &t));
  first_b = add_collider(b, sdf, 1.0f);
  assert_true(first_b.bits != in_b.collider.bits);
  EXPECT_OK(sph_world_restore(b, saved, size));
  second_b = add_collider(b, sdf, 1.0f);
  assert_true(second_b.bits != first_b.bits && second_b.bits != in_b.collider.bits);
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_get_transform(b, first_b, &t));
  EXPECT_ERROR(SPH_ERROR_INVALID_HANDLE, "id", sph_collider_destroy(b, first_b));
  EXPECT_OK(sph_collider_get_transform(b, second_b, &t));
  free(saved);
  EXPECT_OK(sph_world_destroy(b));
  EXPECT_OK(sph_world_destroy(a));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(sph_context_destroy(context));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_def_init),
      cmocka_unit_test(test_create_bad_context),
      cmocka_unit_test(test_create_null_arguments),
      cmocka_unit_test(test_create_struct_size),
      cmocka_unit_test(test_create_header_version),
      cmocka_unit_test(test_create_capacity),
      cmocka_unit_test(test_create_unknown_enums_and_bits),
      cmocka_unit_test(test_create_reserved),
      cmocka_unit_test(test_create_non_finite),
      cmocka_unit_test(test_create_out_of_range),
      cmocka_unit_test(test_destroy),
      cmocka_unit_test(test_get_def),
      cmocka_unit_test(test_particle_mass),
      cmocka_unit_test(test_params_init),
      cmocka_unit_test_setup_teardown(test_set_params_handles_and_sizes, capi_fixture_setup,
                                      capi_fixture_teardown),
      cmocka_unit_test_setup_teardown(test_set_params_non_finite, capi_fixture_setup, capi_fixture_teardown),
      cmocka_unit_test_setup_teardown(test_set_params_out_of_range, capi_fixture_setup,
                                      capi_fixture_teardown),
      cmocka_unit_test_setup_teardown(test_get_params, capi_fixture_setup, capi_fixture_teardown),
      cmocka_unit_test(test_ids_of_another_world_are_refused),
      cmocka_unit_test(test_ids_are_not_reused_after_restore),
  };
  return cmocka_run_group_tests_name("capi_world_errors", tests, NULL, NULL);
}
