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
};

// Serialises a world. Throws only on allocation or backend (device) failures.
HostVector<uint8_t> write_checkpoint(const World& world, const CheckpointOrigin& origin);

using BackendMaker = std::function<std::unique_ptr<Backend>(const WorldConfig&)>;

// Parses and validates a checkpoint completely, then builds a new world on a backend from
// make_backend. Hostile input is safe: every read is bounds-checked, every count is checked
// against the bytes left before anything is allocated. Throws Error(CorruptData) for
// damaged or inconsistent data, Error(VersionMismatch) for another format version.
std::unique_ptr<World> read_checkpoint(const uint8_t* data, size_t size, const BackendMaker& make_backend);

}  // namespace sph
