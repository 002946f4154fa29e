// SPDX-License-Identifier: MIT
// The particle section of a checkpoint (PART): every particle's state and carried arrays, and
// the spring lists, each value checked as the reader of the whole file checks the rest
// (checkpoint_reader.cpp), before anything is made from them.
#pragma once

#include <stdint.h>

#include "byte_io.h"
#include "config.h"
#include "particle_snapshot.h"

namespace sph {

// The particles of a world whose config is `config` and whose next id is `next_id`.
ParticleSnapshot read_checkpoint_particles(ByteReader& r, const WorldConfig& config, uint32_t next_id);
// The spring lists (SPH_FEATURE_SPRINGS) into s: every partner an index of another particle,
// every rest length in [0, h], every spring stored at both ends alike.
// partner_ids: a rank's part of a distributed world, whose lists name partners by id (the ends
// of a spring may be on different ranks: src/cpu/cpu_halo_springs.cpp).
void read_checkpoint_springs(ByteReader& r, const WorldConfig& config, uint32_t next_id, bool partner_ids,
                             ParticleSnapshot& s);

}  // namespace sph
