// SPDX-License-Identifier: MIT
/* The backend of the tests' contexts (SPH_TEST_BACKEND) and backends named on a command line; the
 * CUDA contexts' DFSPH walk (SPH_TEST_CUDA_DFSPH_MASKS = on, off or lists: sph_context_def's
 * cuda_dfsph_masks; unset: the library's default), so that scripts/gpu-test can run the DFSPH
 * tests through the neighbour lists as well. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

sph_backend sph_test_backend(void) {
  return support_backend_from_name(sph_test_backend_name(), SPH_BACKEND_AUTO);
}

const char* sph_test_backend_name(void) {
  const char* value = getenv("SPH_TEST_BACKEND");
  if (value == NULL || value[0] == '\0') return "cpu";
  if (strcmp(value, "cpu") != 0 && strcmp(value, "cuda") != 0 && strcmp(value, "auto") != 0) {
    fprintf(stderr, "SPH_TEST_BACKEND=%s: expected cpu, cuda or auto\n", value);
    exit(2);
  }
  return value;
}

uint32_t sph_test_cuda_dfsph_masks(void) {
  const char* value = getenv("SPH_TEST_CUDA_DFSPH_MASKS");
  if (value == NULL || value[0] == '\0' || strcmp(value, "on") == 0) return 0u;
  if (strcmp(value, "off") == 0) return SPH_CUDA_DFSPH_MASKS_OFF;
  if (strcmp(value, "lists") == 0) return SPH_CUDA_DFSPH_NEIGHBOR_LISTS;
  fprintf(stderr, "SPH_TEST_CUDA_DFSPH_MASKS=%s: expected on, off or lists\n", value);
  exit(2);
}

sph_result sph_test_context_def_init(sph_context_def* def) {
  return support_context_def_init(sph_test_backend(), def);
}

sph_result sph_test_context_create(sph_context** out) {
  return support_context_create(sph_test_backend(), out);
}

sph_backend support_backend_from_name(const char* name, sph_backend otherwise) {
  if (name == NULL) return otherwise;
  if (strcmp(name, "cpu") == 0) return SPH_BACKEND_CPU;
  if (strcmp(name, "cuda") == 0) return SPH_BACKEND_CUDA;
  if (strcmp(name, "auto") == 0) return SPH_BACKEND_AUTO;
  return otherwise;
}

sph_result support_context_def_init(sph_backend backend, sph_context_def* def) {
  const sph_result r = sph_context_def_init(def);
  if (r == SPH_OK) {
    def->backend = backend;
    def->cuda_dfsph_masks = sph_test_cuda_dfsph_masks();
  }
  return r;
}

sph_result support_context_create(sph_backend backend, sph_context** out) {
  sph_context_def def;
  const sph_result r = support_context_def_init(backend, &def);
  return r != SPH_OK ? r : sph_context_create(&def, out);
}
