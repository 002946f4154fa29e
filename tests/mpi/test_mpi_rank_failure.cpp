// SPDX-License-Identifier: MIT
// Failures that are not input errors, on one rank of a distributed world, agreed by every rank
// (core/rank_agreement.h), under mpirun on 1-4 ranks:
//   - a host allocation failure injected on the last rank at each allocation of a step in turn
//     (the replaced operator new of tests/support/allocation_injector.h, armed on that rank
//     only): every rank returns SPH_ERROR_OUT_OF_HOST_MEMORY (the others' messages name the
//     failing rank) instead of waiting in MPI for it, every rank's world is as before the step
//     (gathered bit for bit), and the world then steps on exactly as an undisturbed copy; again
//     with springs, with the tank's collider loads (their sum over the ranks), with a probe and a
//     gauge (their readings then equal the undisturbed world's), and with DFSPH's density solve
//     by conjugate gradients (the allocations of its exchanges inside each iteration, followed by
//     the reductions of its sums);
//   - a crowded cell (700 particles in one cell, more than the 528 one may hold) on whichever
//     rank owns it, and the ranks holding it as ghosts: every rank returns SPH_ERROR_CAPACITY and
//     the world is unchanged;
//   - a frame refused on the last rank alone (frame_dt not positive), a frame_dt that differs
//     between the ranks, parameters (sph_world_set_params), a definition (Clavet's viscosity on one
//     rank) or a scene (a probe on one rank, a collider moved on one rank) that differ: every rank
//     returns
//     INVALID_ARGUMENT, the world unchanged, and steps on once the ranks agree;
//   - sph_mpi_world_create refused on the last rank alone (an invalid world definition, an invalid
//     rebalance threshold, a NULL out, a NULL context): every rank returns that rank's status, the
//     others' messages name it, no rank gets a world, and a world made after it works.
// A rank that waited forever would hang the test into ctest's timeout.
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <atomic>
#include <cstddef>
#include <new>

#include "mpi_test_world.h"
#include "support.h"

#include "allocation_injector.h"

using alloc_fault::arm;
using alloc_fault::disarm;

namespace {

constexpr uint32_t kSubsteps = 2;

sph_result step(sph_world* world) { return sph_mpi_world_step(world, 1.0f); }

void set_substeps(sph_world* world) {
  sph_world_params p;
  REQUIRE(support_params_gravity_and_steps(&p, 0.0f, -9.81f, 0.0f, 1e-5f, 1e-3f) == SPH_OK, "params");
  p.max_substeps = kSubsteps;
  REQUIRE(sph_world_set_params(world, &p) == SPH_OK, "set params");
}

void check_rank_named(int culprit, const char* what) {
  char text[32];
  if (g_rank == culprit) return;
  snprintf(text, sizeof text, "rank %d", culprit);
  CHECK(strstr(sph_get_last_error(), text) != NULL, "%s: the message names %s: %s", what, text,
        sph_get_last_error());
}

// An allocation failure at each allocation of the last rank's step in turn (with springs: their
// linking, spring ghosts and the lists' ids through the rollback too; with collider loads: the sum
// of the tank's loads over the ranks at the frame's end; with `probes`, a point and a gauge sampled
// every substep, whose readings must then equal the undisturbed world's; with `cg`, a DFSPH world whose
// density solve runs by conjugate gradients: its exchanges of the search directions and velocity
// steps and its sums' reductions inside each iteration).
void allocation_failures(sph_context* context, uint32_t features, bool cg, const char* name,
                         bool probes = false) {
  sph_world_def def;
  sph_world* world = NULL;
  sph_world* undisturbed = NULL;
  uint32_t n = 0;
  long k = 0;
  const int victim = g_size - 1;
  mpi_test_world_def(&def);
  def.features = features;
  def.particle_spacing = 0.02f;  // 150 particles: a step per allocation point
  def.kernel_radius = 0.036f;
  if (cg) def.solver = SPH_SOLVER_DFSPH;
  mpi_test_dam(context, &def, 2.0f, NULL, NULL, &world, &n);
  mpi_test_dam(context, &def, 2.0f, NULL, NULL, &undisturbed, &n);
  set_substeps(world);
  set_substeps(undisturbed);
  // With `probes`: a point in the column and a gauge across it, sampled every substep (their
  // sample points are gathered by the ranks whose slabs hold them and exchanged each substep).
  sph_probe_id probe_ids[2][2] = {};
  if (probes) {
    sph_world* worlds[2] = {world, undisturbed};
    for (int w = 0; w < 2; ++w) {
      sph_probe_def probe;
      REQUIRE(sph_probe_def_init(&probe) == SPH_OK, "probe def");
      probe.sampling = SPH_PROBE_EVERY_SUBSTEP;
      probe.position = sph_vec3{0.05f, 0.05f, 0.03f};
      REQUIRE(sph_probe_create(worlds[w], &probe, &probe_ids[w][0]) == SPH_OK, "probe: %s",
              sph_get_last_error());
      probe.kind = SPH_PROBE_GAUGE;
      probe.position = sph_vec3{0.05f, 0.0f, 0.03f};
      probe.length = 0.2f;
      REQUIRE(sph_probe_create(worlds[w], &probe, &probe_ids[w][1]) == SPH_OK, "gauge: %s",
              sph_get_last_error());
    }
  }
  if (cg) {
    sph_dfsph_params dfsph;
    REQUIRE(sph_dfsph_params_init(&dfsph) == SPH_OK, "dfsph params init");
    dfsph.linear_solver = SPH_DFSPH_CONJUGATE_GRADIENTS;
    dfsph.density_error = 1e-5f;  // (iterations past the minimum: the loop's exchanges and sums)
    REQUIRE(sph_world_set_dfsph_params(world, &dfsph) == SPH_OK &&
                sph_world_set_dfsph_params(undisturbed, &dfsph) == SPH_OK,
            "dfsph params: %s", sph_get_last_error());
  }
  for (k = 0; k < 100000; ++k) {
    float *x0 = NULL, *v0 = NULL, *x1 = NULL, *v1 = NULL;
    bool injected = false;
    sph_result r;
    mpi_test_gather(world, n, &x0, &v0);
    if (g_rank == victim) arm(k);
    r = step(world);
    if (g_rank == victim) injected = disarm();
    if (r == SPH_INCOMPLETE) {
      CHECK(!injected, "allocation %ld failed, yet the step succeeded", k);
      free(x0);
      free(v0);
      break;
    }
    CHECK(r == SPH_ERROR_OUT_OF_HOST_MEMORY, "allocation %ld of rank %d failed: the step returned %d", k,
          victim, (int)r);
    CHECK(g_rank != victim || injected, "the step failed (%d) without an injected failure", (int)r);
    check_rank_named(victim, "an allocation failure");
    mpi_test_gather(world, n, &x1, &v1);
    CHECK(g_rank != 0 || mpi_differ(x0, v0, x1, v1, n, nullptr) == 0, "allocation %ld: the world changed", k);
    free(x0);
    free(v0);
    free(x1);
    free(v1);
  }
  REQUIRE(step(undisturbed) == SPH_INCOMPLETE, "undisturbed step");
  for (int p = 0; probes && p < 2; ++p) {
    sph_probe_reading got, want;
    REQUIRE(sph_probe_reading_init(&got) == SPH_OK && sph_probe_reading_init(&want) == SPH_OK,
            "reading init");
    REQUIRE(sph_probe_get_reading(world, probe_ids[0][p], &got) == SPH_OK &&
                sph_probe_get_reading(undisturbed, probe_ids[1][p], &want) == SPH_OK,
            "readings: %s", sph_get_last_error());
    CHECK(got.samples > 0 && memcmp(&got, &want, sizeof got) == 0,
          "%s: after the failures, probe %d reads other bits than the undisturbed world's (%u samples)", name,
          p, got.samples);
  }
  {
    float *x0 = NULL, *v0 = NULL, *x1 = NULL, *v1 = NULL;
    mpi_test_gather(world, n, &x0, &v0);
    mpi_test_gather(undisturbed, n, &x1, &v1);
    if (g_rank == 0) {
      const uint32_t differ = mpi_differ(x0, v0, x1, v1, n, nullptr);
      CHECK(differ == 0, "after the failures, %u of %u particles differ from the undisturbed world", differ,
            n);
      printf(
          "%s: allocation failures on rank %d of %d: %ld allocation points of a %u-substep step failed in "
          "turn, each on every rank; then %u particles differ from the undisturbed world\n",
          name, victim, g_size, k, kSubsteps, differ);
    }
    free(x0);
    free(v0);
    free(x1);
    free(v1);
  }
  CHECK(k > 10, "only %ld allocations in a step", k);
  REQUIRE(sph_world_destroy(world) == SPH_OK && sph_world_destroy(undisturbed) == SPH_OK, "destroy");
}

// 700 particles in one cell of the far end of the tank, beside the column.
void crowded_cell(sph_context* context) {
  sph_world_def def;
  sph_world* world = NULL;
  uint32_t n = 0;
  float *x0 = NULL, *v0 = NULL, *x1 = NULL, *v1 = NULL;
  float clump[3 * 700];
  uint64_t state = 99;
  sph_mpi_counts counts;
  sph_result r;
  mpi_test_world_def(&def);
  mpi_test_dam(context, &def, 0.0f, NULL, NULL, &world, &n);
  for (int i = 0; i < 700; ++i) {
    // Inside the cell [0.360, 0.378) x [0, 0.018) x [0.018, 0.036).
    clump[3 * i] = 0.362f + 0.014f * (float)support_random(&state);
    clump[3 * i + 1] = 0.002f + 0.014f * (float)support_random(&state);
    clump[3 * i + 2] = 0.020f + 0.014f * (float)support_random(&state);
  }
  REQUIRE(sph_mpi_world_add_particles(world, clump, NULL, g_rank == 0 ? 700u : 0u, NULL) == SPH_OK, "clump");
  n += 700;
  set_substeps(world);
  mpi_test_gather(world, n, &x0, &v0);
  r = step(world);
  CHECK(r == SPH_ERROR_CAPACITY, "a crowded cell: the step returned %d", (int)r);
  CHECK(strstr(sph_get_last_error(), "particles share one cell") != NULL, "the message: %s",
        sph_get_last_error());
  mpi_test_gather(world, n, &x1, &v1);
  CHECK(g_rank != 0 || mpi_differ(x0, v0, x1, v1, n, nullptr) == 0, "a crowded cell: the world changed");
  REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK && sph_mpi_world_get_counts(world, &counts) == SPH_OK,
          "counts");
  CHECK(counts.global_count == n, "%llu particles after a refused step, %u before",
        (unsigned long long)counts.global_count, n);
  if (g_rank == 0) printf("a crowded cell on %d ranks: every rank returned %d\n", g_size, (int)r);
  free(x0);
  free(v0);
  free(x1);
  free(v1);
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
}

// The world's creation refused on the last rank only: before session 37 that rank returned while
// the others went on to the next collective call and waited there for it (found by reading
// sph_mpi_world_create; the bad arguments are each of the checks that call makes).
void creation_refused_on_one_rank(sph_context* context) {
  const int culprit = g_size - 1;
  const char* cases[] = {"a negative kernel radius", "a rebalance threshold past 10000 %", "a NULL out",
                         "a NULL context"};
  for (int k = 0; k < 4; ++k) {
    sph_world_def def;
    mpi_test_world_def(&def);
    sph_mpi_world_def mdef;
    REQUIRE(sph_mpi_world_def_init(&mdef) == SPH_OK, "mpi def");
    sph_world* world = NULL;
    sph_world** out = &world;
    sph_context* ctx = context;
    if (g_rank == culprit) {
      if (k == 0) def.kernel_radius = -1.0f;
      if (k == 1) mdef.rebalance_threshold_percent = 10001;
      if (k == 2) out = NULL;
      if (k == 3) ctx = NULL;
    }
    const sph_result r = sph_mpi_world_create(ctx, &def, (int32_t)MPI_Comm_c2f(MPI_COMM_WORLD), &mdef, out);
    // The culprit's status on every rank (a NULL context is an invalid handle).
    const sph_result expected = k == 3 ? SPH_ERROR_INVALID_HANDLE : SPH_ERROR_INVALID_ARGUMENT;
    CHECK(r == expected, "%s on rank %d: rank %d returned %d, not %d (%s)", cases[k], culprit, g_rank, (int)r,
          (int)expected, sph_get_last_error());
    CHECK(world == NULL, "%s: rank %d got a world", cases[k], g_rank);
    check_rank_named(culprit, cases[k]);
  }
  // The ranks are in step: a world made now works.
  sph_world_def def;
  sph_world* world = NULL;
  uint32_t n = 0;
  mpi_test_world_def(&def);
  mpi_test_dam(context, &def, 0.0f, NULL, NULL, &world, &n);
  set_substeps(world);
  CHECK(step(world) == SPH_INCOMPLETE, "a world after the refusals (its step's substeps capped): %s",
        sph_get_last_error());
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
  if (g_rank == 0)
    printf("sph_mpi_world_create refused on rank %d of %d: every rank refused, 4 cases\n", culprit, g_size);
}

// Frames the ranks disagree on (since session 37: before, a rank whose frame_dt was refused returned
// while the others waited for it in the frame's first collective call, and ranks with other frames
// or parameters took other substeps, each alone in its collectives).
void frames_disagreed(sph_context* context) {
  const int culprit = g_size - 1;
  sph_world_def def;
  sph_world* world = NULL;
  uint32_t n = 0;
  float *x0 = NULL, *v0 = NULL, *x1 = NULL, *v1 = NULL;
  mpi_test_world_def(&def);
  mpi_test_dam(context, &def, 0.0f, NULL, NULL, &world, &n);
  set_substeps(world);
  mpi_test_gather(world, n, &x0, &v0);
  // frame_dt refused on one rank (the others' messages name it).
  sph_result r = sph_mpi_world_step(world, g_rank == culprit ? -1.0f : 1.0f);
  CHECK(r == SPH_ERROR_INVALID_ARGUMENT, "a negative frame_dt on rank %d: rank %d returned %d (%s)", culprit,
        g_rank, (int)r, sph_get_last_error());
  check_rank_named(culprit, "a negative frame_dt");
  if (g_size > 1) {
    r = sph_mpi_world_step(world, g_rank == culprit ? 0.5f : 1.0f);
    CHECK(r == SPH_ERROR_INVALID_ARGUMENT && strstr(sph_get_last_error(), "every rank steps the same frame"),
          "frame_dt 0.5 on rank %d, 1 elsewhere: rank %d returned %d (%s)", culprit, g_rank, (int)r,
          sph_get_last_error());
    sph_world_params p;
    REQUIRE(sph_world_params_init(&p) == SPH_OK && sph_world_get_params(world, &p) == SPH_OK, "get params");
    sph_world_params changed = p;
    if (g_rank == culprit) changed.gravity.y = -9.0f;
    REQUIRE(sph_world_set_params(world, &changed) == SPH_OK, "set params");
    r = sph_mpi_world_step(world, 1.0f);
    CHECK(r == SPH_ERROR_INVALID_ARGUMENT && strstr(sph_get_last_error(), "parameters"),
          "gravity -9 on rank %d, -9.81 elsewhere: rank %d returned %d (%s)", culprit, g_rank, (int)r,
          sph_get_last_error());
    REQUIRE(sph_world_set_params(world, &p) == SPH_OK, "set params back");
    // A probe on one rank only: the scene differs.
    sph_probe_def probe;
    sph_probe_id probe_id{};
    REQUIRE(sph_probe_def_init(&probe) == SPH_OK, "probe def");
    probe.position = sph_vec3{0.05f, 0.05f, 0.03f};
    if (g_rank == culprit) REQUIRE(sph_probe_create(world, &probe, &probe_id) == SPH_OK, "probe");
    r = sph_mpi_world_step(world, 1.0f);
    CHECK(r == SPH_ERROR_INVALID_ARGUMENT && strstr(sph_get_last_error(), "scene differs"),
          "a probe on rank %d alone: rank %d returned %d (%s)", culprit, g_rank, (int)r,
          sph_get_last_error());
    if (g_rank == culprit) REQUIRE(sph_probe_destroy(world, probe_id) == SPH_OK, "probe destroy");
    // A collider moved on one rank alone (each rank picks the step from its fastest collider): the
    // same counts, another scene.
    const support_tank far_tank = {{5.0f, 0.2f, 0.1f}, {0.2f, 0.2f, 0.1f}, 0.02f, 0.0f};
    sph_sdf* far_sdf = nullptr;
    sph_collider_id far_id{};
    REQUIRE(support_tank_create(context, world, &far_tank, &far_sdf, &far_id) == SPH_OK, "a second tank");
    if (g_rank == culprit) {
      const sph_transform moved = {{5.0f, 0.3f, 0.1f}, {0.0f, 0.0f, 0.0f, 1.0f}};
      REQUIRE(sph_collider_set_target_transform(world, far_id, &moved) == SPH_OK, "target");
    }
    r = sph_mpi_world_step(world, 1.0f);
    CHECK(r == SPH_ERROR_INVALID_ARGUMENT && strstr(sph_get_last_error(), "scene differs"),
          "a collider moved on rank %d alone: rank %d returned %d (%s)", culprit, g_rank, (int)r,
          sph_get_last_error());
    REQUIRE(sph_collider_destroy(world, far_id) == SPH_OK && sph_sdf_destroy(far_sdf) == SPH_OK,
            "destroy tank");
    // Another world definition on one rank (Clavet's viscosity): made, but its first frame refused.
    sph_world_def other_def = def;
    if (g_rank == culprit) other_def.viscosity_method = SPH_VISCOSITY_CLAVET;
    sph_world* other = nullptr;
    uint32_t other_n = 0;
    mpi_test_dam(context, &other_def, 0.0f, NULL, NULL, &other, &other_n);
    set_substeps(other);
    r = sph_mpi_world_step(other, 1.0f);
    CHECK(r == SPH_ERROR_INVALID_ARGUMENT && strstr(sph_get_last_error(), "definition"),
          "Clavet's viscosity on rank %d alone: rank %d returned %d (%s)", culprit, g_rank, (int)r,
          sph_get_last_error());
    REQUIRE(sph_world_destroy(other) == SPH_OK, "destroy");
  }
  mpi_test_gather(world, n, &x1, &v1);
  CHECK(g_rank != 0 || mpi_differ(x0, v0, x1, v1, n, nullptr) == 0, "a refused frame changed the world");
  r = sph_mpi_world_step(world, 1.0f);
  CHECK(r == SPH_INCOMPLETE, "the frame once the ranks agree: %d (%s)", (int)r, sph_get_last_error());
  if (g_rank == 0) printf("frames the ranks disagree on, %d ranks: refused on every rank\n", g_size);
  free(x0);
  free(v0);
  free(x1);
  free(v1);
  REQUIRE(sph_world_destroy(world) == SPH_OK, "destroy");
}

}  // namespace

int main(int argc, char** argv) {
  sph_context* context = NULL;
  mpi_test_init(&argc, &argv, &context);
  allocation_failures(context, SPH_FEATURE_NONE, false, "the stirred column");
  allocation_failures(context, SPH_FEATURE_SPRINGS, false, "the stirred column with springs");
  // (The tank's loads are summed over the ranks at the frame's end: that sum's allocations too.)
  allocation_failures(context, SPH_FEATURE_COLLIDER_LOADS, false, "the stirred column with collider loads");
  allocation_failures(context, SPH_FEATURE_NONE, false, "the stirred column with a probe and a gauge", true);
  allocation_failures(context, SPH_FEATURE_NONE, true, "the stirred column, DFSPH with conjugate gradients");
  crowded_cell(context);
  creation_refused_on_one_rank(context);
  frames_disagreed(context);
  return mpi_test_finish(context, "mpi rank failures");
}
