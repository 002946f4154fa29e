// The CPU backend's neighbour structure: a stable counting sort of particles by wrapped cell
// hash, which yields the permutation and the dense cell-start table in one pass.
#pragma once

#include <stdint.h>

#include <vector>

#include "../physics/float4_types.h"
#include "../physics/neighbor_walk.h"

namespace sph {

// Below this many particles the CPU backend's loops run on one thread.
constexpr uint32_t kParallelMinimum = 4096;

// The CPU backend's parallel loops hand out particles in chunks of this many to whichever thread
// is free (schedule(dynamic)): a static split makes every pass wait for its slowest thread, and on
// a machine where another process holds a core that thread is off the core for whole time
// slices. Each particle's result depends on nothing but its index, so the split changes no bit.
// 1024 particles are about 0.1-0.3 ms of a gather, large against the cost of taking a chunk.
constexpr int kParticleChunk = 1024;

class CpuNeighborGrid {
 public:
  explicit CpuNeighborGrid(const GridShape& shape) : shape_(shape) {}

  // Hashes positions[0..n) and computes the stable order by cell (order()[i] is the old index
  // of the particle that goes to place i). Fills the cell-start table for the sorted order.
  void build(const Float4* positions, uint32_t n, unsigned workers);

  const std::vector<uint32_t>& order() const { return order_; }
  GridView view() const { return GridView{shape_, cell_start_.data()}; }
  const GridShape& shape() const { return shape_; }
  size_t bytes() const {
    return (hashes_.capacity() + order_.capacity() + cell_start_.capacity() + cursor_.capacity()) *
           sizeof(uint32_t);
  }

 private:
  GridShape shape_;
  std::vector<uint32_t> hashes_;
  std::vector<uint32_t> order_;
  std::vector<uint32_t> cell_start_;
  std::vector<uint32_t> cursor_;
};

}  // namespace sph
