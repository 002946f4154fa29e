/* SPDX-License-Identifier: MIT */
/* Springs across ranks (mpi_springs_cases.c says what each case checks), on the ranks of any
 * backend against the undivided world on the same context: test_mpi_springs.c (CPU) and
 * gpu_check_mpi (CUDA, test_mpi_cuda.c). */
#pragma once

#include <stdint.h>

#include "sph_c.h"

/* Every case and the rank checkpoints on `context`; capacity 0: mpi_test_world_def's (4096; the
 * CUDA ranks take 32768, whose table never folds over the tank: bit for bit with any lanes). */
void mpi_springs_cases(sph_context* context, uint32_t capacity);
