// SPDX-License-Identifier: MIT
// What the C layer of include/sph_mpi.h shares between its files.
#pragma once

#include <memory>

#include "../capi/handles.h"
#include "../core/rank_agreement.h"
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

// COLLECTIVE. Registers each rank's new world under an agreement and returns its handle: a rank
// that fails to register its world takes the others' back out of the registry (they are deleted),
// so no rank keeps a world the others do not have.
inline sph_world* publish_on_every_rank(const RankTransport& ranks, std::unique_ptr<sph_world> world) {
  sph_world* handle = nullptr;
  try {
    agreed(ranks, [&] { handle = publish_world(std::move(world)); });
  } catch (...) {
    if (handle && try_retire_world(handle) == Take::Taken) delete handle;
    throw;
  }
  return handle;
}

}  // namespace sph
