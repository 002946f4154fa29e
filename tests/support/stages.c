/* SPDX-License-Identifier: MIT */
#include "support.h"

const char* support_stage_name(int stage) {
  static const char* const names[SPH_STAGE_COUNT] = {"hash_sort", "cell_ranges", "density", "forces",
                                                     "integrate", "collide",     "emit",    "other"};
  return stage >= 0 && stage < SPH_STAGE_COUNT ? names[stage] : "?";
}
