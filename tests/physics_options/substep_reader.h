// SPDX-License-Identifier: MIT
// The state the loads' measuring programs (loads_breakdown.cpp, loads_side_wall.cpp) read around
// one substep, by particle id: the positions at its start, and after it the positions, densities
// and pressures (its density pass's, at the start's positions). Each sampled frame must take one
// substep, so the positions read before it are that substep's start; the end of one sampled
// substep is the start of the next, so a run of sampled frames reads the positions once a frame.
#pragma once

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <vector>

#include "sph_c.h"
#include "support.h"

namespace loads_sampling {

class SubstepReader {
 public:
  std::vector<float> start, end, density, pressure;  // by id; 3 floats a particle for positions
  uint32_t count = 0;                                // particles read

  explicit SubstepReader(uint32_t capacity)
      : start(3 * static_cast<size_t>(capacity)), end(start.size()), density(capacity), pressure(capacity) {}

  // Steps one frame of `seconds` with step(seconds), which returns the substeps it took, and when
  // `sampled` reads the substep's start before it (unless the last sampled frame's end is held)
  // and its end, densities and pressures after. Returns false, after a message, when the frame
  // took other than one substep; exits the program when a read fails.
  template <class Step>
  bool frame(const sph_world* world, bool sampled, int index, float seconds, Step&& step) {
    if (sampled && !have_start_) read(world, SPH_ATTRIBUTE_POSITION, start.data(), "read positions");
    const uint32_t took = step(seconds);
    have_start_ = false;
    if (took != 1) {
      fprintf(stderr, "frame %d took %u substeps, not 1: lower the frame time\n", index, took);
      return false;
    }
    if (!sampled) return true;
    read(world, SPH_ATTRIBUTE_POSITION, end.data(), "read positions");
    read(world, SPH_ATTRIBUTE_DENSITY, density.data(), "read densities");
    read(world, SPH_ATTRIBUTE_PRESSURE, pressure.data(), "read pressures");
    return true;
  }

  // After a sampled frame's sums: its end becomes the next substep's start.
  void advance() {
    start.swap(end);
    have_start_ = true;
  }

 private:
  bool have_start_ = false;  // start holds the next substep's start

  void read(const sph_world* world, sph_attribute attribute, float* out, const char* what) {
    const sph_result r =
        support_read_by_id(world, attribute, out, static_cast<uint32_t>(density.size()), &count);
    if (r == SPH_OK) return;
    fprintf(stderr, "%s: %s (%s)\n", what, sph_result_string(r), sph_get_last_error());
    exit(1);
  }
};

}  // namespace loads_sampling
