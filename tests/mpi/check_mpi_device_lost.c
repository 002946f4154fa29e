/* SPDX-License-Identifier: MIT */
/* A lost device on one rank of a distributed CUDA world (gpu_check_mpi_device_lost; scripts/gpu-test
 * runs it under mpirun -np 2, in a time limit). The last rank poisons its process's CUDA context (a
 * sticky error: every later CUDA call there fails) and learns of it through a call of its own,
 * sph_cuda_world_record_event, which marks its world lost (SPH_ERROR_DEVICE_LOST, sph_c.h). The other
 * ranks know nothing of it. Then every rank makes the collective calls of sph_mpi.h: each must
 * return an error on every rank (the lost rank SPH_ERROR_DEVICE_LOST, the others the agreed
 * failure naming the lost device), none may leave the others waiting in MPI for it (which the
 * time limit would show as a hang), and the world and the contexts must still be destroyed.
 *
 * --in-step: the last rank poisons its context and makes no call of its own, so that the loss
 * surfaces inside the next step, after its first agreement. That step's failure is agreed with the
 * status SPH_ERROR_DEVICE_LOST on every rank, and each rank's step marks its own world lost
 * (docs/distributed.md, "A lost device is agreed"): every rank's step returns DEVICE_LOST, a local
 * read (sph_world_copy_attribute) is then refused with it on every rank, and so is every later
 * collective call. */
#include <stdlib.h>
#include <string.h>

#include "mpi_poison_device.h"
#include "mpi_test_world.h"
#include "sph_cuda.h"

/* A collective call's result on this rank: an error everywhere, DEVICE_LOST on the lost rank, and
 * elsewhere a message that names the lost device. */
static void expect_refused(const char* call, sph_result r, int lost_rank) {
  if (g_rank == lost_rank) {
    CHECK(r == SPH_ERROR_DEVICE_LOST, "%s on the lost rank: %s, expected SPH_ERROR_DEVICE_LOST", call,
          sph_result_string(r));
  } else {
    CHECK(r < 0, "%s beside a lost device: %s, expected an error", call, sph_result_string(r));
    CHECK(r >= 0 || strstr(sph_get_last_error(), "device was lost") != NULL,
          "%s beside a lost device: the message does not name the lost device", call);
  }
}

/* --in-step: every rank's world is lost after the step that met the loss. */
static void expect_lost(const char* call, sph_result r) {
  CHECK(r == SPH_ERROR_DEVICE_LOST, "%s after a loss met in a step: %s, expected SPH_ERROR_DEVICE_LOST (%s)",
        call, sph_result_string(r), sph_get_last_error());
}

int main(int argc, char** argv) {
  sph_context* cpu = NULL;
  sph_context* cuda = NULL;
  sph_world* world = NULL;
  sph_world_def def;
  uint32_t n = 0;
  int lost_rank;
  void* event;
  const char* path = "gpu_check_mpi_device_lost.sphrank";
  int in_step;
  mpi_test_init(&argc, &argv, &cpu);
  in_step = argc > 1 && strcmp(argv[1], "--in-step") == 0;
  lost_rank = g_size - 1;
  cuda = mpi_test_cuda_context(0);
  mpi_test_world_def(&def);
  def.capacity = 32768;
  mpi_test_dam(cuda, &def, 0.0f, NULL, NULL, &world, &n);
  mpi_test_step(world, 2, 1);
  REQUIRE(sph_mpi_world_save_file(world, path) == SPH_OK, "save before the fault");
  event = mpi_device_event_create();
  REQUIRE(event != NULL, "a CUDA event");
  MPI_Barrier(MPI_COMM_WORLD);
  if (g_rank == lost_rank) {
    CHECK(mpi_poison_device() != 0, "the poisoning kernel did not fault");
    if (!in_step)
      CHECK(sph_cuda_world_record_event(world, event) == SPH_ERROR_DEVICE_LOST,
            "record_event on the poisoned rank: %s", sph_get_last_error());
  }
  if (in_step) {
    sph_mpi_counts counts;
    float position[3];
    uint32_t written = 0;
    REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK, "counts init");
    expect_lost("sph_world_step (the loss met inside it)", sph_world_step(world, 0.01f));
    expect_lost("sph_world_copy_attribute", sph_world_copy_attribute(world, SPH_ATTRIBUTE_POSITION, position,
                                                                     sizeof position, 0, 0, 1, &written));
    expect_lost("sph_world_step again", sph_world_step(world, 0.01f));
    expect_lost("sph_mpi_world_get_counts", sph_mpi_world_get_counts(world, &counts));
    expect_lost("sph_mpi_world_save_file", sph_mpi_world_save_file(world, path));
  } else {
    sph_mpi_counts counts;
    float x[3] = {0.05f, 0.1f, 0.03f};
    uint64_t gathered = 0;
    uint32_t removed = 0;
    REQUIRE(sph_mpi_counts_init(&counts) == SPH_OK, "counts init");
    expect_refused("sph_world_step", sph_world_step(world, 0.01f), lost_rank);
    expect_refused("sph_world_step again", sph_world_step(world, 0.01f), lost_rank);
    expect_refused("sph_mpi_world_get_counts", sph_mpi_world_get_counts(world, &counts), lost_rank);
    expect_refused("sph_mpi_world_gather", sph_mpi_world_gather(world, 0, NULL, NULL, NULL, 0, &gathered),
                   lost_rank);
    expect_refused("sph_mpi_world_gather_removed_ids",
                   sph_mpi_world_gather_removed_ids(world, 0, NULL, 0, &removed), lost_rank);
    expect_refused("sph_mpi_world_add_particles",
                   sph_mpi_world_add_particles(world, x, NULL, g_rank == 0 ? 1u : 0u, NULL), lost_rank);
    expect_refused("sph_mpi_world_save_file", sph_mpi_world_save_file(world, path), lost_rank);
    expect_refused("sph_mpi_world_restore_file", sph_mpi_world_restore_file(world, path), lost_rank);
  }
  CHECK(sph_world_destroy(world) == SPH_OK, "destroy the world: %s", sph_get_last_error());
  CHECK(sph_context_destroy(cuda) == SPH_OK, "destroy the CUDA context: %s", sph_get_last_error());
  return mpi_test_finish(cpu, in_step ? "mpi_cuda device lost in a step" : "mpi_cuda device lost");
}
