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
