/* SPDX-License-Identifier: MIT */
/* sph_mpi.h as strict C99 and as C++ (the same file, built both ways) with pedantic warnings as
 * errors, without mpi.h; run, it checks that its init functions link from libsph_mpi and fill
 * the defaults (no MPI call: nothing here needs mpirun). */
#include "sph_mpi.h"
#include "sph_mpi.h" /* the include guard holds */

#include <stdio.h>

int main(void) {
  sph_mpi_world_def def;
  sph_mpi_counts counts;
  if (sph_mpi_world_def_init(&def) != SPH_OK || def.struct_size != sizeof def ||
      def.rebalance_threshold_percent != 0) {
    printf("sph_mpi_world_def_init: %s\n", sph_get_last_error());
    return 1;
  }
  if (sph_mpi_counts_init(&counts) != SPH_OK || counts.struct_size != sizeof counts) {
    printf("sph_mpi_counts_init: %s\n", sph_get_last_error());
    return 1;
  }
  /* Not a distributed world: refused, not crashed. */
  if (sph_mpi_world_get_counts(NULL, &counts) != SPH_ERROR_INVALID_HANDLE) {
    printf("sph_mpi_world_get_counts(NULL) was not INVALID_HANDLE\n");
    return 1;
  }
  return 0;
}
