// SPDX-License-Identifier: MIT
#include "validation_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int validation_full(void) {
  const char* v = getenv("SPH_VALIDATION_FULL");
  return v != NULL && strcmp(v, "1") == 0;
}

const char* validation_output_dir(void) {
  const char* v = getenv("SPH_VALIDATION_OUT");
  return (v != NULL && v[0] != '\0') ? v : NULL;
}

FILE* validation_open_output(const char* name) {
  char path[4096];
  const char* dir = validation_output_dir();
  if (dir == NULL) return NULL;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return fopen(path, "w");
}
