// SPDX-License-Identifier: MIT
// The scene sections of a checkpoint (SDF assets, colliders, sources, sinks, force fields):
// each object is made by the same rules as a caller's (scene_build.h), its slot layout
// restored as saved so ids stay valid.
#pragma once

#include <memory>
#include <vector>

#include "byte_io.h"
#include "config.h"
#include "host_memory.h"
#include "scene_objects.h"
#include "sdf_asset.h"
#include "slot_map.h"

namespace sph {

using CheckpointAssets = HostVector<std::shared_ptr<SdfAsset>>;

CheckpointAssets read_checkpoint_assets(ByteReader& r);
// version: the file's (load points from kFirstProbeVersion on).
SlotTable<Collider> read_checkpoint_colliders(ByteReader& r, const CheckpointAssets& assets,
                                              uint32_t version);
// version: the file's (a rate budget may be a debt from kFirstSourceDebtVersion on).
SlotTable<Source> read_checkpoint_sources(ByteReader& r, const CheckpointAssets& assets,
                                          const WorldConfig& config, uint32_t version);
SlotTable<Sink> read_checkpoint_sinks(ByteReader& r, const CheckpointAssets& assets);
SlotTable<ForceField> read_checkpoint_force_fields(ByteReader& r, const CheckpointAssets& assets);
// The probes as World::add_probe would have made them; readings cleared.
SlotTable<Probe> read_checkpoint_probes(ByteReader& r, uint32_t version);

}  // namespace sph
