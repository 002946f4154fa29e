// SPDX-License-Identifier: MIT
// The CPU backend's neighbour structure: a stable counting sort of particles by wrapped cell
// hash, which yields the permutation and the dense cell-start table in one pass. The table is
// sized at every build from the particles' extent and count (core/grid_layout.h), and a build
// that finds more than max_per_cell particles in one slot is refused (docs/reliability.md,
// "What one call may cost").
#pragma once

#include <stdint.h>

#include <vector>

#include "../core/crowded_cell.h"
#include "../physics/float4_types.h"
#include "../physics/neighbor_walk.h"
#include "cpu_parallel.h"

namespace sph {

class CpuNeighborGrid {
 public:
  CpuNeighborGrid(float kernel_radius, uint32_t max_per_cell)
      : inv_cell_size_(1.0f / kernel_radius), kernel_radius_(kernel_radius), max_per_cell_(max_per_cell) {}

  // Hashes positions[0..n) and computes the stable order by cell (order()[i] is the old index
  // of the particle that goes to place i). Fills the cell-start table for the sorted order.
  // Throws Error(Capacity) when a slot holds more than max_per_cell particles (nothing the
  // caller owns has changed: the world's frame rolls back).
  // A distributed world's rank (cpu_halo.cpp) passes the world's shape (`shape`, else it is
  // chosen from these positions) and the order in which the sort takes the particles
  // (`visit`, n indices; else 0 .. n-1): within a slot they keep that order.
  void build(const Float4* positions, uint32_t n, const CpuParallel& parallel,
             const GridShape* shape = nullptr, const uint32_t* visit = nullptr);

  const HostVector<uint32_t>& order() const { return order_; }
  GridView view() const { return GridView{shape_, cell_start_.data()}; }
  const GridShape& shape() const { return shape_; }
  uint32_t max_per_cell() const { return max_per_cell_; }
  size_t bytes() const {
    return (hashes_.capacity() + order_.capacity() + cell_start_.capacity() + cursor_.capacity()) *
           sizeof(uint32_t);
  }

 private:
  void choose_shape(const Float4* positions, uint32_t n, const CpuParallel& parallel);
  void refuse_crowded_slot(const Float4* positions, uint32_t n, uint32_t slot, uint32_t held) const;

  float inv_cell_size_;
  float kernel_radius_;
  uint32_t max_per_cell_;
  GridShape shape_{1.0f, 3, 3, 3, 27};
  HostVector<uint32_t> hashes_;
  HostVector<uint32_t> order_;
  HostVector<uint32_t> cell_start_;
  HostVector<uint32_t> cursor_;
};

}  // namespace sph
