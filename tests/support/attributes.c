// SPDX-License-Identifier: MIT
/* Reading one attribute of every particle, in storage order or by particle id. */
#include <stdlib.h>
#include <string.h>

#include "support.h"

size_t support_attribute_size(sph_attribute attribute) {
  return (attribute == SPH_ATTRIBUTE_POSITION || attribute == SPH_ATTRIBUTE_VELOCITY) ? 12 : 4;
}

sph_result support_read(const sph_world* world, sph_attribute attribute, void* out, uint32_t max,
                        uint32_t* count) {
  const size_t size = support_attribute_size(attribute);
  uint32_t n = 0;
  sph_result r = sph_world_get_particle_count(world, &n);
  *count = 0;
  if (r != SPH_OK) return r;
  /* An empty world copies nothing (and out may then be a NULL or empty buffer). */
  if (n > 0 &&
      (r = sph_world_copy_attribute(world, attribute, out, (uint64_t)size * max, 0, 0, n, NULL)) != SPH_OK)
    return r;
  *count = n;
  return SPH_OK;
}

sph_result support_read_by_id(const sph_world* world, sph_attribute attribute, void* out, uint32_t max,
                              uint32_t* count) {
  const size_t size = support_attribute_size(attribute);
  uint32_t n = 0, i;
  unsigned char* raw;
  uint32_t* ids;
  sph_result r = sph_world_get_particle_count(world, &n);
  *count = 0;
  if (r != SPH_OK) return r;
  raw = (unsigned char*)malloc(size * ((size_t)n + 1));
  ids = (uint32_t*)malloc(sizeof(uint32_t) * ((size_t)n + 1));
  if (raw == NULL || ids == NULL) {
    r = SPH_ERROR_OUT_OF_HOST_MEMORY;
  } else if (n > 0) {
    r = sph_world_copy_attribute(world, SPH_ATTRIBUTE_ID, ids, sizeof(uint32_t) * (uint64_t)n, 0, 0, n, NULL);
    if (r == SPH_OK) r = sph_world_copy_attribute(world, attribute, raw, (uint64_t)size * n, 0, 0, n, NULL);
    for (i = 0; r == SPH_OK && i < n; ++i)
      if (ids[i] >= n || ids[i] >= max) r = SPH_ERROR_INVALID_ARGUMENT;
    for (i = 0; r == SPH_OK && i < n; ++i) memcpy((unsigned char*)out + size * ids[i], raw + size * i, size);
  }
  free(raw);
  free(ids);
  if (r == SPH_OK) *count = n;
  return r;
}

static sph_result copy_new(const sph_world* world, sph_attribute attribute, int by_id, void** out,
                           uint32_t* count) {
  const size_t size = support_attribute_size(attribute);
  uint32_t n = 0;
  void* buffer;
  sph_result r = sph_world_get_particle_count(world, &n);
  *out = NULL;
  *count = 0;
  if (r != SPH_OK) return r;
  buffer = calloc((size_t)n + 1, size);
  if (buffer == NULL) return SPH_ERROR_OUT_OF_HOST_MEMORY;
  r = by_id ? support_read_by_id(world, attribute, buffer, n, count)
            : support_read(world, attribute, buffer, n, count);
  if (r != SPH_OK) {
    free(buffer);
    return r;
  }
  *out = buffer;
  return SPH_OK;
}

sph_result support_copy(const sph_world* world, sph_attribute attribute, void** out, uint32_t* count) {
  return copy_new(world, attribute, 0, out, count);
}

sph_result support_copy_by_id(const sph_world* world, sph_attribute attribute, void** out, uint32_t* count) {
  return copy_new(world, attribute, 1, out, count);
}

sph_result support_kinetic_energy(const sph_world* world, float mass, double* energy) {
  float* v = NULL;
  uint32_t n = 0;
  double e = 0.0;
  const sph_result r = support_copy_by_id(world, SPH_ATTRIBUTE_VELOCITY, (void**)&v, &n);
  if (r != SPH_OK) return r;
  for (uint32_t i = 0; i < 3 * n; ++i) e += 0.5 * mass * (double)v[i] * v[i];
  free(v);
  *energy = e;
  return SPH_OK;
}
