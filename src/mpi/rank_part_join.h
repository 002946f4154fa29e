// SPDX-License-Identifier: MIT
// A distributed world's checkpoint loaded on another rank count than saved it
// (sph_mpi_world_load_file, _restore_file): each new rank takes the particles of a block of the
// saved rank files, joined into one rank's part. The particles keep their sort keys, which
// order the next sort on any rank count alike (docs/distributed.md), so the world steps on as
// the saved one would have; the first frame then cuts the slabs anew and migrates.
#pragma once

#include <stdint.h>

#include <vector>

#include "../core/checkpoint.h"

namespace sph {

// The saved rank files [first, last) a rank `rank` of `ranks` takes from a save on `saved`
// ranks: contiguous blocks in rank order, empty for some ranks when there are more ranks than
// files.
struct RankFileBlock {
  uint32_t first = 0;
  uint32_t last = 0;
};
RankFileBlock rank_file_block(uint32_t saved, int rank, int ranks);

// Joins `others` (parts of the same save) into `into`: their particles (every carried array,
// the sort keys) after its own, or instead of them unless keep_own; the last frame's removed
// ids and sink-removal counts likewise; the capacity raised to the particles' count. Throws
// CorruptData for parts of different worlds or a duplicate id, Capacity past max_capacity.
// Springs join as they are (their lists name partners by id); their lowest waiting id is the
// parts' smallest.
void join_rank_parts(CheckpointPart& into, bool keep_own, const std::vector<CheckpointPart>& others);

}  // namespace sph
