// SPDX-License-Identifier: MIT
#include "cpu_neighbor_grid.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <omp.h>

#include "../core/grid_layout.h"
#include "../core/status.h"

namespace sph {

uint32_t max_particles_per_cell(float particle_spacing, float kernel_radius) {
  const double per_axis = static_cast<double>(kernel_radius) / static_cast<double>(particle_spacing);
  const double rest = std::sqrt(2.0) * per_axis * per_axis * per_axis;
  const double cap = std::ceil(kMaxCellDensityRatio * rest);
  return static_cast<uint32_t>(std::min(std::max(cap, static_cast<double>(kMinCellCap)), 1e9));
}

// The cells the particles span, then the table for them (make_grid_shape_for_extent). Exact
// (a min and max of integers), so the shape is the same for the same positions on any thread
// count.
void CpuNeighborGrid::choose_shape(const Float4* positions, uint32_t n, unsigned workers) {
  int32_t lo_x = 0, lo_y = 0, lo_z = 0, hi_x = 0, hi_y = 0, hi_z = 0;
  if (n > 0) {
    lo_x = lo_y = lo_z = INT32_MAX;
    hi_x = hi_y = hi_z = INT32_MIN;
  }
  const int count = static_cast<int>(n);
  const float inv = inv_cell_size_;
#pragma omp parallel for num_threads(n >= kParallelMinimum ? workers : 1u) schedule(static) \
    reduction(min                                                                           \
              : lo_x, lo_y, lo_z) reduction(max                                             \
                                            : hi_x, hi_y, hi_z)
  for (int i = 0; i < count; ++i) {
    const int32_t x = cell_coordinate(positions[i].x, inv), y = cell_coordinate(positions[i].y, inv),
                  z = cell_coordinate(positions[i].z, inv);
    lo_x = std::min(lo_x, x);
    lo_y = std::min(lo_y, y);
    lo_z = std::min(lo_z, z);
    hi_x = std::max(hi_x, x);
    hi_y = std::max(hi_y, y);
    hi_z = std::max(hi_z, z);
  }
  shape_ =
      make_grid_shape_for_extent(kernel_radius_, CellCoord{lo_x, lo_y, lo_z}, CellCoord{hi_x, hi_y, hi_z}, n);
}

void CpuNeighborGrid::refuse_crowded_slot(const Float4* positions, uint32_t n, uint32_t slot,
                                          uint32_t held) const {
  Vec3 where{0.0f, 0.0f, 0.0f};
  for (uint32_t i = 0; i < n; ++i)
    if (hashes_[i] == slot) {
      where = xyz(positions[i]);
      break;
    }
  throw Error(Status::Capacity,
              "neighbour grid: " + std::to_string(held) + " particles share one cell (near (" +
                  std::to_string(where.x) + ", " + std::to_string(where.y) + ", " + std::to_string(where.z) +
                  ")); at most " + std::to_string(max_per_cell_) +
                  " may (64 times the rest density), so the step was refused and rolled back: "
                  "remove or spread the piled-up particles");
}

// A stable counting sort on the worker team. The particles are cut into one contiguous block per
// worker. Each worker hashes its block and counts it into its own row of block_counts_ (one slot
// per cell); one worker turns the rows into where each block's run of each cell starts, in cell
// order and then block order (the cell-start table is the first block's start); each worker
// scatters its block from its own starts, in particle order. Within a cell the particles of block
// 0 come first, then those of block 1, each block in particle order: exactly the order of the
// one-pass stable sort, whatever the number of workers. The workers meet twice (after the counts,
// after the starts): on a machine whose cores are shared, every meeting can cost a time slice.
void CpuNeighborGrid::build(const Float4* positions, uint32_t n, unsigned workers) {
  choose_shape(positions, n, workers);
  const unsigned team = n >= kParallelMinimum ? std::min(std::max(workers, 1u), kMaxSortWorkers) : 1u;
  const size_t cells = shape_.cell_count;
  hashes_.resize(n);
  order_.resize(n);
  cell_start_.resize(cells + 1);
  block_counts_.resize(cells * team);  // (every slot is written before it is read)
  const GridShape shape = shape_;
  const uint32_t cap = max_per_cell_;
  uint32_t crowded = UINT32_MAX;  // the lowest slot holding more than the cap
#pragma omp parallel num_threads(team)
  {
    // The team may be smaller than asked for: blocks follow the team that runs.
    const unsigned blocks = static_cast<unsigned>(omp_get_num_threads());
    const unsigned b = static_cast<unsigned>(omp_get_thread_num());
    const uint32_t first = static_cast<uint32_t>(static_cast<uint64_t>(n) * b / blocks);
    const uint32_t last = static_cast<uint32_t>(static_cast<uint64_t>(n) * (b + 1) / blocks);
    uint32_t* counts = block_counts_.data() + cells * b;
    std::fill(counts, counts + cells, 0u);
    for (uint32_t i = first; i < last; ++i) {
      const uint32_t h = cell_hash_of_position(shape, xyz(positions[i]));
      hashes_[i] = h;
      ++counts[h];
    }
#pragma omp barrier
#pragma omp single
    {
      uint32_t running = 0;
      for (size_t c = 0; c < cells; ++c) {
        cell_start_[c] = running;
        const uint32_t before = running;
        for (unsigned k = 0; k < blocks; ++k) {
          uint32_t& slot = block_counts_[cells * k + c];
          const uint32_t count = slot;
          slot = running;
          running += count;
        }
        if (running - before > cap && crowded == UINT32_MAX) crowded = static_cast<uint32_t>(c);
      }
      cell_start_[cells] = running;
    }  // (the single's barrier publishes the starts and `crowded`)
    if (crowded == UINT32_MAX)
      for (uint32_t i = first; i < last; ++i) order_[counts[hashes_[i]]++] = i;
  }
  if (crowded != UINT32_MAX)
    refuse_crowded_slot(positions, n, crowded, cell_start_[crowded + 1] - cell_start_[crowded]);
}

}  // namespace sph
