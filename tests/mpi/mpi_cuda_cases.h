/* SPDX-License-Identifier: MIT */
/* The CUDA rank's DFSPH (Jacobi and conjugate gradients), probes and sinks cases of gpu_check_mpi
 * (tests/mpi/test_mpi_cuda.c runs them; test_mpi_cuda_cases.c says what each checks). */
#pragma once

#include <stdint.h>

#include "sph_c.h"

/* DFSPH's Jacobi solves on the distributed CUDA world against the undivided one (stir 0: the dam
 * break); divergence_solve 0 skips the divergence solve; cap > 0: the density solve's cap, with a
 * bound it never reaches (every solve capped). */
void mpi_cuda_dfsph_case(const char* name, sph_context* cuda, sph_context* cpu, float stir,
                         uint32_t divergence_solve, uint32_t cap);
/* A point probe and a gauge on the stirred column, with `solver`. */
void mpi_cuda_probes_case(const char* name, sph_context* cuda, sph_solver solver);
/* A sink over the stirred column's top, with `solver`. */
void mpi_cuda_sinks_case(const char* name, sph_context* cuda, sph_solver solver);
/* DFSPH's density solve with `linear_solver` (SPH_DFSPH_CONJUGATE_GRADIENTS or SPH_DFSPH_CHEBYSHEV) on
 * CUDA ranks against the same world on one rank, bit for bit; `cap`: the density solve capped there
 * (0: not). */
void mpi_cuda_rank_solver_case(const char* name, sph_context* cuda, uint32_t linear_solver, float stir,
                               uint32_t cap);
