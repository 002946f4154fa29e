// SPDX-License-Identifier: MIT
/* An FCC sphere at rest density with no gravity stays at rest: the particle mass is chosen so
 * the lattice sits exactly at rest density, so pressure and viscosity leave it alone. 100
 * frames of 1/25 s with dt_max 1 ms (4,000 substeps).
 *
 * The particles start with random velocities of up to 0.1 mm/s (1e-5 of the sound speed).
 * Without them the lattice is exactly static (every density is at or just below rest density,
 * where the EOS gives zero pressure, so every acceleration is exactly 0) and "kinetic energy
 * not growing" would compare zeros. With them the test asks what matters: a sphere at rest is
 * a stable state that small disturbances do not pump up.
 *
 * argv[1] overrides the disturbance (m/s). ctest also registers 1 mm/s as a disabled case,
 * physics_rest_sphere_1mm_s_KNOWN_ISSUE: with the EOS clamped at zero below rest density
 * nothing pulls particles back together, and the sphere slowly expands (interior density
 * 1 % low after 1.4 s, 2 % after 4 s, still falling). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "capi_test.h"

#define FRAMES 100

static double disturbance = 1e-4; /* m/s, the largest velocity component at the start */

static void test_sphere_stays_at_rest(void** state) {
  const float spacing = 0.02f;
  const float radius = 6.0f * spacing; /* ~1,280 particles; ~80 of them interior */
  support_world w;
  sph_world_def def;
  sph_world_params params;
  support_sphere ball = {{0.0, 0.0, 0.0}, 0.0, 0.0, 0.0, NULL, 12345, 0};
  sph_world* world;
  float mass = 0.0f, h, rest;
  uint32_t n = 0;
  double ke0 = 0.0;
  double ke[FRAMES], worst_density_error = 0.0, max_first = 0.0, max_last = 0.0;
  (void)state;

  sph_world_def_init(&def);
  def.particle_spacing = spacing;
  def.capacity = 4096;
  EXPECT_OK(support_params_gravity_and_steps(&params, 0.0f, 0.0f, 0.0f, 1e-6f, 1e-3f));
  ball.radius = radius;
  ball.speed = disturbance;
  EXPECT_OK(support_rest_sphere_open(&w, sph_test_backend(), &def, &params, &ball, &n));
  world = w.world;
  h = w.def.kernel_radius;
  rest = w.def.rest_density;
  mass = w.mass;
  EXPECT_OK(support_kinetic_energy(world, mass, &ke0));

  for (int f = 0; f < FRAMES; ++f) {
    float* x = NULL;
    float* v = NULL;
    float* rho = NULL;
    double c[3] = {0.0, 0.0, 0.0}, energy = 0.0, density_sum = 0.0;
    uint32_t interior = 0;
    uint32_t count = 0;
    EXPECT_OK(sph_world_step(world, 1.0f / 25.0f));
    EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_POSITION, (void**)&x, &count));
    assert_int_equal(count, n);
    EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &count));
    EXPECT_OK(support_copy_by_id(world, SPH_ATTRIBUTE_DENSITY, (void**)&rho, &count));
    for (uint32_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) c[k] += x[3 * i + k] / (double)n;
      energy += 0.5 * mass *
                ((double)v[3 * i] * v[3 * i] + (double)v[3 * i + 1] * v[3 * i + 1] +
                 (double)v[3 * i + 2] * v[3 * i + 2]);
    }
    /* Interior: farther than 2 h from the surface, so the kernel sees a full neighbourhood. */
    for (uint32_t i = 0; i < n; ++i) {
      const double dx = x[3 * i] - c[0], dy = x[3 * i + 1] - c[1], dz = x[3 * i + 2] - c[2];
      if (sqrt(dx * dx + dy * dy + dz * dz) < radius - 2.0 * h) {
        density_sum += rho[i];
        ++interior;
      }
    }
    assert_true(interior >= 50);
    ke[f] = energy;
    {
      const double error = fabs(density_sum / interior - rest) / rest;
      if (error > worst_density_error) worst_density_error = error;
      /* The bound: mean density error of the interior <= 1 %. */
      if (error > 0.01)
        printf("frame %d: interior mean density %.3f, %.2f %% off rest density\n", f + 1,
               density_sum / interior, 100.0 * error);
      assert_true(error <= 0.01);
    }
    free(x);
    free(v);
    free(rho);
  }
  for (int f = 0; f < FRAMES; ++f) {
    if (f < FRAMES / 2 && ke[f] > max_first) max_first = ke[f];
    if (f >= FRAMES / 2 && ke[f] > max_last) max_last = ke[f];
  }
  {
    /* Kinetic energy as the rms speed it implies: sqrt(2 KE / total mass). */
    const double total_mass = (double)mass * n;
    const double initial_speed = sqrt(2.0 * ke0 / total_mass);
    const double final_speed = sqrt(2.0 * ke[FRAMES - 1] / total_mass);
    printf(
        "%u particles, h = %.4f m: worst interior density error %.3f %%; KE %.3g J at the start, max %.3g J "
        "(frames 1-50) and %.3g J (51-100), final %.3g J (rms speed %.3g -> %.3g m/s)\n",
        n, h, 100.0 * worst_density_error, ke0, max_first, max_last, ke[FRAMES - 1], initial_speed,
        final_speed);
    /* Not growing: the second half never exceeds the first half's peak. */
    assert_true(max_last <= max_first);
    /* Final KE small: below the disturbance it started with (viscosity damps it). A sphere
     * that expands, collapses or rings moves at a good fraction of the sound speed sqrt(k) =
     * 10 m/s instead. */
    assert_true(ke[FRAMES - 1] < ke0);
    assert_true(final_speed < initial_speed);
  }
  EXPECT_OK(support_world_close(&w));
}

int main(int argc, char** argv) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sphere_stays_at_rest),
  };
  if (argc > 1) disturbance = atof(argv[1]);
  printf("initial disturbance: velocity components up to %g m/s\n", disturbance);
  return cmocka_run_group_tests_name("rest_sphere", tests, NULL, NULL);
}
