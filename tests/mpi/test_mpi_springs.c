/* SPDX-License-Identifier: MIT */
/* Springs across ranks (SPH_FEATURE_SPRINGS in a distributed world, src/cpu/cpu_halo_springs.cpp)
 * on CPU ranks against one undivided world, under mpirun on 1-3 ranks: the cases of
 * mpi_springs_cases.c, which gpu_check_mpi runs on CUDA ranks too. */
#include "mpi_springs_cases.h"
#include "mpi_test_world.h"

int main(int argc, char** argv) {
  sph_context* context = NULL;
  mpi_test_init(&argc, &argv, &context);
  mpi_springs_cases(context, 0);
  return mpi_test_finish(context, "mpi_springs");
}
