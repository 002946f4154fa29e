#include "test_support.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sph_backend sph_test_backend(void) {
  const char* name = sph_test_backend_name();
  if (strcmp(name, "cpu") == 0) return SPH_BACKEND_CPU;
  if (strcmp(name, "cuda") == 0) return SPH_BACKEND_CUDA;
  return SPH_BACKEND_AUTO;
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

sph_result sph_test_context_def_init(sph_context_def* def) {
  const sph_result r = sph_context_def_init(def);
  if (r == SPH_OK) def->backend = sph_test_backend();
  return r;
}

sph_result sph_test_context_create(sph_context** out) {
  sph_context_def def;
  const sph_result r = sph_test_context_def_init(&def);
  if (r != SPH_OK) return r;
  return sph_context_create(&def, out);
}

double sph_test_random(uint64_t* state) {
  uint64_t x = *state;
  x ^= x >> 12;
  x ^= x << 25;
  x ^= x >> 27;
  *state = x;
  return (double)((x * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}
