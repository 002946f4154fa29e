// SPDX-License-Identifier: MIT
// Checkpoints: a world's whole state as a self-contained, versioned and checksummed byte
// string (docs/checkpoint.md has the layout). The C layer adds files and handles.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <functional>
#include <memory>
#include <vector>

#include "byte_io.h"
#include "particle_snapshot.h"
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

// The world's definition section of a checkpoint (the capacities, the methods, the lattice and the
// fluid; layout: checkpoint_format.h).
void write_config(ByteWriter& w, const WorldConfig& c);

// Serialises a world. Throws on allocation or backend (device) failures, and Unsupported for a
// distributed world unless origin.rank_part.
HostVector<uint8_t> write_checkpoint(const World& world, const CheckpointOrigin& origin);

using BackendMaker = std::function<std::unique_ptr<Backend>(const WorldConfig&)>;

// What the rank parts of one distributed save hold each of their own (the sections before the
// scene, which every part holds alike): a load on another rank count (src/mpi) joins the
// particles of several parts into one rank's world.
struct CheckpointPart {
  WorldConfig config;  // capacity: the rank's own
  uint32_t next_id = 0;
  uint16_t id_tag = 0;  // the world tag of the scene's ids (World::id_tag)
  double simulated_time = 0.0;
  ParticleSnapshot particles;  // with their sort keys (kArrayDistributedSortKey)
  FrameReport report;          // the last frame's, its removed ids the rank's
  HostVector<Event> events;    // the last frame's, sink removals the rank's
};
// Changes a checkpoint's part before the world is built from it (read_checkpoint).
using CheckpointAdjust = std::function<void(CheckpointPart&)>;

// A rank's part, validated as read_checkpoint validates it, up to its particles (the scene
// sections are left unread: the part's checksum covers them).
CheckpointPart read_checkpoint_part(const uint8_t* data, size_t size);

// Parses and validates a checkpoint completely, then builds a new world on a backend from
// make_backend. Hostile input is safe: every read is bounds-checked, every count is checked
// against the bytes left before anything is allocated. Throws Error(CorruptData) for
// damaged or inconsistent data, Error(VersionMismatch) for another format version.
// With rank_part, the checkpoint must be one rank's part of a distributed world (CorruptData
// otherwise), and make_backend must attach the ranks (its sort keys are a carried array then);
// without, such a part is refused (InvalidArgument: it loads only with its manifest). `adjust`,
// when given, may change the part (its particles, capacity, last frame) before the world is
// built; it validates what it puts there.
std::unique_ptr<World> read_checkpoint(const uint8_t* data, size_t size, const BackendMaker& make_backend,
                                       bool rank_part = false, const CheckpointAdjust& adjust = nullptr);

}  // namespace sph
