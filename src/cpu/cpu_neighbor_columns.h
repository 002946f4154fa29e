// SPDX-License-Identifier: MIT
// Columns of the sorted particle records, one float array per attribute, for the SIMD passes
// (cpu_simd_passes.h): a run of candidates, contiguous after the sort, is then one unaligned
// load per attribute for 16 lanes, in candidate order, with no transposition. They are copies:
// the Float4 records (position_, velocity_, ...) stay what the rest of the backend reads. Each
// column has kLanePadding extra elements so a load that starts at the last particle stays in
// bounds (its lanes past the end are masked off).
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <vector>

#include "../core/host_memory.h"
#include "../physics/float4_types.h"

namespace sph {

constexpr size_t kLanePadding = 16;

// What the SIMD passes read; a pointer is null when its column is not kept.
struct NeighborColumns {
  const float* x;
  const float* y;
  const float* z;
  const float* vx;  // velocities; DFSPH: those its solve's last velocity update wrote
  const float* vy;
  const float* vz;
  const float* pressure;        // p, after the density pass; DFSPH: its solve's k = p / rho^2
  const float* inv_density;     // 1 / rho, after the density pass
  const float* neighbor_count;  // n (exact in a float), after the density pass; Clavet only
  const float* normal_x;        // colour-field normal and its length; surface tension only
  const float* normal_y;
  const float* normal_z;
  const float* normal_length;
};

class CpuNeighborColumns {
 public:
  // Keeps the count and normal columns only where a pass reads them.
  CpuNeighborColumns(bool keep_counts, bool keep_normals) : counts_(keep_counts), normals_(keep_normals) {}

  // Sizes every column for n particles (before the sort's reorder), then copies positions and
  // velocities of particles [first, last) (after it, on the worker that reordered them).
  void resize(uint32_t n);
  void copy_state(const Float4* positions, const Float4* velocities, size_t first, size_t last) {
    for (size_t i = first; i < last; ++i) {
      x_[i] = positions[i].x;
      y_[i] = positions[i].y;
      z_[i] = positions[i].z;
      vx_[i] = velocities[i].x;
      vy_[i] = velocities[i].y;
      vz_[i] = velocities[i].z;
    }
  }

  // One particle's results of the density pass, and of the colour-field pass.
  void set_density(uint32_t i, float pressure, float inv_density) {
    pressure_[i] = pressure;
    inv_density_[i] = inv_density;
  }
  void set_neighbor_count(uint32_t i, uint32_t count) {
    if (counts_) neighbor_count_[i] = static_cast<float>(count);
  }
  // DFSPH's solves (src/cpu/cpu_dfsph_solver.cpp): the velocity a velocity update gave particle
  // i (the rate passes read it for neighbours), and the pressures k = p / rho^2 of the iteration,
  // kept in the pressure column (a weakly compressible p is not used by DFSPH).
  void set_velocity(uint32_t i, Vec3 v) {
    vx_[i] = v.x;
    vy_[i] = v.y;
    vz_[i] = v.z;
  }
  float* dfsph_step() { return pressure_.data(); }
  void set_normal(uint32_t i, const Float4& n) {
    normal_x_[i] = n.x;
    normal_y_[i] = n.y;
    normal_z_[i] = n.z;
    normal_length_[i] = n.w;
  }

  NeighborColumns view() const;
  size_t bytes() const;

 private:
  bool counts_;
  bool normals_;
  HostVector<float> x_, y_, z_, vx_, vy_, vz_, pressure_, inv_density_, neighbor_count_;
  HostVector<float> normal_x_, normal_y_, normal_z_, normal_length_;
};

}  // namespace sph
