// SPDX-License-Identifier: MIT
// The identity permutation on the device, for the halo tables' sorts.
#pragma once

#include <stdint.h>

namespace sph {

// Writes v[i] = i for i < n (default stream; a failed launch throws as check_launch does).
void fill_iota(uint32_t* v, uint32_t n);

}  // namespace sph
