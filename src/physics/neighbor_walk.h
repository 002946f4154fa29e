// SPDX-License-Identifier: MIT
// Visits every particle in the 27 cells around a position, in a fixed order, using a dense
// cell-start table: cell_start[c] is the index of the first particle whose hash is >= c, and
// cell_start[cell_count] is the particle count. Because the table is dense, the three cells of
// one x-row are a single contiguous index range unless the row wraps around the table.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include "float4_types.h"
#include "grid_hash.h"
#include "host_device.h"

namespace sph {

struct GridView {
  GridShape shape;
  const uint32_t* cell_start;  // cell_count + 1 entries
  // The CUDA backend's table shape of this sort, fitted on the device to the particles' extent
  // (cuda/device_neighbor_grid.h); null: `shape` is the table's. Device code only.
  const GridShape* live_shape = nullptr;
};

// The shape the table was filled with.
SPH_HD GridShape shape_of(const GridView& grid) {
#if defined(__CUDA_ARCH__)
  if (grid.live_shape) return *grid.live_shape;
#endif
  return grid.shape;
}

// Calls visit_range(begin, end) for each run of consecutive particle indices in the 3x3x3
// block of cells around p: one run per row of three cells (two where the row wraps around the
// table), nine rows in a fixed order. Candidates are not filtered by distance: the caller
// tests r < h (wrapped slots can hold far particles).
template <class VisitRange>
SPH_HD void for_each_neighbor_range(const GridView& grid, Vec3 p, VisitRange&& visit_range) {
  const GridShape g = shape_of(grid);
  const CellCoord c = cell_of(g, p);
  // One remainder per axis; the neighbouring slots follow by stepping (each n >= 3).
  const int32_t cx = shifted_index(c.x, g.nx, g.sx), cy = shifted_index(c.y, g.ny, g.sy),
                cz = shifted_index(c.z, g.nz, g.sz);
  const int32_t x_lo = wrap_step(cx, -1, g.nx);
  const int32_t x_hi = wrap_step(cx, 1, g.nx);
  for (int32_t dz = -1; dz <= 1; ++dz) {
    const int32_t wz = wrap_step(cz, dz, g.nz);
    for (int32_t dy = -1; dy <= 1; ++dy) {
      const int32_t wy = wrap_step(cy, dy, g.ny);
      const uint32_t row = hash_wrapped(g, 0, wy, wz);
      if (x_lo < x_hi) {
        visit_range(grid.cell_start[row + static_cast<uint32_t>(x_lo)],
                    grid.cell_start[row + static_cast<uint32_t>(x_hi) + 1u]);
      } else {
        // The row wraps: [x_lo, nx) then [0, x_hi].
        visit_range(grid.cell_start[row + static_cast<uint32_t>(x_lo)],
                    grid.cell_start[row + static_cast<uint32_t>(g.nx)]);
        visit_range(grid.cell_start[row], grid.cell_start[row + static_cast<uint32_t>(x_hi) + 1u]);
      }
    }
  }
}

// Calls visit(j) for each particle j in the 3x3x3 block of cells around p, in the order of
// for_each_neighbor_range.
template <class Visit>
SPH_HD void for_each_neighbor_candidate(const GridView& grid, Vec3 p, Visit&& visit) {
  for_each_neighbor_range(grid, p, [&](uint32_t begin, uint32_t end) {
    SPH_UNROLL(4)
    for (uint32_t j = begin; j < end; ++j) visit(j);
  });
}

// A particle's candidate mask (CUDA DFSPH, issue 18): bit k of the mask says whether the k-th
// candidate of for_each_neighbor_range's walk (in its order, from 0) is a neighbour. Positions do
// not change between DFSPH's density pass and the end of its solves, so the pass that walks every
// candidate once can record them, and the solves' many passes visit only the set bits
// (for_each_masked_neighbor). Twelve words: bits 0-382 for candidates 0-382, bit 383 (the last
// word's top bit) marks a particle with more candidates than that, whose passes walk all of them.
// Why 383 and not 255: on an FCC lattice at rest at the default radius (1.8 spacings) the 27
// cells of 16 % of the particles hold 256-259 candidates (45 % at a 3 % closer spacing), all the
// particles of a cell alike, and a warp waits for its slowest lane's full walk; 383 holds the
// lattice at rest and at a 5 % closer spacing (host counts, docs/cuda.md).
constexpr uint32_t kNeighborMaskWords = 12;
constexpr uint32_t kNeighborMaskCandidates = 32u * kNeighborMaskWords - 1u;  // 383
constexpr uint32_t kNeighborMaskOverflow = 0x80000000u;                      // in the last word
// The neighbour lists' slots (ListedCandidates, below, says why 63).
constexpr uint32_t kNeighborListSlots = 63;
constexpr uint32_t kNeighborListRows = kNeighborListSlots + 1;  // uint32 a particle, the count's included

// The index of the lowest set bit of x != 0.
SPH_HD uint32_t lowest_set_bit(uint32_t x) {
#if defined(__CUDA_ARCH__)
  return static_cast<uint32_t>(__ffs(static_cast<int>(x)) - 1);
#elif defined(__GNUC__) || defined(__clang__)
  return static_cast<uint32_t>(__builtin_ctz(x));
#else
  uint32_t b = 0;
  while (!(x & 1u)) x >>= 1, ++b;
  return b;
#endif
}

// Writes one particle's mask as a walk goes: add(keep, j) once per candidate j, in the walk's
// order, then finish(). out: the particle's kNeighborMaskWords words (all of them written), or
// null: a world without masks, whose density pass runs this same code and stores nothing. (One
// instantiation of the pass for both: a second one, compiled apart, may contract its arithmetic
// into other fused multiply-adds and give other bits; with and without masks must be the same.)
// list: with neighbour lists (below), the world's lists, into which the same walk writes particle
// `particle`'s list as it records the mask: slot 0 and the visits of for_each_masked_neighbor over
// this mask, in its order (what write_neighbor_list writes from the finished mask, without a second
// walk of the 27 cells); null without lists.
struct NeighborMaskWriter {
  uint32_t* out;
  uint32_t* list = nullptr;  // the lists (slot-major, ListedCandidates), or null
  uint32_t stride = 0;       // the lists' capacity
  uint32_t particle = 0;     // whose list
  uint32_t count = 0;        // candidates so far
  uint32_t word = 0;         // the bits of the word being filled
  uint32_t visits = 0;       // with a list: the bits set so far (the masked walk's visits)

  SPH_HD void add(bool keep, uint32_t j) {
    if (keep && count < kNeighborMaskCandidates) {
      word |= 1u << (count & 31u);
      if (list && ++visits <= kNeighborListSlots) list[static_cast<size_t>(visits) * stride + particle] = j;
    }
    ++count;
    if ((count & 31u) == 0u && count <= 32u * kNeighborMaskWords) {
      if (out) out[(count >> 5) - 1u] = word;
      word = 0u;
    }
  }
  SPH_HD void finish() const {
    // An overflowed mask (its passes walk every candidate) gets a count past the slots; the slots
    // written before the overflow showed are never read.
    if (list) list[particle] = count > kNeighborMaskCandidates ? kNeighborListSlots + 1u : visits;
    if (!out) return;
    if (count > kNeighborMaskCandidates) {
      out[kNeighborMaskWords - 1u] = kNeighborMaskOverflow;  // the other words are not read
      return;
    }
    uint32_t w = count >> 5;  // the words written so far (count <= 383: at most 11)
    if (count & 31u) out[w++] = word;
    for (; w < kNeighborMaskWords; ++w) out[w] = 0u;
  }
};

// Calls visit(j) for the candidates of for_each_neighbor_candidate (same rows, same order) whose
// bit is set in mask (NeighborMaskWriter's, for this particle's position and the same table);
// for every candidate where the mask overflowed or is null. One loop for all three, so that a
// kernel holds one copy of the pass's body (registers, code size).
template <class Visit>
SPH_HD void for_each_masked_neighbor(const GridView& grid, Vec3 p, const uint32_t* mask, Visit&& visit) {
  const bool all = !mask || (mask[kNeighborMaskWords - 1u] & kNeighborMaskOverflow);
  uint32_t k = 0;  // the walk index of the run's first candidate (below 383 unless `all`)
  for_each_neighbor_range(grid, p, [&](uint32_t begin, uint32_t end) {
    const uint32_t last = k + (end - begin);
    // The run's bits, at most 32 at a time (a run can start and end inside a word).
    for (uint32_t first = k; first < last;) {
      const uint32_t shift = first & 31u;
      const uint32_t take = (32u - shift < last - first) ? 32u - shift : last - first;
      uint32_t bits = all ? 0xffffffffu : mask[first >> 5] >> shift;
      if (take < 32u) bits &= (1u << take) - 1u;
      const uint32_t j0 = begin + (first - k);
      while (bits) {
        visit(j0 + lowest_set_bit(bits));
        bits &= bits - 1u;
      }
      first += take;
    }
    k = last;
  });
}

// The candidates a neighbour pass visits: every candidate of the 27 cells (the default, both
// backends), or, with masks (CUDA DFSPH's solves: kNeighborMaskWords words per particle, written
// by the density pass), those of particle i's mask (every candidate, through the same loop, where
// masks is null), or, with lists (ListedCandidates below), those of particle i's list. The passes
// keep their own r < h test on what they visit, so every walk gives the same terms in the same
// order.
struct AllCandidates {
  template <class Visit>
  SPH_HD void operator()(const GridView& grid, Vec3 p, uint32_t, Visit&& visit) const {
    for_each_neighbor_candidate(grid, p, visit);
  }
};
struct MaskedCandidates {
  const uint32_t* masks;  // null: every candidate
  template <class Visit>
  SPH_HD void operator()(const GridView& grid, Vec3 p, uint32_t i, Visit&& visit) const {
    for_each_masked_neighbor(grid, p, masks ? masks + static_cast<size_t>(i) * kNeighborMaskWords : nullptr,
                             visit);
  }
};

// DFSPH's neighbour lists (CUDA, sph_context_def.cuda_dfsph_masks = SPH_CUDA_DFSPH_NEIGHBOR_LISTS):
// the masked walk's visits written out once a substep, so that the solves' many passes loop over
// a particle's own short list instead of the 27 cells' runs, whose lengths and bits differ from
// lane to lane of a warp (session 16's ncu: about 11 of 32 lanes active in the masked passes).
// Slot-major, so that a warp's 32 particles read one slot in one coalesced line: entry s of
// particle i at list[s * stride + i], stride the world's capacity; slot 0 holds the count and
// slots 1..count the indices, in the masked walk's order (the same terms in the same order: the
// same bits). A particle with more than kNeighborListSlots visits, or an overflowed mask (which
// visits every candidate), gets a count past the slots and walks its mask. 64 slots (256 B a
// particle): at the default radius a particle at rest has about 35 neighbours (the mask's visits
// add those just past h), a compressed one rarely 60.
// One caveat: a kernel holds two inlined copies of its pass's body (the list's loop and the
// mask's), and the same bits need both compiled to the same arithmetic; gpu_check_dfsph_masks is
// what shows it for a compiler and an architecture (nvcc 13, sm_90, session 27).

// Writes particle i's list from its mask (for_each_masked_neighbor's visits, in order); slot 0
// gets the count, or, for an overflowed or null mask, kNeighborListSlots + 1 without a walk. The
// lists' definition: the CUDA density pass writes the same list while it records the mask
// (NeighborMaskWriter's list), and tests/unit/test_neighbor_mask.cpp holds the two equal.
SPH_HD void write_neighbor_list(const GridView& grid, Vec3 p, const uint32_t* mask, uint32_t* list,
                                uint32_t stride, uint32_t i) {
  if (!mask || (mask[kNeighborMaskWords - 1u] & kNeighborMaskOverflow)) {
    list[i] = kNeighborListSlots + 1u;
    return;
  }
  uint32_t count = 0;
  for_each_masked_neighbor(grid, p, mask, [&](uint32_t j) {
    ++count;
    if (count <= kNeighborListSlots) list[static_cast<size_t>(count) * stride + i] = j;
  });
  list[i] = count;
}

// The walk of the solves' passes with lists: particle i's list where it holds every visit, its
// masked walk otherwise (or where the world has no lists: lists null).
struct ListedCandidates {
  const uint32_t* masks;  // null: every candidate
  const uint32_t* lists;  // null: the masked walk for every particle
  uint32_t stride;        // the lists' capacity
  template <class Visit>
  SPH_HD void operator()(const GridView& grid, Vec3 p, uint32_t i, Visit&& visit) const {
    const uint32_t count = lists ? lists[i] : kNeighborListSlots + 1u;
    if (count <= kNeighborListSlots) {
      // (Unrolled by 4 it measured the same at 1M, session 27: the loop waits on its gathers.)
      const uint32_t* entry = lists + i;
      for (uint32_t s = 1; s <= count; ++s) visit(entry[static_cast<size_t>(s) * stride]);
      return;
    }
    MaskedCandidates{masks}(grid, p, i, visit);
  }
};

}  // namespace sph
