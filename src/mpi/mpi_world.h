// SPDX-License-Identifier: MIT
// What the C layer of include/sph_mpi.h shares between its files.
#pragma once

#include "../capi/handles.h"
#include "../core/rank_transport.h"
#include "../core/status.h"

namespace sph {

// The world's ranks (the caller holds its lock); Unsupported for a world of sph_world_create.
inline const RankTransport& ranks_of(const sph_world* world) {
  const RankTransport* t = world->world->backend().rank_transport();
  if (!t)
    throw Error(Status::Unsupported,
                "world: is not a distributed world (make it with sph_mpi_world_create on every rank)");
  return *t;
}

}  // namespace sph
