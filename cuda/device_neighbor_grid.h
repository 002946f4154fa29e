// SPDX-License-Identifier: MIT
// The CUDA backend's neighbour structure: each particle's wrapped cell hash, a stable radix
// sort of (hash, index) pairs (CUB), and the dense cell-start table the shared neighbour walk
// reads. The sort is stable over the current order, so the permutation is the CPU backend's.
#pragma once

#include <stdint.h>

#include <cuda_runtime.h>

#include "../src/physics/neighbor_walk.h"
#include "device_array.h"
#include "device_particle_store.h"
#include "frame_state.cuh"

namespace sph {

// What the reorder needs to disarm a crowded table (enqueue_reorder): the table to empty and the
// sorted keys that name the crowded slot's first particle.
struct CrowdGuard {
  uint32_t* cell_start;
  uint32_t entries;  // cell_count + 1
  const uint32_t* sorted_keys;
};

// The table shape of one sort, built on the device: the particles' cell extent, each bound as
// the maximum of an unsigned code (so that a zeroed record is the identity of all six maxima, and
// the order of the blocks' atomicMax calls cannot change it), then the dims fitted to it within
// the table's slots (physics/grid_fit.h).
struct LiveGridShape {
  uint32_t lowest_code[3];   // max over the particles of ~(cell + 2^31): the lowest cell
  uint32_t highest_code[3];  // max over the particles of cell + 2^31; 0: no particle
  GridShape shape;
};

class DeviceNeighborGrid {
 public:
  // scratch: the key/value buffers (capacity entries each). spare/spare_bytes: memory that is
  // free while the sort runs, reused for the sort's temporary storage when large enough.
  // max_per_cell: the crowd cap of one slot (src/core/crowded_cell.h). fit_to_extent: every sort
  // first fits the dims of the table's shape.cell_count slots to the particles' extent (a long
  // flume or a thin slab then folds far fewer cells onto one slot: fewer far candidates in the
  // walks); false keeps `shape` (a distributed rank's grid, whose slot order its halo follows).
  // stream: the world's, where the fitted shape's reset runs (waited for here, so a grid dropped
  // by a failed growth frees no memory a reset still writes).
  DeviceNeighborGrid(const GridShape& shape, uint32_t capacity, uint32_t max_per_cell, SortScratch scratch,
                     void* spare, size_t spare_bytes, cudaStream_t stream, bool fit_to_extent = true);

  // Hashes positions[0, n) and sorts. Afterwards order() gives, for each sorted place, the
  // particle's index before the sort. The buffers order() and sorted_keys() point to are
  // decided here, on the host, and are the same on every call with the same n (so the
  // launches can be captured in a graph). visit (a distributed rank's key order, cuda_halo.cu):
  // the particles are taken in this order, so a slot lists its particles in it; null: storage order.
  void enqueue_sort(const Float4* positions, uint32_t n, FrameState* state, cudaStream_t stream,
                    const uint32_t* visit = nullptr);
  // Fills the dense cell-start table from the sorted keys: every one of cell_count + 1 entries
  // is written once, without clearing the table first. A slot holding more than max_per_cell
  // particles sets FrameState::crowded_key; the reorder that follows then empties the table
  // (crowd_guard) so that no walk of the failing substep visits the pile.
  void enqueue_cell_starts(uint32_t n, FrameState* state, cudaStream_t stream);

  const uint32_t* order() const { return order_; }
  GridView view() const {
    return GridView{shape_, cell_start_.get(), fit_to_extent_ ? &live_.get()->shape : nullptr};
  }
  CrowdGuard crowd_guard() const {
    return CrowdGuard{cell_start_.get(), shape_.cell_count + 1, sorted_keys_};
  }
  uint64_t bytes() const { return cell_start_.bytes() + temp_.bytes() + live_.bytes(); }

 private:
  GridShape shape_;  // the table's slots (cell_count) and, without the fit, its dims
  bool fit_to_extent_;
  DeviceArray<LiveGridShape> live_;  // one record, when fit_to_extent_
  uint32_t capacity_;
  uint32_t max_per_cell_;
  int key_bits_;
  SortScratch scratch_;
  DeviceArray<uint32_t> cell_start_;
  DeviceArray<unsigned char> temp_;  // only when the spare memory is too small
  void* temp_storage_ = nullptr;
  size_t temp_bytes_ = 0;
  const uint32_t* sorted_keys_ = nullptr;
  const uint32_t* order_ = nullptr;
};

}  // namespace sph
