// SPDX-License-Identifier: MIT
// header_mpi.c compiled as C++ (sph_mpi.h in C++ with pedantic warnings as errors).
#include "header_mpi.c"
