// SPDX-License-Identifier: MIT
// The particle section of a checkpoint (checkpoint_particles_reader.h).
#include "checkpoint_particles_reader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "../physics/kernels.h"
#include "checkpoint.h"
#include "checkpoint_fields.h"
#include "checkpoint_format.h"

namespace sph {

using namespace checkpoint;
using namespace checkpoint_read;

ParticleSnapshot read_checkpoint_particles(ByteReader& r, const WorldConfig& config, uint32_t next_id) {
  ParticleSnapshot s;
  const uint32_t n = r.u32();
  zero(r, "reserved");
  s.max_speed = magnitude_max(r, "max speed");
  s.max_acceleration = magnitude_max(r, "max acceleration");
  if (n > config.capacity)
    corrupt(r.what() + ": " + std::to_string(n) + " particles exceed the capacity " +
            std::to_string(config.capacity));
  r.need_elements(n, 2 * sizeof(Float4) + 2 * sizeof(uint32_t), "particles");
  s.position.resize(n);
  s.velocity.resize(n);
  s.id.resize(n);
  s.density.resize(n);
  for (uint32_t i = 0; i < n; ++i) s.position[i] = float4(r, "position of particle", i);
  for (uint32_t i = 0; i < n; ++i) s.velocity[i] = float4(r, "velocity of particle", i);
  for (uint32_t i = 0; i < n; ++i) {
    s.id[i] = r.u32();
    if (s.id[i] >= next_id)
      corrupt(r.what() + ": particle id " + std::to_string(s.id[i]) + " was never issued (next id " +
              std::to_string(next_id) + ")");
  }
  for (uint32_t i = 0; i < n; ++i) s.density[i] = bulk_finite(r, "density of particle", i);
  // Normalised density: the carried factors, positive and finite, or NaN (a particle spawned
  // since its last density pass). A checkpoint written before the factors existed ends here:
  // its particles start fresh.
  if ((config.features & kFeatureNormalizedDensity) && r.remaining() != 0) {
    r.need_elements(n, sizeof(float), "density factors");
    HostVector<float> factors(n);
    for (uint32_t i = 0; i < n; ++i) {
      const float d = r.f32();
      if (!std::isnan(d) && !(d > 0.0f && std::isfinite(d)))
        corrupt(r.what() + ": density factor of particle " + std::to_string(i) + " is " + std::to_string(d) +
                ", not positive and finite");
      factors[i] = d;
    }
    s.set_carried(kArrayDensityFactor, factors);
  }
  // DFSPH: the warm starts of its two solves (finite; the density solve's pressure is never
  // negative). Every DFSPH checkpoint has them (DFSPH came with version 3).
  if (config.solver == Solver::Dfsph) {
    r.need_elements(n, 2 * sizeof(float), "DFSPH warm starts");
    HostVector<float> pressure(n), divergence(n);
    for (uint32_t i = 0; i < n; ++i) {
      pressure[i] = bulk_finite(r, "DFSPH pressure of particle", i);
      if (pressure[i] < 0.0f)
        corrupt(r.what() + ": DFSPH pressure of particle " + std::to_string(i) + " is negative");
    }
    for (uint32_t i = 0; i < n; ++i)
      divergence[i] = bulk_finite(r, "DFSPH divergence pressure of particle", i);
    s.set_carried(kArrayDfsphPressure, pressure);
    s.set_carried(kArrayDfsphDivergencePressure, divergence);
  }
  // The user attribute: any uint32 (the library never reads it). Every checkpoint of a world
  // with the feature has it (the feature came with it, in version 3).
  if (config.features & kFeatureUserAttribute) {
    r.need_elements(n, sizeof(uint32_t), "user attributes");
    HostVector<uint32_t> attribute(n);
    for (uint32_t& a : attribute) a = r.u32();
    s.set_carried(kArrayUserAttribute, attribute);
  }
  HostVector<uint32_t> sorted(s.id);
  std::sort(sorted.begin(), sorted.end());
  const auto dup = std::adjacent_find(sorted.begin(), sorted.end());
  if (dup != sorted.end()) corrupt(r.what() + ": particle id " + std::to_string(*dup) + " appears twice");
  return s;
}

// The spring lists: every partner another particle (an index of this file; in a rank's part an id,
// which may be of a particle on another rank), every rest length in [0, h], and every spring whose
// two ends are in the file stored at both ends with the same rest length (bit for bit), as the
// solver keeps them. (A rank's part may name an id no rank holds: a particle a sink removed in the
// saved substep, whose spring the next substep drops.)
void read_checkpoint_springs(ByteReader& r, const WorldConfig& config, uint32_t next_id, bool partner_ids,
                             ParticleSnapshot& s) {
  const uint32_t n = static_cast<uint32_t>(s.id.size());
  const uint32_t link_from = r.u32();
  if (link_from != kNoPendingLinks && link_from > next_id)
    corrupt(r.what() + ": the first id waiting for springs, " + std::to_string(link_from) +
            ", was never issued");
  if (r.u32() != kSpringSlots)
    corrupt(r.what() + ": spring lists do not have " + std::to_string(kSpringSlots) + " slots");
  r.need_elements(n, kSpringSlots * 8, "spring lists");
  HostVector<SpringList> springs(n);
  for (uint32_t i = 0; i < n; ++i) {
    SpringList& list = springs[i];
    for (uint32_t k = 0; k < kSpringSlots; ++k) {
      list.partner[k] = r.u32();
      list.rest[k] = bulk_finite(r, "spring rest length of particle", i);
      const uint32_t j = list.partner[k];
      if (j == kNoSpring) {
        if (list.rest[k] != 0.0f)
          corrupt(r.what() + ": an empty spring slot of particle " + std::to_string(i) +
                  " has a rest length");
        continue;
      }
      if (partner_ids ? (j >= next_id || j == s.id[i]) : (j >= n || j == i))
        corrupt(r.what() + ": particle " + std::to_string(i) + " has a spring to " +
                (partner_ids ? "id " : "") + std::to_string(j) + ", which is not another particle");
      if (list.rest[k] < 0.0f || list.rest[k] > config.kernel_radius)
        corrupt(r.what() + ": a spring rest length of particle " + std::to_string(i) + " is outside [0, h]");
    }
  }
  // A rank's part: the file's index of each id (ids are unique, checked with the particles).
  HostVector<uint64_t> by_id(partner_ids ? n : 0);
  for (uint32_t i = 0; i < by_id.size(); ++i) by_id[i] = (static_cast<uint64_t>(s.id[i]) << 32) | i;
  std::sort(by_id.begin(), by_id.end());
  const auto index_of = [&](uint32_t partner) {
    if (!partner_ids) return partner;
    const auto at = std::lower_bound(by_id.begin(), by_id.end(), static_cast<uint64_t>(partner) << 32);
    return at == by_id.end() || (*at >> 32) != partner ? kNoSpring : static_cast<uint32_t>(*at & 0xffffffffu);
  };
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t k = 0; k < kSpringSlots; ++k) {
      const uint32_t p = springs[i].partner[k];
      if (p == kNoSpring) continue;
      uint32_t copies = 0;
      for (uint32_t m = 0; m < kSpringSlots; ++m) copies += springs[i].partner[m] == p ? 1u : 0u;
      const uint32_t j = index_of(p);
      const uint32_t me = partner_ids ? s.id[i] : i;
      uint32_t matches = 1;  // (a partner in another rank's part: its own file is checked there)
      if (j != kNoSpring) {
        matches = 0;
        for (uint32_t m = 0; m < kSpringSlots; ++m)
          if (springs[j].partner[m] == me &&
              std::memcmp(&springs[j].rest[m], &springs[i].rest[k], sizeof(float)) == 0)
            ++matches;
      }
      if (matches != 1 || copies != 1)
        corrupt(r.what() + ": the spring between particles " + std::to_string(i) + " and " +
                std::to_string(p) + " is not stored once at each end with one rest length");
    }
  s.set_carried(kArraySprings, springs);
  s.set_carried(kArraySpringLinkFrom, HostVector<uint32_t>{link_from});
}

}  // namespace sph
