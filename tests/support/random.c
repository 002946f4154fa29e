// SPDX-License-Identifier: MIT
/* xorshift64* (Vigna 2016): a small generator whose sequence is the same on every platform, so
 * that every run builds the same scene. */
#include "support.h"

double support_random(uint64_t* state) {
  uint64_t x = *state;
  x ^= x >> 12;
  x ^= x << 25;
  x ^= x >> 27;
  *state = x;
  return (double)((x * 0x2545F4914F6CDD1Dull) >> 11) * (1.0 / 9007199254740992.0);
}

void support_random_velocities(float* velocities, uint32_t count, double speed, const float* drift,
                               uint64_t* state) {
  for (uint32_t i = 0; i < 3 * count; ++i) {
    /* 2 u - 1 is exact (u has 53 bits), so speed 0.5 gives exactly u - 0.5. */
    const float random = (float)(speed * (2.0 * support_random(state) - 1.0));
    velocities[i] = drift ? drift[i % 3] + random : random;
  }
}

void support_nudge(float* xyz, uint32_t count, uint64_t seed, double amplitude) {
  uint64_t state = seed * 0x9E3779B97F4A7C15ull;
  for (uint32_t i = 0; i < 3 * count; ++i) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    xyz[i] += (float)(((double)(state >> 11) * (1.0 / 9007199254740992.0) * 2.0 - 1.0) * amplitude);
  }
}
