// SPDX-License-Identifier: MIT
// Everything the per-particle physics needs, passed by value to every kernel and loop
// (no globals: two worlds in one process, even on two devices, keep their own): the part every
// method reads (fluid_base.h) and each method's own constants (methods.h).
#pragma once

#include "fluid_base.h"
#include "methods.h"

namespace sph {

struct FluidConstants : FluidBase {
  MethodConstants methods;
};

}  // namespace sph
