// SPDX-License-Identifier: MIT
// Checkpoints: a world's whole state as a self-contained, versioned and checksummed byte
// string (docs/checkpoint.md has the layout). The C layer adds files and handles.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <functional>
#include <memory>
#include <vector>

#include "world.h"

namespace sph {

// Who wrote a checkpoint (informational: any backend loads any checkpoint).
struct CheckpointOrigin {
  uint32_t backend = 0;          // 1 CPU, 2 CUDA (BackendKind)
  uint32_t library_version = 0;  // SPH_VERSION of the writer
  // One rank's part of a distributed world (sph_mpi.h's files; checkpoint_format.h's
  // kFlagRankPart). A distributed world saves only as such, any other world never.
  bool rank_part = false;
};

// Serialises a world. Throws on allocation or backend (device) failures, and Unsupported for a
// distributed world unless origin.rank_part.
HostVector<uint8_t> write_checkpoint(const World& world, const CheckpointOrigin& origin);

using BackendMaker = std::function<std::unique_ptr<Backend>(const WorldConfig&)>;

// Parses and validates a checkpoint completely, then builds a new world on a backend from
// make_backend. Hostile input is safe: every read is bounds-checked, every count is checked
// against the bytes left before anything is allocated. Throws Error(CorruptData) for
// damaged or inconsistent data, Error(VersionMismatch) for another format version.
// With rank_part, the checkpoint must be one rank's part of a distributed world (CorruptData
// otherwise), and make_backend must attach the ranks (its sort keys are a carried array then);
// without, such a part is refused (InvalidArgument: it loads only with its manifest).
std::unique_ptr<World> read_checkpoint(const uint8_t* data, size_t size, const BackendMaker& make_backend,
                                       bool rank_part = false);

}  // namespace sph
