// SPDX-License-Identifier: MIT
/* Surface tension (issue 5 items 1 and 7) against the physics of a free droplet, with the
 * physical sigma the caller gives (water's 0.0728 N/m) and no gravity:
 * - a resting droplet holds the Laplace pressure 2 sigma / R inside;
 * - a droplet set oscillating in its l = 2 mode (low viscosity) has Rayleigh's period
 *   T2 = (pi / sqrt 2) sqrt(rho R^3 / sigma) (Rayleigh 1879; Lamb, Hydrodynamics, s. 275);
 * - a cube of fluid rounds into a sphere.
 * Every droplet is R = 1 cm at 10 particles per radius (spacing 1 mm, h = 1.8 mm, about 5,900
 * particles), with Tait's equation of state at c = 2 m/s: the Laplace pressure (14.6 Pa) then
 * compresses the drop by only 0.4 %, the breathing (acoustic) mode, about pi c / R = 630 rad/s,
 * is far above the l = 2 mode's 24 rad/s, and the acoustic step limit (0.4 h / c = 0.36 ms)
 * makes a period about 700 substeps. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_test.h"

static const double kPi = 3.14159265358979323846;

enum { kMaxParticles = 12000 };

static const float kSpacing = 0.001f;  /* m */
static const float kSigma = 0.0728f;   /* N/m, water at 20 C */
static const float kRho = 1000.0f;     /* kg/m^3 */
static const float kSoundSpeed = 2.0f; /* m/s */

typedef struct drop {
  scene s;
  uint32_t n;
  float mass;
  float* x;
  float* v;
} drop;

/* A world with surface tension, Tait's law, no gravity and Mueller viscosity mu (Pa s). */
static void drop_open(drop* d, float viscosity) {
  sph_world_def def;
  sph_world_params params;
  sph_surface_tension_params st;
  sph_tait_params tait;
  memset(d, 0, sizeof *d);
  sph_world_def_init(&def);
  def.capacity = kMaxParticles;
  def.particle_spacing = kSpacing;
  def.rest_density = kRho;
  def.features = SPH_FEATURE_SURFACE_TENSION;
  def.equation_of_state = SPH_EOS_TAIT;
  sph_world_params_init(&params);
  params.gravity.y = 0.0f;
  params.viscosity = viscosity;
  params.dt_max = 1e-3f;
  params.step_limits = SPH_STEP_LIMIT_ACOUSTIC;
  SCENE_OK(support_world_open(&d->s, sph_test_backend(), &def, &params));
  sph_tait_params_init(&tait);
  tait.speed_of_sound = kSoundSpeed;
  SCENE_OK(sph_world_set_tait_params(d->s.world, &tait));
  sph_surface_tension_params_init(&st);
  st.coefficient = kSigma;
  SCENE_OK(sph_world_set_surface_tension_params(d->s.world, &st));
  SCENE_OK(sph_world_get_particle_mass(d->s.world, &d->mass));
  d->x = malloc(12 * (size_t)kMaxParticles);
  d->v = malloc(12 * (size_t)kMaxParticles);
  assert_true(d->x && d->v);
}

static void drop_close(drop* d) {
  free(d->x);
  free(d->v);
  scene_close(&d->s);
}

/* FCC lattice points (spacing kSpacing, a point at the origin) inside a sphere of radius
 * `radius` (shape 0) or a cube of half-side `radius` (shape 1), with the l = 2 potential flow
 * v = a (-x, -y, 2 z) (divergence-free), spawned. */
static void drop_spawn(drop* d, int shape, float radius, float a) {
  const double step = kSpacing / sqrt(2.0);
  const int m = (int)(radius / step) + 1;
  int i, j, k;
  uint32_t n = 0;
  sph_spawn_desc spawn;
  for (k = -m; k <= m; ++k)
    for (j = -m; j <= m; ++j)
      for (i = -m; i <= m; ++i) {
        const double x = step * i, y = step * j, z = step * k;
        const int inside = shape == 0 ? x * x + y * y + z * z <= (double)radius * radius
                                      : fabs(x) <= radius && fabs(y) <= radius && fabs(z) <= radius;
        if (((i + j + k) % 2 + 2) % 2 != 0 || !inside) continue;
        assert_true(n < kMaxParticles);
        d->x[3 * n] = (float)x, d->x[3 * n + 1] = (float)y, d->x[3 * n + 2] = (float)z;
        d->v[3 * n] = (float)(-a * x), d->v[3 * n + 1] = (float)(-a * y),
                 d->v[3 * n + 2] = (float)(2.0 * a * z);
        ++n;
      }
  sph_spawn_desc_init(&spawn);
  spawn.count = n;
  spawn.positions = d->x;
  spawn.velocities = d->v;
  SCENE_OK(sph_world_spawn(d->s.world, &spawn, NULL));
  d->n = n;
}

/* The radius of the sphere with the fluid's volume, N m / rho0. */
static double drop_volume_radius(const drop* d) { return cbrt(3.0 * d->n * d->mass / (4.0 * kPi * kRho)); }

/* Rayleigh's l = 2 period of a drop of radius r. */
static double rayleigh_period(double r) { return kPi / sqrt(2.0) * sqrt(kRho * r * r * r / kSigma); }

typedef struct shape_stats {
  double quadrupole; /* mean of z^2 - (x^2 + y^2) / 2 about the centroid, m^2 */
  double r_max;      /* largest distance from the centroid, m */
  uint32_t strays;   /* particles farther than 1.5 R from the centroid */
} shape_stats;

static shape_stats drop_shape(drop* d, double radius) {
  shape_stats st;
  double c[3] = {0.0, 0.0, 0.0};
  uint32_t i;
  memset(&st, 0, sizeof st);
  assert_int_equal(scene_positions(&d->s, d->x, d->n), d->n);
  for (i = 0; i < d->n; ++i)
    for (int a = 0; a < 3; ++a) c[a] += d->x[3 * i + a];
  for (int a = 0; a < 3; ++a) c[a] /= d->n;
  for (i = 0; i < d->n; ++i) {
    const double x = d->x[3 * i] - c[0], y = d->x[3 * i + 1] - c[1], z = d->x[3 * i + 2] - c[2];
    const double r = sqrt(x * x + y * y + z * z);
    st.quadrupole += z * z - 0.5 * (x * x + y * y);
    if (r > st.r_max) st.r_max = r;
    if (r > 1.5 * radius) ++st.strays;
  }
  st.quadrupole /= d->n;
  return st;
}

/* The mean Tait pressure of the particles within half the radius of the centre. */
static double drop_core_pressure(drop* d, double radius) {
  float* p = malloc(4 * (size_t)d->n);
  double sum = 0.0;
  uint32_t i, count = 0;
  assert_true(p != NULL);
  assert_int_equal(scene_positions(&d->s, d->x, d->n), d->n);
  SCENE_OK(
      sph_world_copy_attribute(d->s.world, SPH_ATTRIBUTE_PRESSURE, p, 4 * (uint64_t)d->n, 0, 0, d->n, NULL));
  for (i = 0; i < d->n; ++i) {
    const double x = d->x[3 * i], y = d->x[3 * i + 1], z = d->x[3 * i + 2];
    if (x * x + y * y + z * z > 0.25 * radius * radius) continue;
    sum += p[i];
    ++count;
  }
  free(p);
  assert_true(count > 0);
  return sum / count;
}

/* Runs `seconds` in frames of `frame`, returning the shape after each frame through `out`
 * (may be null) and the mean core pressure over the frames after `average_from` seconds. */
static double drop_run(drop* d, double radius, double seconds, double frame, double average_from,
                       double* quadrupole, uint32_t* strays, double* r_max) {
  double t = 0.0, p_sum = 0.0;
  int frames = 0, k = 0;
  *strays = 0;
  *r_max = 0.0;
  while (t < seconds - 0.5 * frame) {
    shape_stats st;
    SCENE_OK(sph_world_step(d->s.world, (float)frame));
    t += frame;
    st = drop_shape(d, radius);
    if (quadrupole) quadrupole[k] = st.quadrupole;
    ++k;
    if (st.strays > *strays) *strays = st.strays;
    if (st.r_max > *r_max) *r_max = st.r_max;
    if (t > average_from) {
      p_sum += drop_core_pressure(d, radius);
      ++frames;
    }
  }
  return frames > 0 ? p_sum / frames : 0.0;
}

/* The core pressure of a resting droplet of lattice radius `lattice_radius` (mu = 1), averaged
 * over 0.1-0.15 s; *radius gets its volume radius. */
static double resting_core_pressure(float lattice_radius, double* radius, uint32_t* strays, double* r_max) {
  drop d;
  double pressure;
  drop_open(&d, 1.0f);
  drop_spawn(&d, 0, lattice_radius, 0.0f);
  *radius = drop_volume_radius(&d);
  pressure = drop_run(&d, *radius, 0.15, 0.01, 0.1, NULL, strays, r_max);
  drop_close(&d);
  return pressure;
}

/* A droplet at rest holds the Laplace pressure 2 sigma / R above the pressure a flat surface
 * holds (R the radius of a sphere of the fluid's volume). The flat-surface pressure is not zero:
 * the cohesion half of the surface tension pulls the surface layer in, and the equation of state
 * holds that (63 Pa here, docs/physics.md), so the test compares two drops, R = 1 cm and
 * 0.6 cm: their core pressures must differ by 2 sigma (1/R2 - 1/R1) (9.7 Pa). Each starts as a
 * lattice sphere at zero pressure; the breathing mode the tension starts is damped by mu = 1
 * within 0.1 s and the pressure of the core (r < R/2) is then averaged over the next 50 ms.
 * Bound 15 %: both halves of sigma are calibrated on flat lattice surfaces, whose (100), (110)
 * and (111) faces differ by +-5 % and which a 6-particle-radius drop only roughly is, and the
 * remaining breathing oscillation moves each 50 ms average by a few tenths of a pascal.
 * Nothing may leave either drop (strays: particles beyond 1.5 R). Measured: 10.45 Pa for 9.88
 * (+5.8 %); core pressures 77.3 and 87.8 Pa. */
static void test_laplace_pressure(void** state) {
  double r1, r2, p1, p2, m1, m2, expected;
  uint32_t s1, s2;
  (void)state;
  p1 = resting_core_pressure(0.01f, &r1, &s1, &m1);
  p2 = resting_core_pressure(0.006f, &r2, &s2, &m2);
  expected = 2.0 * kSigma * (1.0 / r2 - 1.0 / r1);
  print_message(
      "surface tension: core pressures %.2f Pa (R %.4f m) and %.2f Pa (R %.4f m): difference %.2f Pa "
      "(2 sigma (1/R2 - 1/R1) = %.2f), r_max/R %.3f %.3f, strays %u %u\n",
      p1, r1, p2, r2, p2 - p1, expected, m1 / r1, m2 / r2, s1, s2);
  assert_true(fabs(p2 - p1 - expected) < 0.15 * expected);
  assert_int_equal(s1, 0);
  assert_int_equal(s2, 0);
}

/* Rayleigh's l = 2 oscillation: the drop starts round with the potential flow v = a (-x, -y, 2z)
 * (a = 1/s: an axis amplitude of about 8 % of R) and its quadrupole moment
 * <z^2 - (x^2 + y^2)/2> then goes as sin(omega t): its zero crossings are half periods apart.
 * The period from the first to the third crossing must be within 10 % of T2 (issue 5), with
 * mu = 0.1 (the l = 2 damping rate 5 nu / R^2 = 5/s shifts the frequency by 2 %). Nothing may
 * leave the drop (the cohesion's share of sigma, 15 %, was chosen with this test: docs/physics.md
 * gives the other shares' results). Measured: 0.2464 s for T2 = 0.2586 s (-4.7 %), r_max 1.063 R, no strays
 * (without the cohesion, 134 particles left the drop, the farthest to 4.7 R). */
static void test_rayleigh_period(void** state) {
  enum { kFrames = 240 };
  /* Long enough for three crossings of a period up to 1.1 T2 when the first comes by 0.6 T2
   * (measured: 0.52 T2). */
  const double kSpan = 1.8;
  const double frame = 0.0025;
  double q[kFrames], radius, period, crossings[3] = {0.0, 0.0, 0.0}, r_max;
  uint32_t strays;
  int k, found = 0;
  drop d;
  (void)state;
  drop_open(&d, 0.1f);
  drop_spawn(&d, 0, 0.01f, 1.0f);
  radius = drop_volume_radius(&d);
  period = rayleigh_period(radius);
  assert_true(kSpan * period < kFrames * frame);
  drop_run(&d, radius, kSpan * period, frame, 1e9, q, &strays, &r_max);
  for (k = 1; k < (int)(kSpan * period / frame) && found < 3; ++k)
    if ((q[k - 1] > 0.0) != (q[k] > 0.0)) crossings[found++] = frame * (k + q[k - 1] / (q[k - 1] - q[k]));
  print_message("surface tension: %d zero crossings, period %.4f s (T2 %.4f), r_max/R %.3f, strays %u\n",
                found, found == 3 ? crossings[2] - crossings[0] : 0.0, period, r_max / radius, strays);
  assert_int_equal(found, 3);
  assert_true(fabs(crossings[2] - crossings[0] - period) < 0.1 * period);
  assert_int_equal(strays, 0);
  drop_close(&d);
}

/* A cube (side 1.6 cm, about 5,800 particles) with no gravity rounds into a sphere: after 0.3 s (about
 * one l = 2 period of the equal-volume sphere) every particle is within 10 % of the
 * equal-volume radius R of the centre (the lattice cube's outermost corner particles start at
 * 1.30 R), and none has left. mu = 0.3 damps the shape oscillation. Measured: r_max 1.30 R ->
 * 0.958 R after 0.3 s (the outer particles' centres sit about half a spacing inside the
 * surface, and the cohesion's bulk pressure compresses the drop by about 1.5 % in density), no strays
 * (without the cohesion: 1.17 R). */
static void test_cube_rounds(void** state) {
  drop d;
  double radius, r_max, r_start;
  uint32_t strays;
  shape_stats st;
  (void)state;
  drop_open(&d, 0.3f);
  drop_spawn(&d, 1, 0.008f, 0.0f);
  radius = drop_volume_radius(&d);
  r_start = drop_shape(&d, radius).r_max;
  drop_run(&d, radius, 0.3, 0.01, 1e9, NULL, &strays, &r_max);
  st = drop_shape(&d, radius);
  print_message("surface tension: cube r_max/R %.3f -> %.3f, strays %u\n", r_start / radius,
                st.r_max / radius, st.strays);
  assert_true(st.r_max < 1.1 * radius);
  assert_int_equal(st.strays, 0);
  drop_close(&d);
}

/* Without arguments: the Laplace pressure; "rayleigh" and "cube" run those tests (each its own
 * ctest, so each stays under a minute). */
int main(int argc, char** argv) {
  const struct CMUnitTest laplace[] = {
      cmocka_unit_test(test_laplace_pressure),
  };
  const struct CMUnitTest rayleigh[] = {
      cmocka_unit_test(test_rayleigh_period),
  };
  const struct CMUnitTest cube[] = {
      cmocka_unit_test(test_cube_rounds),
  };
  if (argc > 1 && strcmp(argv[1], "rayleigh") == 0) return cmocka_run_group_tests(rayleigh, NULL, NULL);
  if (argc > 1 && strcmp(argv[1], "cube") == 0) return cmocka_run_group_tests(cube, NULL, NULL);
  return cmocka_run_group_tests(laplace, NULL, NULL);
}
